"""The compiled erk integrator calling the model library against the same integrator embedding the model.

Before: the integrator's DAE embedded the model's SX Functions, so its C held the model, and a run compiled
the model library (for Python-side evaluations) and, separately, the model again inside every integrator.
After (a run's path): the DAE calls the library's ``hybrid_ode`` and ``hybrid_zero``, the integrator's C
declares them extern and links against the library, which therefore also holds their derivatives.

* :func:`integrator_before_after`: one rhs evaluation inside each compiled integrator (``apexseal bench``
  prints it in its table of evaluation costs);
* :func:`cold_builds`: what a cold run compiles in each form, in an empty cache: the model library and the
  integrator, wall seconds each.

Everything is compiled at the station: the integrators' records name the model they embed or call, and the
library before (:func:`before_library`), which no manifest describes, is a variant of the model with a record
of its own (generated/variant.py).

``python -m apexseal.runtime.bench.linking [--flags quick|optimised] [--repeats N]`` prints both for the
default scene.
"""

from __future__ import annotations

import argparse
import dataclasses
import time
import warnings
from pathlib import Path

import numpy as np

from ...generated.compiler import FLAG_SETS

BEFORE = "before (the integrator's C embeds the model)"
AFTER = "after (the integrator calls the compiled model library)"


def _integrator(sx, problem, *, flags: str, library=None):
    from ..solving.event_integrator import EventIntegrator

    names = tuple(sx.parameter_names)
    return EventIntegrator(sx.rhs, sx.guards, len(names), names.index("omega"), method="erk", rtol=1e-6, atol=1e-6,
                           n_samples=problem.samples, span=problem.span, compile_c=False, flags=flags,
                           model_hash=sx.model_hash, state_names=sx.state_names, library=library,
                           pressure=problem.pressure)


def _compile(engine, *, flags: str, model_hash: str | None) -> float:
    """Generate, compile (unless cached) and load the engine's integrator; wall seconds."""
    from ...generated.compile import compile_function

    w0 = time.perf_counter()
    engine.function = compile_function(engine.vm, flags=flags, model_hash=model_hash, link=engine.link)
    engine.compiled = engine.function is not engine.vm
    return time.perf_counter() - w0


def _compiled_library(problem, flags: str):
    """The problem's compiled model Functions (None when no compiler works)."""
    from ...generated.compile import CompilerFallbackWarning
    from ...generated.load import load_functions

    with warnings.catch_warnings():
        warnings.simplefilter("error", CompilerFallbackWarning)
        try:
            return load_functions(problem.effects, problem.scene.assumptions, flags=flags)
        except CompilerFallbackWarning:
            return None


def integrator_before_after(problem, *, flags: str, repeats: int = 5) -> list[dict]:
    """One rhs evaluation inside the compiled erk integrator, before and after it called the model library.

    Both are compiled and run over the problem's span, interleaved ``repeats`` times; CPU per revolution /
    rhs evaluations, medians. Rows as :func:`.rhs_cost.rhs_costs` gives them (form, seconds, what was timed).
    """
    loaded = _compiled_library(problem, flags)
    if loaded is None:
        return []  # no compiler: nothing compiled to compare
    sx = problem.functions.sx()
    engines = {BEFORE: _integrator(sx, problem, flags=flags), AFTER: _integrator(sx, problem, flags=flags,
                                                                                   library=loaded.c)}
    for e in engines.values():
        _compile(e, flags=flags, model_hash=sx.model_hash)
    args = (problem.z0, problem.params, problem.theta0, problem.pressures)
    per: dict[str, list[float]] = {k: [] for k in engines}
    for _ in range(repeats):
        for label, e in engines.items():
            c0 = time.process_time()
            e.run(*args)
            per[label].append(time.process_time() - c0)
    rows = []
    from ...generated.hybrid import controls

    for label, e in engines.items():  # the statistics come from the interpreted run of the same integrator
        e.vm(x0=args[0], p=np.r_[args[1], args[2]], u=controls(args[3], e.grid, e.pressure, e.hybrid.dae["u"].size1()))
        evals = max(1, int(e.vm.stats().get("n_rhs") or 1))
        rows.append({"form": f"erk integrator (compiled, rtol 1e-6), rhs evaluation, {label}",
                     "s": float(np.median(per[label])) / evals, "n": f"{repeats} runs, interleaved",
                     "revolution_s": float(np.median(per[label])),
                     "ratio": float(np.median(np.array(per[label]) / np.array(per[BEFORE])))})
    return rows


#: what the model library before the integrators called it leaves out (its variant record's ``how``)
BEFORE_LIBRARY = {"library": "the model's Functions without hybrid_ode, hybrid_zero and their derivatives: the model "
                             "library before the erk integrator called it"}


def before_library(sx, flags: str) -> Path:
    """The model library as it was before: the model's Functions without the hybrid ones, a variant of the model
    no manifest describes, compiled at the station under its own record (generated/variant.py)."""
    from ...generated.compile import variant_library
    from ...generated.variant import record_variant

    base = dataclasses.replace(sx, hybrid_ode=None, hybrid_zero=None)
    return variant_library(record_variant(base, of=sx.model_hash, how=BEFORE_LIBRARY), flags=flags)


def cold_builds(problem, *, flags: str, rounds: int = 1) -> list[dict]:
    """Wall seconds of what a cold run of the problem's model compiles, before and after, in an empty cache each.

    Before: the library of the model's Functions, and the integrator embedding the model. After: the library
    with the hybrid Functions and their derivatives, and the integrator calling it. ``rounds`` x (before,
    after, after, before), so a drifting machine load biases neither; one row per build.
    """
    from ...generated.compile import compile_library, load_externals
    from ...generated.functions import library_groups
    from .compile_pool import private_cache

    loaded = _compiled_library(problem, flags)
    if loaded is None:
        return []
    sx = problem.functions.sx()
    hybrid = [f.name() for f in library_groups(sx)["casadi_model"] if f.name().startswith("hybrid_")]
    rows = []
    for form in [BEFORE, AFTER, AFTER, BEFORE] * rounds:
        with private_cache():
            w0 = time.perf_counter()
            if form == BEFORE:
                before_library(sx, flags)
                engine = _integrator(sx, problem, flags=flags)
            else:
                so = compile_library(loaded.source_dir, flags=flags, manifest=loaded.manifest)
                c = sx.with_functions(load_externals(so, hybrid))
                c.library = so
                engine = _integrator(sx, problem, flags=flags, library=c)
            library_s = time.perf_counter() - w0
            integrator_s = _compile(engine, flags=flags, model_hash=sx.model_hash)
        rows.append({"form": form, "library_s": library_s, "integrator_s": integrator_s,
                     "total_s": library_s + integrator_s})
    return rows


def main(argv=None) -> None:
    from ..scenes.scene import load_scene
    from .problem import load_model, make_problem

    ap = argparse.ArgumentParser(prog="python -m apexseal.runtime.bench.linking", description=__doc__.split("\n")[0])
    ap.add_argument("--flags", default="optimised", choices=tuple(FLAG_SETS))
    ap.add_argument("--repeats", type=int, default=15, help="interleaved timed runs of each integrator")
    ap.add_argument("--rounds", type=int, default=1, help="rounds of (before, after, after, before) cold builds")
    a = ap.parse_args(argv)
    scene = load_scene()
    sx, _ = load_model(scene.effects, scene.assumptions)
    problem = make_problem("default", scene, scene.effects, sx, samples=360, span=2 * np.pi, settle_revolutions=0)
    print(f"one revolution of the default scene, erk rtol 1e-6, flags {a.flags}")
    for r in integrator_before_after(problem, flags=a.flags, repeats=a.repeats):
        print(f"  {r['s'] * 1e9:6.0f} ns per rhs evaluation, {r['revolution_s'] * 1e3:6.1f} ms CPU per span "
              f"(median ratio to before {r['ratio']:.3f})  {r['form']} ({r['n']})")
    print("cold builds (empty cache), wall seconds: library + integrator = total")
    builds = cold_builds(problem, flags=a.flags, rounds=a.rounds)
    for form in (BEFORE, AFTER):
        rs = [r for r in builds if r["form"] == form]
        med = {k: float(np.median([r[k] for r in rs])) for k in ("library_s", "integrator_s", "total_s")}
        print(f"  {med['library_s']:5.1f} + {med['integrator_s']:5.1f} = {med['total_s']:5.1f} s  {form} "
              f"(median of {len(rs)})")


if __name__ == "__main__":
    main()
