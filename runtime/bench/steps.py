"""What limits erk's steps on the benchmark's problem: step counts with one thing changed at a time.

Made by ``python -m apexseal.runtime.bench.steps [--rtol 1e-8] [--inert] [--compare]`` (a few minutes;
docs/bench/levers.md).
erk (RK45 + events, interpreted, for its statistics; the step sequence is the compiled integrator's) integrates
one revolution of the benchmark's problem (runtime/bench/problem.py: default scene, 360 output intervals,
settled start) with each variant: scene parameters changed (contact stiffness, friction regularisation width,
friction coefficients), effects left out (runtime/bench/effects.py), the chamber pressures held per interval
("steps") or linear over it ("linear"). Fewer steps with a change = that change removes what limited them.

``--inert`` also times the compiled erk with and without the event counters in the integrated state (interleaved
rounds, medians): the cost of the inert entries the hybrid state carries (generated/layout.py).
``--compare`` runs the default scene with each pressure profile and states how far apart the results are.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from .config import METHODS
from .effects import effect_sets
from .methods import EngineCache
from .problem import load_model, make_problem

_STIFF = ("contacts.kw", *(f"contacts.kg{i}" for i in range(1, 5)))
#: label -> scene overrides
VARIANTS: dict[str, dict] = {
    "default scene": {},
    "v_eps x 10 (10 mm/s)": {"friction.v_eps": "10 mm/s"},
    "v_eps x 100 (100 mm/s)": {"friction.v_eps": "100 mm/s"},
    "mu2 = 0 (no groove friction)": {"friction.mu2": 0.0},
    "mu1 = mu2 = mus = 0 (no friction)": {"friction.mu1": 0.0, "friction.mu2": 0.0, "friction.mus": 0.0},
    "kw, kg / 10 (1e8 N/m)": {k: "1e8 N/m" for k in _STIFF},
}
PROFILES = ("steps", "linear")


def _problem(name, scene, effects, functions, engines):
    settle_engine, settle_settings = engines.settle(name, functions, 1e-10, 1e-12)
    return make_problem(name, scene, effects, functions, samples=engines.samples, span=2 * math.pi,
                        settle_revolutions=3, settle_engine=settle_engine, settle_settings=settle_settings,
                        pressure_profile=engines.pressure)


def _count(engine, problem) -> dict:
    s = engine.run(problem.z0, problem.params, problem.theta0, problem.pressures).stats
    return {k: int(s[k]) for k in ("n_steps", "n_rhs", "n_reject", "n_events")}


def step_counts(rtol: float, log=print) -> list[dict]:
    """Rows: (what, pressure profile, steps, RHS evaluations, rejected steps, events)."""
    from ..scenes.scene import load_scene

    base = load_scene()
    rows = []
    for profile in PROFILES:
        engines = EngineCache(samples=360, span=2 * math.pi, flags="optimised", pressure=profile)
        functions, _ = load_model(base.effects, base.assumptions)
        vm = engines.get("all", functions, METHODS["erk-C"], rtol, compiled=False)
        for label, over in VARIANTS.items():
            scene = base.with_overrides(**over) if over else base
            rows.append({"what": label, "pressure": profile} | _count(vm, _problem(label, scene, base.effects,
                                                                                    functions, engines)))
            log(rows[-1])
        for label, effects in effect_sets():
            if label == "all":
                continue
            fns, _ = load_model(effects, base.assumptions)
            eng = engines.get(label, fns, METHODS["erk-C"], rtol, compiled=False)
            try:
                rows.append({"what": f"effects: {label}", "pressure": profile} | _count(eng, _problem(
                    label, base, effects, fns, engines)))
            except RuntimeError as exc:  # a model that cannot be run is a row too
                rows.append({"what": f"effects: {label}", "pressure": profile, "failed": str(exc)[-120:]})
            log(rows[-1])
    return rows


def inert_entries(rtols=(1e-6, 1e-8), rounds: int = 7, log=print) -> list[dict]:
    """Compiled erk with and without the event counters in z (linear pressures), interleaved rounds, medians."""
    import casadi as ca

    from ...generated.compile import compile_function
    from ...generated.hybrid import build_hybrid_dae, linear_controls
    from ..scenes.scene import load_scene
    from ..solving.event_integrator import events_tested

    base = load_scene()
    functions, _ = load_model(base.effects, base.assumptions)
    engines = EngineCache(samples=360, span=2 * math.pi, flags="optimised", pressure="linear")
    problem = _problem("all", base, base.effects, functions, engines)
    names = tuple(functions.parameter_names)
    grid = np.linspace(0, 2 * math.pi, 361)[1:]
    U = linear_controls(problem.pressures, grid)
    p = np.r_[problem.params, problem.theta0]
    rows = []
    for rtol in rtols:
        h = build_hybrid_dae(functions.rhs, functions.guards, len(names), names.index("omega"), event_tol=1e-10,
                             pressure="linear")
        n, ng = h.layout.n_x, h.layout.n_g
        dae, tr = h.dae, h.transition
        z = ca.SX.sym("z", n + ng)  # the same hybrid state without the counters
        full = ca.vertcat(z, ca.SX.zeros(ng))
        idx = ca.SX.sym("index")
        post = tr(index=idx, t=dae["t"], x=full, p=dae["p"], u=dae["u"])["post_x"][:n + ng]
        tr_b = ca.Function("transition", {"index": idx, "t": dae["t"], "x": z, "p": dae["p"], "u": dae["u"],
                                          "post_x": post}, ca.event_in(), ca.event_out())
        dae_b = {"x": z, "t": dae["t"], "p": dae["p"], "u": dae["u"],
                 "ode": ca.substitute(dae["ode"], dae["x"], full)[:n + ng],
                 "zero": ca.substitute(dae["zero"], dae["x"], full)}
        opts = {"reltol": rtol, "abstol": rtol, "max_events": 10000, "max_num_steps": 200000, "event_tol": 1e-10,
                "show_eval_warnings": False}
        variants = {}
        for label, d, t, z0 in (("with counters", dae, tr, problem.z0), ("without counters", dae_b, tr_b,
                                                                          problem.z0[:n + ng])):
            with events_tested():
                F = ca.integrator(f"inert_{len(variants)}", "erk", d, 0.0, grid, opts | {"transition": t})
            variants[label] = (F, compile_function(F, flags="optimised", model_hash=functions.model_hash), z0)
        times: dict = {k: [] for k in variants}
        for _ in range(rounds):
            for label, (_, C, z0) in variants.items():
                c0 = time.process_time()
                C(x0=z0, p=p, u=U)
                times[label].append(time.process_time() - c0)
        for label, (F, _, z0) in variants.items():
            F(x0=z0, p=p, u=U)
            s = F.stats()
            med = float(np.median(times[label]))
            rows.append({"rtol": rtol, "state": label, "cpu_ms": 1e3 * med, "n_steps": int(s["n_steps"]),
                         "us_per_step": 1e6 * med / int(s["n_steps"])})
            log(rows[-1])
    return rows


def profile_difference(samples=(360, 3600), revolutions: int = 3, log=print) -> list[dict]:
    """The default scene run with each pressure profile (erk, rtol 1e-8): how far apart the results are, and the
    integration wall time of each (one run each, after a warm-up of the same run)."""
    import warnings

    from ..api import simulate
    from ..scenes.scene import load_scene

    scene = load_scene()
    rows = []
    for n in samples:
        runs, wall = {}, {}
        for profile in PROFILES:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                for _ in range(2):  # the first compiles (or loads) the integrator
                    runs[profile] = simulate(scene, revolutions=revolutions, samples_per_revolution=n, rtol=1e-8,
                                             pressure=profile)
            wall[profile] = runs[profile].info["timings_s"]["integrate"]
        a, b = runs["steps"], runs["linear"]
        last = slice(-n, None)  # the last revolution
        Xa, Xb = np.asarray(a.state)[:, last], np.asarray(b.state)[:, last]
        rows.append({"samples": n, "pf_steps": float(np.mean(a.outputs["Pf_total"][last])),
                     "pf_linear": float(np.mean(b.outputs["Pf_total"][last])),
                     "dx_um": 1e6 * float(np.abs(Xa[0] - Xb[0]).max()), "x_range_um": 1e6 * float(np.ptp(Xa[0])),
                     "dy_um": 1e6 * float(np.abs(Xa[1] - Xb[1]).max()), "events": (a.n_events, b.n_events),
                     "wall_steps_s": wall["steps"], "wall_linear_s": wall["linear"]})
        log(rows[-1])
    return rows


def markdown(rows: list[dict], inert: list[dict], rtol: float, diff: list[dict] = ()) -> str:
    out = []
    if rows:
        out += [f"erk at rtol {rtol:g}, one revolution of the benchmark's problem (360 intervals, settled start):", "",
                "| what | pressures | steps | RHS evaluations | rejected | events |", "|---|---|---|---|---|---|"]
    for r in rows:
        if "failed" in r:
            out.append(f"| {r['what']} | {r['pressure']} | failed: {r['failed']} | | | |")
        else:
            out.append(f"| {r['what']} | {r['pressure']} | {r['n_steps']:,} | {r['n_rhs']:,} | {r['n_reject']:,} | "
                       f"{r['n_events']} |")
    if diff:
        out += ["", f"The default scene, erk at rtol 1e-8, last of {diff[0].get('revolutions', 3)} revolutions, each "
                "profile:", "",
                "| samples / rev | mean friction power: steps / linear | max abs(x difference) (x range) | "
                "max abs(y difference) | events | integration wall, 3 rev: steps / linear |", "|---|---|---|---|---|---|"]
        out += [f"| {r['samples']} | {r['pf_steps']:.4g} / {r['pf_linear']:.4g} W | {r['dx_um']:.3g} µm "
                f"({r['x_range_um']:.3g} µm) | {r['dy_um']:.3g} µm | {r['events'][0]} / {r['events'][1]} | "
                f"{r['wall_steps_s']:.2f} / {r['wall_linear_s']:.2f} s |" for r in diff]
    if inert:
        out += ["", "| rtol | integrated state | CPU / rev | steps | µs / step |", "|---|---|---|---|---|"]
        out += [f"| {r['rtol']:g} | {r['state']} | {r['cpu_ms']:.1f} ms | {r['n_steps']:,} | {r['us_per_step']:.2f} |"
                for r in inert]
    return "\n".join(out)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rtol", type=float, default=1e-8)
    ap.add_argument("--inert", action="store_true", help="also time erk without the event counters in its state")
    ap.add_argument("--compare", action="store_true", help="also compare the two pressure profiles' results")
    ap.add_argument("--no-counts", action="store_true", help="skip the step counts")
    a = ap.parse_args(argv)
    quiet = lambda *_: None  # noqa: E731
    rows = [] if a.no_counts else step_counts(a.rtol, log=quiet)
    inert = inert_entries(log=quiet) if a.inert else []
    diff = profile_difference(log=quiet) if a.compare else []
    print(markdown(rows, inert, a.rtol, diff))


if __name__ == "__main__":
    main()
