"""What the goal "2x ahead of the best peer" asks of an integrator, from one benchmark run's own numbers.

A method's CPU time per revolution is (right-hand-side evaluations it needs for an error) x (CPU per evaluation,
its integrator's work included). Both factors are in a run's results: the evaluations of every point (``stats``)
and the cost of one evaluation in its cheapest measured form (``rhs_cost``: the peer's numba right-hand side in a
bare loop, the generated C in the Euler fold). :func:`evaluation_budget` interpolates the evaluations at an error
on each method's (evaluations, error) Pareto front, as :func:`.metrics.time_at_error` does for CPU time, and
bounds what an integrator of apexseal's own could gain: one that needs the evaluations of apexseal's fastest
method at the cheapest evaluation measured, with no work of its own, against the fastest peer; and how many
evaluations a method may need at that cost to be 2x ahead.
"""

from __future__ import annotations

from .metrics import time_at_error


def _evaluations(points: list[dict], method: str, error: float) -> float | None:
    """Right-hand-side evaluations ``method`` needs for ``error``, interpolated on its Pareto front (no
    extrapolation beyond the points' own range is trusted here: ``time_at_error`` flags it)."""
    curve = [(p["stats"]["rhs_evaluations"], p["error"]["state"]) for p in points
             if p["method"] == method and p["status"] == "ok" and (p.get("stats") or {}).get("rhs_evaluations")]
    at = time_at_error(curve, error) if curve else None
    return at.get("time_s") if at and at.get("how") == "interpolated" else None


def evaluation_budget(results: dict, scene: str = "default", error: float | None = None,
                      speedup: float = 2.0) -> dict | None:
    """At ``error`` (the run's target by default): the fastest apexseal method and peer with their evaluations and
    CPU per evaluation, the cheapest evaluation measured, the bound for an overhead-free integrator needing the
    apexseal method's evaluations at that cost, and the evaluations allowed to be ``speedup`` x ahead of the
    peer at that cost. None when the run has no peer or no evaluation costs."""
    from .runner import peer_ratios

    error = results["config"]["target_error"] if error is None else error
    s = next((x for x in results["scenes"] if x["name"] == scene), None)
    if s is None or not s.get("rhs_cost"):
        return None
    row = peer_ratios(results, scene, errors=(error,))[0]
    if not row["apexseal"] or not row["peer"]:
        return None
    n_a = _evaluations(s["points"], row["apexseal"], error)
    n_p = _evaluations(s["points"], row["peer"], error)
    cheapest = min(s["rhs_cost"], key=lambda c: c["s"])
    if n_a is None or n_p is None:
        return None
    bound = n_a * cheapest["s"]
    allowed = row["peer_s"] / speedup / cheapest["s"]
    return {"error": error, "speedup": speedup,
            "apexseal": row["apexseal"], "apexseal_s": row["apexseal_s"], "apexseal_evaluations": n_a,
            "apexseal_s_per_evaluation": row["apexseal_s"] / n_a,
            "peer": row["peer"], "peer_s": row["peer_s"], "peer_evaluations": n_p,
            "peer_s_per_evaluation": row["peer_s"] / n_p,
            "cheapest_form": cheapest["form"], "cheapest_s": cheapest["s"],
            "bound_s": bound, "bound_ratio": row["peer_s"] / bound,
            "allowed_evaluations": allowed, "allowed_vs_apexseal": allowed / n_a, "allowed_vs_peer": allowed / n_p}


def budget_md(results: dict) -> list[str]:
    """The section of table.md that states :func:`evaluation_budget` for the run's first scene."""
    b = evaluation_budget(results, results["scenes"][0]["name"]) if results.get("scenes") else None
    if b is None:
        return []
    ms = lambda s: f"{1e3 * s:.3g} ms"  # noqa: E731
    ns = lambda s: f"{1e9 * s:.0f} ns"  # noqa: E731
    return [f"## What {b['speedup']:g}x ahead of the peer asks of an integrator", "",
            "CPU per revolution = (right-hand-side evaluations for the error) x (CPU per evaluation, integrator "
            "work included); evaluations interpolated on each method's (evaluations, error) Pareto front "
            "(runtime/bench/budget.py).", "",
            "| at scaled error | method | CPU / rev | evaluations | CPU per evaluation |", "|---|---|---|---|---|",
            f"| {b['error']:g} | {b['apexseal']} (apexseal's fastest) | {ms(b['apexseal_s'])} | "
            f"{b['apexseal_evaluations']:,.0f} | {ns(b['apexseal_s_per_evaluation'])} |",
            f"| {b['error']:g} | {b['peer']} (fastest peer) | {ms(b['peer_s'])} | {b['peer_evaluations']:,.0f} | "
            f"{ns(b['peer_s_per_evaluation'])} |", "",
            f"The cheapest evaluation measured in this run costs {ns(b['cheapest_s'])} ({b['cheapest_form']}). An "
            f"integrator of apexseal's own that needed {b['apexseal']}'s {b['apexseal_evaluations']:,.0f} "
            f"evaluations at that cost and did no work of its own would take {ms(b['bound_s'])}: "
            f"**{b['bound_ratio']:.2f}x** the peer's speed, the most that a cheaper right-hand side and less "
            f"per-step overhead can give together. {b['speedup']:g}x ahead of the peer "
            f"({ms(b['peer_s'] / b['speedup'])}) allows at most {b['allowed_evaluations']:,.0f} evaluations at that "
            f"cost: {b['allowed_vs_apexseal']:.2f} of {b['apexseal']}'s and {b['allowed_vs_peer']:.2f} of the "
            f"peer's. " + (f"{b['apexseal']} is {b['peer_s'] / b['apexseal_s']:.2f}x ahead: its evaluations are within "
                           "that budget." if b["apexseal_s"] * b["speedup"] <= b["peer_s"] else
                           "Only a method that needs that many fewer evaluations for the error can reach it."), ""]
