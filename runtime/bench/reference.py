"""The reference solution of a problem, and its check by a second, independent method.

Reference: erk (RK45) with events located on its dense output to ``1e-13`` rad
of crank angle, ``rtol = atol = 1e-12`` (scaled state), compiled to C. Check: CVODES (BDF, a different method
family) at the same tolerance with apexseal's own event loop locating every
contact switch to ``1e-13`` rad of crank angle (runtime/solving/stepper_integrator.py).
Their disagreement, in the benchmark's own error metrics, bounds how small an
error the diagram can resolve; it is stored with the results and printed in the
tables.
"""

from __future__ import annotations

import time

from .metrics import STATE_KEYS, Trajectory, errors, trajectory


def solve_reference(problem, engine) -> tuple[Trajectory, dict]:
    c0 = time.process_time()
    out = engine.run(problem.z0, problem.params, problem.theta0, problem.pressures)
    cpu = time.process_time() - c0
    ref = trajectory(problem, out.z)
    info = {"method": "erk (RK45, events on dense output), compiled C", "cpu_s": cpu,
            "events": int(ref.events.sum()), "events_per_guard": dict(zip(problem.functions.guard_names,
                                                                           map(int, ref.events), strict=True)),
            "mean_friction_power_W": ref.mean_friction_power,
            "range": {k: float(ref.X[i].max() - ref.X[i].min()) for i, k in enumerate(STATE_KEYS)}}
    return ref, info


def check_reference(problem, ref: Trajectory, engine, *, method: str, rtol: float, event_tol: float) -> dict:
    """Solve again with a second method; the errors between the two are the reference's uncertainty."""
    c0 = time.process_time()
    try:
        out = engine.run(problem.z0, problem.params, problem.theta0, problem.pressures)
    except RuntimeError as exc:
        return {"method": method, "rtol": rtol, "event_tol": event_tol, "status": "failed", "reason": str(exc)[-300:]}
    cpu = time.process_time() - c0
    other = trajectory(problem, out.z)
    return {"method": method, "rtol": rtol, "event_tol": event_tol, "status": "ok", "cpu_s": cpu,
            "difference": errors(other, ref), "events": int(other.events.sum()),
            "events_match": bool((other.events == ref.events).all())}
