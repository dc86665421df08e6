"""What one right-hand-side evaluation costs, in each form the benchmark uses.

The speed-up of a whole method is (cost per evaluation) x (evaluations for the
target error); this table separates the two. Timed at the problem's initial
state, each form in a loop of calls from Python, except the last rows, which are
derived from the benchmark's own points (CPU per revolution / evaluations, so the
integrator's own work per evaluation is included).
"""

from __future__ import annotations

import time

import numpy as np

from .linking import integrator_before_after


def _per_call(fn, min_s: float = 0.2, max_calls: int = 20000) -> tuple[float, int]:
    fn()
    n, total = 0, 0.0
    c0 = time.process_time()
    while total < min_s and n < max_calls:
        fn()
        n += 1
        total = time.process_time() - c0
    return total / n, n


def rhs_costs(problem, sx, c_model, lambdified, scene_points: list[dict], peer=None, *,
              flags: str = "optimised") -> list[dict]:
    """Rows: form, seconds per evaluation, calls timed (or the point it was derived from)."""
    from .baseline_scipy import lambdify_model, make_rhs

    th, X, p, u = problem.theta0, problem.X0, problem.params, problem.pressures[:, 0]
    rows = []
    if lambdified is not None:
        rhs = make_rhs(lambdified, problem)
        t, n = _per_call(lambda: rhs(0.0, X))
        rows.append({"form": "sympy.lambdify (numpy, cse=True) + guards, Python: the scipy baseline's RHS", "s": t, "n": n})
        plain = lambdify_model(problem.effects, problem.scene.assumptions, cse=False)
        rhs0 = make_rhs(plain, problem)
        t, n = _per_call(lambda: rhs0(0.0, X), min_s=0.1, max_calls=200)
        rows.append({"form": f"sympy.lambdify (numpy, default cse=False) + guards (lambdify took {plain.setup_s:.1f} s)",
                     "s": t, "n": n})
    t, n = _per_call(lambda: sx.rhs_switched(th, X, p, u))
    rows.append({"form": "CasADi SX Function rhs_switched called from Python (VM + call overhead)", "s": t, "n": n})
    if c_model is not None:
        t, n = _per_call(lambda: c_model.rhs_switched(th, X, p, u))
        rows.append({"form": "compiled rhs_switched (generated C) called from Python", "s": t, "n": n})
    if peer is not None:
        from .peer_numba import per_evaluation

        rows.append({"form": "sympy.cse + numba switched RHS (the peer's), in a numba loop of 200000 calls",
                     "s": per_evaluation(peer, "switched_rhs"), "n": 200000})
        rows.append({"form": "sympy.cse + numba RHS of one mode (the peer's DOP853), in a numba loop of 200000 calls",
                     "s": per_evaluation(peer, "mode_rhs"), "n": 200000})
    for mid, what in (("euler-C", "generated C inside the Euler fold (per step, 1 evaluation)"),
                      ("erk-C", "generated C inside the erk integrator (per evaluation, integrator work included)"),
                      ("erk-VM", "CasADi VM inside the erk integrator (per evaluation, integrator work included)"),
                      ("numbalsoda-LSODA", "numba RHS inside numbalsoda LSODA (per evaluation, integrator work included)"),
                      ("numbalsoda-DOP853", "numba RHS inside numbalsoda DOP853 + events (per evaluation, integrator "
                                            "and event work included)")):
        pts = [q for q in scene_points if q["method"] == mid and q["status"] == "ok"
               and (q.get("stats") or {}).get("rhs_evaluations")]
        if pts:
            q = pts[len(pts) // 2]
            per = q["timing"]["median_cpu_s"] / q["stats"]["rhs_evaluations"]
            rows.append({"form": what, "s": per, "n": f"{mid} at {q['value']:g}"})
    rows += integrator_before_after(problem, flags=flags)
    return [r | {"s": float(np.float64(r["s"]))} for r in rows]
