"""One point of the diagram: a method at one setting on one problem, timed, checked against the reference.

Failures (solver errors, exceeded CPU budgets, non-finite states) are points too,
with ``status = "failed"`` and the reason; they are never dropped.

Solver statistics: compiled integrators report none, so for them the same
integrator is run once more interpreted (CasADi VM, identical algorithm and
settings, so identical counts); that run's CPU time is kept as
``interpreted_cpu_s``. Euler and the RK4 fold have known step counts; their
contact switches are counted on the output grid (a lower bound: a bounce inside
one output interval is not seen). Stepper methods count their integrator calls
and the events their Python loop located.
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
import tempfile
import time

import numpy as np

from .baseline_scipy import solve
from .config import MethodSpec
from .methods import normalise_stats
from .metrics import errors, trajectory
from .timing import measure, timed


@contextlib.contextmanager
def captured_output(fds: tuple[int, ...] = (1,)):
    """Collect what C code prints on the file descriptors ``fds`` (CasADi dumps a failing Function's inputs on 1,
    numbalsoda's LSODA its warnings on 2)."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = {fd: os.dup(fd) for fd in fds}
    with tempfile.TemporaryFile(mode="w+b") as tmp:
        for fd in fds:
            os.dup2(tmp.fileno(), fd)
        box = {"text": ""}
        try:
            yield box
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            for fd, copy in saved.items():
                os.dup2(copy, fd)
                os.close(copy)
            tmp.seek(0)
            box["text"] = tmp.read().decode(errors="replace")


def point_base(problem, spec: MethodSpec, value: float) -> dict:
    """The fields every point of ``spec`` at ``value`` on ``problem`` has, whatever became of it."""
    return {"scene": problem.name, "method": spec.id, "label": spec.label, "family": spec.family, "sweep": spec.sweep,
            "value": value, "generated_c": spec.generated_c}


def failed_point(point: dict, exc: BaseException, cpu_s: float) -> dict:
    """``point`` as failed with ``exc`` (its last line the reason) after ``cpu_s`` of CPU time: a result."""
    reason = str(exc).strip().splitlines()[-1] if str(exc).strip() else type(exc).__name__
    return point | {"status": "failed", "reason": f"{type(exc).__name__}: {reason}"[:300], "timing": None,
                    "cpu_s_until_failure": cpu_s, "load_average": os.getloadavg()[0]}


def _analyse(point: dict, problem, ref, out, timing) -> dict:
    traj = trajectory(problem, out.z)
    err = errors(traj, ref)
    status = "ok" if math.isfinite(err["state"]) else "failed"
    point |= {"status": status, "error": err, "mean_friction_power_W": traj.mean_friction_power,
              "timing": timing.as_dict(), "counted_switches": int(traj.events.sum())}
    if status == "failed":
        point["reason"] = "non-finite state"
    return point


def casadi_point(problem, ref, spec: MethodSpec, value: float, engine, *, repeats: int, slow_run_s: float,
                 budget_s: float | None, stats_engine=None, build_s: float | None = None) -> dict:
    point = point_base(problem, spec, value) | {"engine_build_s": build_s,
                                                "compiled": bool(getattr(engine, "compiled", False))}
    z0, P = problem.z0, problem.pressures

    def call():
        return engine.run(z0, problem.params, problem.theta0, P)

    c0 = time.process_time()
    with captured_output() as printed:
        try:
            out, timing = measure(call, repeats=repeats, slow_run_s=slow_run_s, budget_s=budget_s)
        except Exception as exc:  # noqa: BLE001 - every failure is a result
            out, failure = None, exc
    if out is None:
        return failed_point(point, failure, time.process_time() - c0) | {"solver_output": printed["text"][-2000:]}
    point = _analyse(point, problem, ref, out, timing)
    point["load_average"] = os.getloadavg()[0]
    stats = normalise_stats(out.stats, "run")
    if spec.kind == "rk4" or spec.method == "euler":
        stats.setdefault("rhs_evaluations", stats.get("steps"))
        stats["events"] = point["counted_switches"]
        stats["source"] = "fixed steps; events = switches seen on the output grid (lower bound)"
    elif spec.method == "erk-rk4":
        steps = int(value)
        stats |= {"steps": steps, "rhs_evaluations": 4 * steps, "events": point["counted_switches"],
                  "source": "nominal fixed steps (+1 per event); events from the integrator's own counters"}
    elif "integrator_calls" in stats:
        stats["source"] = "apexseal's event loop (integrator calls, located events); internal steps not reported"
    if stats_engine is not None:
        try:
            vm_out, cpu, _ = timed(lambda: stats_engine.run(z0, problem.params, problem.theta0, P), budget_s)
            stats = normalise_stats(vm_out.stats, "one interpreted run with identical settings")
            point["interpreted_cpu_s"] = cpu
            same = np.allclose(vm_out.z[:6], out.z[:6], rtol=1e-9, atol=1e-9)
            point["interpreted_matches_compiled"] = bool(same)
        except Exception as exc:  # noqa: BLE001
            stats["stats_run_failed"] = str(exc)[-200:]
    point["stats"] = stats
    return point


def scipy_point(problem, ref, spec: MethodSpec, rtol: float, model, *, repeats: int, slow_run_s: float,
                budget_s: float | None) -> dict:
    point = point_base(problem, spec, rtol) | {"compiled": False}
    c0 = time.process_time()
    try:
        out, timing = measure(lambda: solve(model, problem, spec.method, rtol), repeats=repeats, slow_run_s=slow_run_s,
                              budget_s=budget_s)
    except Exception as exc:  # noqa: BLE001
        return failed_point(point, exc, time.process_time() - c0)
    point = _analyse(point, problem, ref, out, timing)
    point["load_average"] = os.getloadavg()[0]
    stats = normalise_stats(out.stats, "solve_ivp (nfev, njev); events = switches seen on the output grid")
    stats["lu_decompositions"] = out.stats.get("n_lu")
    stats["events"] = point["counted_switches"]
    point["stats"] = stats
    return point


def peer_point(problem, ref, spec: MethodSpec, rtol: float, peer, *, repeats: int, slow_run_s: float,
               budget_s: float | None) -> dict:
    """A point of the hand-written numba peer (runtime/bench/peer_numba.py); its kernels are compiled beforehand."""
    point = point_base(problem, spec, rtol) | {"compiled": True, "engine_build_s": peer.build_s}
    c0 = time.process_time()
    try:
        with captured_output((1, 2)) as printed:  # LSODA's warnings (numbalsoda's C++ prints them)
            out, timing = measure(lambda: peer.run(spec.method, rtol), repeats=repeats, slow_run_s=slow_run_s,
                                  budget_s=budget_s)
    except Exception as exc:  # noqa: BLE001
        return failed_point(point, exc, time.process_time() - c0)
    point = _analyse(point, problem, ref, out, timing)
    if printed["text"].strip():
        lines = [ln.strip() for ln in printed["text"].splitlines() if ln.strip()]
        point["solver_messages"] = {"lines": len(lines), "first": " ".join(lines[:3])[:300]}
    point["load_average"] = os.getloadavg()[0]
    if "n_events" in out.stats:
        src = "DOP853's nfev summed over its calls (one per output interval and event); events located by the driver"
    else:
        src = "evaluations counted inside the right-hand side (LSODA's finite-difference Jacobians included); " \
              "events = switches seen on the output grid"
    stats = normalise_stats(out.stats, src)
    stats.setdefault("events", point["counted_switches"])
    point["stats"] = stats
    return point
