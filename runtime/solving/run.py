"""Run a scene: call by call, with progress, failure capture, chattering detection and a wall-time budget.

``simulate(scene)`` integrates the hybrid model with the scene's method (see
:mod:`.methods`) and returns a :class:`SimulationResult`. A revolution is one
integrator call, or ``calls_per_revolution`` calls (36, 10 degrees each, when a
wall-time budget is set, so the budget is checked often enough). Nothing computed is lost, and every
run ends with a named reason: on Ctrl-C, a solver failure, a non-finite state, a
missed contact event, chattering or a used-up wall-time budget, the result keeps
every finished sample and says where (crank angle, contact case) and why it
stopped (docs/hard-cases.md lists what each reason means and what to do).
The checks after each call are in :mod:`.checks`, the diagnosis of a failed call in :mod:`.diagnosis`.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..results.assemble import assemble
from ..results.result import SimulationResult, StopInfo
from .checks import RunChecks
from .diagnosis import locate_failure
from .layout import HybridLayout
from .methods import WallTimeExceeded, make_engine
from .preflight import initial_activations, preflight
from .scaling import to_scaled
from .settings import RunSettings, out_of_time, samples_per_call


def run(functions, params: np.ndarray, settings: RunSettings, *, theta_start: float, state0: np.ndarray,
        revolutions: int, pressure=None, until_periodic: bool = False, periodic_tol: float = 1e-6,
        progress: bool = False, engine=None, info: dict | None = None) -> SimulationResult:
    """Integrate ``revolutions`` revolutions from ``state0`` (physical) at crank angle ``theta_start``.

    ``engine`` (optional) must cover a whole number of output intervals that divides a revolution.
    """
    from tqdm.auto import tqdm

    lay = HybridLayout.of(functions)
    omega = float(params[list(functions.parameter_names).index("omega")])
    N = settings.samples_per_revolution
    dth = 2 * np.pi / N
    t_wall = time.perf_counter()
    deadline = t_wall + settings.max_wall_time if settings.max_wall_time else math.inf
    u0 = _pressures(pressure, theta_start + np.array([0.0, dth]))[:, 0]
    z = lay.pack(to_scaled(state0, omega), initial_activations(functions, theta_start, state0, params, u0))
    first = z.copy()
    blocks, thetas, pressures_used = [], [], []
    stop = preflight(functions, settings, params, theta_start, state0, z[lay.active], u0)
    status = "completed" if stop is None else "failed"
    if engine is None and stop is None:  # no compiling for a run that cannot start
        m = samples_per_call(settings)
        engine = make_engine(functions, settings, n_samples=m, span=m * dth)
    m = engine.n_samples if engine is not None else N
    if N % m:
        raise ValueError(f"the engine covers {m} output intervals, which do not divide samples_per_revolution = {N}")
    calls = N // m
    stats_total: dict = {}
    check = RunChecks(functions, settings, params, theta_start)
    bar = tqdm(total=revolutions, unit="rev", disable=not progress, leave=False)
    z_rev = z.copy()
    try:
        for call in range(revolutions * calls if stop is None else 0):
            rev, c = divmod(call, calls)
            if time.perf_counter() > deadline:
                status, stop = "interrupted", StopInfo(call * m * dth, lay.mode(z[lay.active]),
                                                       out_of_time(settings, t_wall))
                break
            edges = theta_start + rev * 2 * np.pi + dth * (c * m + np.arange(m + 1))
            P = _pressures(pressure, edges)
            engine.deadline = deadline
            try:
                out = engine.run(z, params, edges[0], P)
                Z, stats, failure = out.z, out.stats, None
            except WallTimeExceeded as late:
                Z, stats = late.partial, {}
                last = Z[lay.active, -1] if Z.shape[1] else z[lay.active]
                failure = "interrupted", StopInfo(edges[Z.shape[1]] - theta_start, lay.mode(last),
                                                  out_of_time(settings, t_wall))
            except RuntimeError as err:
                Z, failure = locate_failure(functions, settings, params, z, edges, P, err, deadline, theta_start,
                                            make_engine)
                stats = {"n_recovered_calls": 1} if failure is None else {}
            Z, bad = check.finite(Z, edges[1:])
            failure = failure or bad
            if Z.shape[1]:
                blocks.append(Z)
                thetas.append(edges[1:1 + Z.shape[1]])
                pressures_used.append(P[:, :Z.shape[1]])
            for k, v in stats.items():
                if k.startswith("n_") and isinstance(v, int | float):
                    stats_total[k] = stats_total.get(k, 0) + v
            found = failure or check.events(Z, z, edges[1:], P, z_rev)
            if Z.shape[1]:
                z = Z[:, -1].copy()
            if found is not None:
                status, stop = found
                break
            bar.update(1 / calls)
            if c == calls - 1:
                z_prev, z_rev = z_rev, z.copy()
                if until_periodic and rev > 0:
                    change = np.max(np.abs(z[lay.x] - z_prev[lay.x]) / np.maximum(1.0, np.abs(z[lay.x])))
                    if change < periodic_tol:
                        stats_total["periodic_after"] = rev + 1
                        break
    except KeyboardInterrupt:
        status = "interrupted"
        done = sum(b.shape[1] for b in blocks)
        last = blocks[-1][lay.active, -1] if blocks else first[lay.active]
        stop = StopInfo(done * dth, lay.mode(last), "interrupted by the user (Ctrl-C)")
    finally:
        bar.close()
    wall = time.perf_counter() - t_wall
    result = assemble(functions, params, blocks, thetas, pressures_used, first, theta_start, omega)
    result.status, result.stop = status, stop
    result.info = dict(info or {}) | {"method": settings.method, "rtol": settings.rtol, "atol": settings.atol,
                                      "samples_per_revolution": N, "calls_per_revolution": calls,
                                      "wall_time_s": wall, "solver_stats": stats_total,
                                      "compiled": bool(engine is not None and engine.compiled)}
    return result


def _pressures(pressure, edges: np.ndarray) -> np.ndarray:
    if pressure is None:
        return np.zeros((2, edges.size - 1))
    return np.asarray(pressure(edges), float)
