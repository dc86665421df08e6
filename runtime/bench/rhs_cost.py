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


def integrator_before_after(problem, *, flags: str, repeats: int = 5) -> list[dict]:
    """One rhs evaluation inside the compiled erk integrator, built as before and after the generation station.

    Before: the integrator embedded SX Functions lowered from the derivation at run time (sympy). After: it
    embeds the SX Functions deserialized from the model's artefacts, the ones whose C is the model library.
    Both are compiled and run over the problem's span, interleaved ``repeats`` times; CPU per revolution /
    rhs evaluations, medians. Also reports whether the two integrators' C is the same file.
    """
    from ...derive.cache import cached_model
    from ...generated.compile import function_source
    from ...generated.functions import build_functions
    from ..solving.event_integrator import EventIntegrator

    forms = {"before (SX lowered from the derivation)": build_functions(cached_model(problem.effects,
                                                                                      problem.scene.assumptions)),
             "after (SX of the model's artefacts)": problem.functions.sx()}
    names = tuple(problem.functions.parameter_names)
    engines, sources = {}, {}
    for label, f in forms.items():
        e = EventIntegrator(f.rhs, f.guards, len(names), names.index("omega"), method="erk", rtol=1e-6, atol=1e-6,
                            n_samples=problem.samples, span=problem.span, compile_c=True, flags=flags,
                            model_hash=f.model_hash, pressure=problem.pressure)
        engines[label], sources[label] = e, function_source(e.vm).key_payload["c_sha256"]
    args = (problem.z0, problem.params, problem.theta0, problem.pressures)
    per: dict[str, list[float]] = {k: [] for k in engines}
    evals = {}
    for _ in range(repeats):
        for label, e in engines.items():
            c0 = time.process_time()
            e.run(*args)
            per[label].append(time.process_time() - c0)
    for label, e in engines.items():  # the statistics come from the interpreted run of the same integrator
        e.function = e.vm
        e.run(*args)
        evals[label] = e.vm.stats().get("n_rhs")
    same = len(set(sources.values())) == 1
    if not all(e.compiled for e in engines.values()):
        return []  # no compiler: nothing compiled to compare
    return [{"form": f"erk integrator (compiled, rtol 1e-6), rhs evaluation, {label}; integrator C "
             f"{'identical' if same else 'different'} (sha256 {sources[label][:12]})",
             "s": float(np.median(per[label])) / max(1, int(evals[label] or 1)), "n": f"{repeats} runs"}
            for label in engines]
