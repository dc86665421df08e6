"""Levers on the cost of one right-hand-side evaluation of the generated C (lowering and compiler flags).

Run ``python -m apexseal.runtime.bench.levers`` (a few minutes; it compiles every
variant into the shared cache). Each variant is measured two ways, interleaved in
rounds on the same process, medians kept:

* *plain loop*: the model's ``rhs`` (activations of the settled start) in a compiled
  ``mapaccum`` of explicit steps, CPU per evaluation;
* *inside erk*: the compiled erk integrator with events over one revolution of the
  benchmark's problem (default scene, 360 intervals, settled start) at ``rtol``, CPU
  per revolution divided by its right-hand-side evaluations (from one interpreted run,
  which counts them), so integrator and event work per evaluation are included.

Variants: the lowering (generated/lower.py: tree walk memoised on sympy's hashing,
then ``casadi.cse``; with or without ``sympy.cse`` first, generated/functions.py),
and the compiler flag sets below, each on the project's lowering (without ``sympy.cse``:
the baseline). Every variant is compiled at the station (:func:`compile_variant`): the records of its C name
the model it embeds, the manifest's input hash or, for the ``sympy.cse`` lowering, which no manifest describes,
the hash of its own record (generated/variant.py); a flag set other than the project's is named by
``generated.compiler.register_flags``, from the flags themselves. A
variant's results are compared with the baseline's (the largest difference of the scaled
state over the revolution, in the benchmark's scaled-error metric) so that a flag that changes more than
round-off shows; for scale, erk's own scaled error at rtol 1e-8 was ~6e-7 on the soft-contact first
default (docs/bench/soft-contacts/table.md).
"""

from __future__ import annotations

import math
import statistics
import time

import casadi as ca
import numpy as np

from ...generated.compile import compile_function
from ...generated.compiler import register_flags

BASE = "-O3 -march=native -ffp-contract=off"
#: label -> compiler flags (the first is the project's "optimised" set, the baseline)
FLAGS = {
    BASE: ("-O3", "-march=native", "-ffp-contract=off"),
    "-O2 -march=native -ffp-contract=off": ("-O2", "-march=native", "-ffp-contract=off"),
    "-O3 -ffp-contract=off (no -march=native)": ("-O3", "-ffp-contract=off"),
    "-O3 -march=native (FMA contraction on)": ("-O3", "-march=native", "-ffp-contract=fast"),
    "-O3 -march=native -ffp-contract=off -fno-math-errno": ("-O3", "-march=native", "-ffp-contract=off",
                                                             "-fno-math-errno"),
    "-O3 -march=native -ffast-math": ("-O3", "-march=native", "-ffast-math"),
}


def _loop(fns, steps: int) -> ca.Function:
    """``steps`` explicit steps x + h f(theta, x, a, p, u) in one fold (a plain loop of RHS evaluations).

    theta, a, p and u ride along in the folded vector, unchanged: inputs of a fold that are not carried would be
    repeated once per step (megabytes copied per call)."""
    th, x = ca.SX.sym("th"), ca.SX.sym("x", 6)
    a = ca.SX.sym("a", fns.rhs.size1_in(2))
    p, u = ca.SX.sym("p", fns.rhs.size1_in(3)), ca.SX.sym("u", 2)
    w = ca.vertcat(x, th, a, p, u)
    step = ca.Function("step", [w], [ca.vertcat(x + 1e-12 * fns.rhs(th, x, a, p, u), th, a, p, u)])
    return step.fold(steps)


def compile_variant(fns, flags: str, *, steps: int, rtol: float, n_samples: int = 360, erk: bool = True):
    """The plain loop of ``steps`` evaluations and (with ``erk``) the erk integrator with events of the model
    Functions ``fns``, compiled at the station with the flag set ``flags``; both C files' records name
    ``fns.model_hash``. Returns (loop, erk integrator or None)."""
    from ..solving.event_integrator import EventIntegrator

    loop = compile_function(_loop(fns, steps), flags=flags, model_hash=fns.model_hash)
    if not erk:
        return loop, None
    omega = tuple(fns.parameter_names).index("omega")
    return loop, EventIntegrator(fns.rhs, fns.guards, fns.rhs.size1_in(3), omega, method="erk", rtol=rtol, atol=None,
                                 n_samples=n_samples, compile_c=True, flags=flags, model_hash=fns.model_hash)


def _cpu(fn) -> float:
    c0 = time.process_time()
    fn()
    return time.process_time() - c0


def measure(*, rtol: float = 1e-8, steps: int = 20000, rounds: int = 9, log=print) -> list[dict]:
    from ...generated.variant import sympy_cse_variant
    from ..scenes.scene import load_scene
    from ..solving.event_integrator import EventIntegrator
    from .methods import EngineCache
    from .problem import load_model, make_problem
    from .runner import MODEL

    scene = load_scene()
    sx, _ = load_model(scene.effects, scene.assumptions)
    log("lowering with sympy.cse first")
    c0 = time.process_time()
    sx_cse = sympy_cse_variant(scene.effects, scene.assumptions)
    lower_s = time.process_time() - c0
    engines = EngineCache(samples=360, span=2 * math.pi, flags="optimised")
    settle_engine, settle_settings = engines.settle(MODEL, sx, 1e-12, 1e-13)
    problem = make_problem("default", scene, scene.effects, sx, samples=360, span=2 * math.pi, settle_revolutions=3,
                           settle_engine=settle_engine, settle_settings=settle_settings)
    n_par = sx.rhs.size1_in(3)
    OMEGA = tuple(sx.parameter_names).index("omega")  # noqa: N806
    variants = [("tree walk + casadi.cse", sx, BASE), ("sympy.cse + tree walk + casadi.cse", sx_cse, BASE)]
    variants += [("tree walk + casadi.cse", sx, f) for f in FLAGS if f != BASE]
    rows = []
    th, X, A, p = problem.theta0, problem.X0, problem.closed0, problem.params
    u = problem.pressures[:, 0]
    w0 = np.r_[X, th, A, p, u]
    built = []
    for lowering, fns, flags in variants:
        log(f"compiling: {lowering}, {flags}")
        loop, erk = compile_variant(fns, register_flags(FLAGS[flags]), steps=steps, rtol=rtol)
        vm = EventIntegrator(fns.rhs, fns.guards, n_par, OMEGA, method="erk", rtol=rtol, atol=None, n_samples=360,
                             compile_c=False)
        stats = vm.run(problem.z0, p, problem.theta0, problem.pressures).stats
        built.append((lowering, flags, fns, loop, erk, int(stats["n_rhs"])))
    timings: dict = {i: {"loop": [], "erk": []} for i in range(len(built))}
    outs = {}
    for r in range(rounds):  # interleaved rounds: every variant sees the same machine load
        log(f"round {r + 1} of {rounds}")
        for i, (_, _, _, loop, erk, _) in enumerate(built):
            timings[i]["loop"].append(_cpu(lambda loop=loop: loop(w0)) / steps)
            c0 = time.process_time()
            out = erk.run(problem.z0, p, problem.theta0, problem.pressures)
            timings[i]["erk"].append(time.process_time() - c0)
            outs[i] = out.z
    from .metrics import errors, trajectory

    base = trajectory(problem, outs[0])
    for i, (lowering, flags, fns, _, _, n_rhs) in enumerate(built):
        t_erk = statistics.median(timings[i]["erk"])
        diff = errors(trajectory(problem, outs[i]), base)["state"]
        rows.append({"lowering": lowering, "flags": flags, "rhs_instructions": int(fns.rhs.n_instructions()),
                     "loop_ns": 1e9 * statistics.median(timings[i]["loop"]), "erk_ms": 1e3 * t_erk,
                     "rhs_evaluations": n_rhs, "erk_ns_per_eval": 1e9 * t_erk / n_rhs,
                     "max_state_difference": diff, "rounds": rounds})
    rows[1]["lowering_cpu_s"] = lower_s
    return rows


def table(rows: list[dict]) -> str:
    b = rows[0]
    lines = ["| lowering | flags | RHS SX instr. | plain loop / eval | vs baseline | erk / rev (rtol 1e-8) | RHS evals "
             "| erk / eval | vs baseline | scaled error vs baseline's result |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['lowering']} | `{r['flags']}` | {r['rhs_instructions']} | {r['loop_ns']:.0f} ns "
                     f"| {r['loop_ns'] / b['loop_ns']:.2f} | {r['erk_ms']:.1f} ms | {r['rhs_evaluations']:,} "
                     f"| {r['erk_ns_per_eval']:.0f} ns | {r['erk_ns_per_eval'] / b['erk_ns_per_eval']:.2f} "
                     f"| {r['max_state_difference']:.1e} |")
    return "\n".join(lines)


def main() -> None:
    import json
    import sys

    rows = measure(log=lambda m: print(m, file=sys.stderr))
    print(table(rows))
    print("levers-json " + json.dumps(rows))


if __name__ == "__main__":
    main()
