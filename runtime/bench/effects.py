"""What each physical effect costs: time per revolution of erk-C at a fixed accuracy, effect by effect.

A seal with no contact is held by nothing (inertia alone throws it 1.5 m out of
its groove; the gas pressure alone drives it to NaN within 7 deg), and without
contact damping the gas pressure blows it out of the groove too. So an effect is
measured "on its own" on top of the *base* model: the three contacts (housing,
groove, spring) with their damping, which keep the seal in its groove. Rows: the
elastic contacts alone (undamped, to show what damping costs and saves), the
base, base + each remaining effect, and all effects. Each model is derived,
generated and compiled separately (times reported apart from run time), settled
like the main problem, and swept over a few tolerances against its own
reference, so its CPU time at the target error (1e-6) can be interpolated. At
one tolerance the same integrator also runs interpreted for its statistics; the
cost of one right-hand-side evaluation (CPU per revolution / evaluations) is the
accuracy-free part of the cost.
"""

from __future__ import annotations

import math

from ...derive.effects import EFFECTS, Effects
from .config import METHODS
from .methods import compile_target
from .metrics import time_at_error
from .points import casadi_point
from .problem import load_model, make_problem
from .reference import solve_reference

ELASTIC = ("housing_contact", "groove_contact", "spring")
BASE = (*ELASTIC, "housing_damping", "groove_damping", "spring_damping")


def effect_sets(only: tuple[str, ...] = ()) -> list[tuple[str, Effects]]:
    sets = [("elastic contacts", Effects.only(*ELASTIC)), ("base", Effects.only(*BASE))]
    sets += [(f"base+{name}", Effects.only(*BASE, name)) for name in EFFECTS if name not in BASE]
    sets.append(("all", Effects()))
    return [s for s in sets if not only or s[0] in only]


def run_effects(scene, cfg, engines, *, precompile, log) -> list[dict]:
    """Rows of the effects table (see the module docstring)."""
    spec_c = METHODS["erk-C"]
    spec_e = cfg.effects
    models = []
    for label, effects in effect_sets(spec_e.only):
        functions, info = load_model(effects, scene.assumptions)
        models.append((label, effects, functions, info))
        log(f"  {label}: model ready ({info['derive_wall_s']:.1f} s, {'cached' if info['derive_cached'] else 'derived'})")
    targets, keys = [], []
    ref_tols = (cfg.reference_rtol, cfg.reference_event_tol)
    for label, _, functions, _ in models:
        targets.append(compile_target(engines.reference(label, functions, *ref_tols, compiled=False)))
        for value in spec_e.rtols:
            targets.append(compile_target(engines.get(label, functions, spec_c, value, compiled=False)))
            keys.append((label, value))
    builds = precompile(targets)["builds"]
    builds = dict(zip(keys, [b for i, b in enumerate(builds) if i % (len(spec_e.rtols) + 1)], strict=True))
    rows = []
    for label, effects, functions, info in models:
        row = {"effects": label, "on": list(effects.on()), "guards": list(functions.guard_names),
               "rhs_instructions": int(functions.rhs.n_instructions()), "rtols": list(spec_e.rtols),
               "stats_rtol": spec_e.stats_rtol, "compile": [builds[(label, v)] for v in spec_e.rtols]} | info
        try:
            ref_engine = engines.reference(label, functions, *ref_tols)
            settle_engine, settle_settings = engines.settle(label, functions, *ref_tols)
            problem = make_problem(label, scene, effects, functions, samples=cfg.samples, span=math.radians(cfg.span_deg),
                                   settle_revolutions=cfg.settle_revolutions, settle_engine=settle_engine,
                                   settle_settings=settle_settings, pressure_profile=cfg.pressure)
            ref, ref_info = solve_reference(problem, ref_engine)
        except Exception as exc:  # noqa: BLE001 - a model that cannot be run is a row too
            rows.append(row | {"status": "failed", "reason": f"{type(exc).__name__}: {str(exc)[-200:]}"})
            log(f"  {label}: failed ({exc})")
            continue
        points = []
        for rtol in spec_e.rtols:
            engine = engines.get(label, functions, spec_c, rtol, compiled=True)
            stats_engine = engines.get(label, functions, spec_c, rtol, compiled=False) if rtol == spec_e.stats_rtol else None
            points.append(casadi_point(problem, ref, spec_c, rtol, engine, repeats=cfg.repeats,
                                       slow_run_s=cfg.slow_run_s, budget_s=cfg.budget_s, stats_engine=stats_engine))
        ok = [p for p in points if p["status"] == "ok"]
        at = time_at_error([(p["timing"]["median_cpu_s"], p["error"]["state"]) for p in ok], cfg.target_error,
                           max_decades=1.0)
        main = next((p for p in points if p["value"] == spec_e.stats_rtol), points[0])
        med = (main.get("timing") or {}).get("median_cpu_s")
        n_rhs = (main.get("stats") or {}).get("rhs_evaluations")
        row |= {"status": "ok" if ok else "failed", "reason": None if ok else points[0].get("reason"),
                "points": points, "at_target": at, "reference_events": ref_info["events"],
                "at_stats_rtol": {"error": main.get("error"), "timing": main.get("timing"), "stats": main.get("stats"),
                                  "interpreted_cpu_s": main.get("interpreted_cpu_s"),
                                  "load_average": main.get("load_average"),
                                  "ns_per_rhs_evaluation": med / n_rhs * 1e9 if med and n_rhs else None}}
        rows.append(row)
        t_at = (at or {}).get("time_s")
        log(f"  {label}: {_ms(t_at)} at {cfg.target_error:g} ({(at or {}).get('how')}); at rtol {spec_e.stats_rtol:g}: "
            f"{_ms(med)}, error {(main.get('error') or {}).get('state', float('nan')):.2g}")
    return rows


def _ms(s: float | None) -> str:
    return f"{1e3 * s:.1f} ms" if s else "–"
