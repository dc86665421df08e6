"""Run a scene: revolution by revolution, with progress, failure capture and chattering detection.

``simulate(scene)`` integrates the hybrid model with the scene's method (see
runtime/methods.py), one revolution per integrator call, and returns a
:class:`SimulationResult`. Nothing computed is lost: on Ctrl-C, on a solver
failure or on chattering the result keeps every finished sample and says where
(crank angle, contact case) and why it stopped.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..derive.modes import Mode
from ..derive.symbols import PARAMETER_NAMES
from .methods import METHODS, check_method
from .result import SimulationResult, StopInfo
from .scaling import to_physical, to_scaled

OMEGA = PARAMETER_NAMES.index("omega")


@dataclass(frozen=True)
class RunSettings:
    """Solver settings of one run (from the scene's [solver] table, with overrides)."""

    method: str = "erk"
    rtol: float = 1e-6
    atol: float | None = None
    samples_per_revolution: int = 720
    steps_per_revolution: int = 200000  # fixed-step methods (euler, rk, collocation)
    event_tol: float = 1e-10  # crank angle, rad (apexseal's own event loop)
    max_events_per_revolution: int = 10000
    chatter_window: float = 1e-3  # rad
    chatter_events: int = 50
    compile_c: bool = True
    flags: str = "optimised"


class Chattering(RuntimeError):
    def __init__(self, guard: str, theta: float, count: int):
        super().__init__(f"chattering on guard {guard}: {count} switches within one output interval near "
                         f"{np.degrees(theta):.3f} deg")
        self.guard, self.theta, self.count = guard, theta, count


def make_engine(functions, settings: RunSettings, *, n_samples: int | None = None, span: float = 2 * np.pi,
                compile_c: bool | None = None):
    """The integrator object for ``settings.method`` (all share ``run(z0, params, theta0, pressures)``)."""
    from .euler_integrator import EulerIntegrator
    from .event_integrator import EventIntegrator
    from .stepper_integrator import StepperIntegrator

    check_method(settings.method)
    kind = METHODS[settings.method][1]
    n = n_samples or settings.samples_per_revolution
    cc = settings.compile_c if compile_c is None else compile_c
    n_par = len(PARAMETER_NAMES)
    if kind == "events":
        rtol = settings.rtol if settings.method != "erk-rk4" else span / (settings.steps_per_revolution * span / (2 * np.pi))
        return EventIntegrator(functions.rhs, functions.guards, n_par, OMEGA, method=settings.method, rtol=rtol,
                               atol=settings.atol, n_samples=n, span=span,
                               max_events=settings.max_events_per_revolution, compile_c=cc, flags=settings.flags)
    if kind == "stepper":
        return StepperIntegrator(functions.rhs, functions.guards, n_par, OMEGA, method=settings.method,
                                 rtol=settings.rtol, atol=settings.atol, n_samples=n, span=span,
                                 steps_per_revolution=settings.steps_per_revolution, event_tol=settings.event_tol,
                                 max_events=settings.max_events_per_revolution)
    return EulerIntegrator(functions.rhs_switched, functions.guards, n_par, OMEGA, n_samples=n,
                           steps_per_revolution=settings.steps_per_revolution, span=span, compile_c=cc,
                           flags=settings.flags)


def initial_activations(functions, theta: float, X: np.ndarray, params: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Which contacts are closed at the start: g < 0, and a guard exactly at 0 by the way it is heading."""
    g = np.array(functions.guards(theta, X, params, u)).ravel()
    closed = g < 0
    on_guard = np.abs(g) <= 1e-15
    if on_guard.any():  # starting exactly on a guard: closed if the gap is closing
        xdot = np.array(functions.rhs(theta, X, closed.astype(float), params, u)).ravel()
        h = 1e-9 / params[OMEGA]
        g2 = np.array(functions.guards(theta + params[OMEGA] * h, X + h * xdot, params, u)).ravel()
        closed = np.where(on_guard, g2 < g, closed)
    return closed.astype(float)


def run(functions, params: np.ndarray, settings: RunSettings, *, theta_start: float, state0: np.ndarray,
        revolutions: int, pressure=None, until_periodic: bool = False, periodic_tol: float = 1e-6,
        progress: bool = False, engine=None, info: dict | None = None) -> SimulationResult:
    """Integrate ``revolutions`` revolutions from ``state0`` (physical) at crank angle ``theta_start``."""
    from tqdm.auto import tqdm

    omega = float(params[OMEGA])
    N = settings.samples_per_revolution
    dth = 2 * np.pi / N
    n_g = functions.guards.size1_out(0)
    engine = engine or make_engine(functions, settings)
    u0 = _pressures(pressure, theta_start + np.array([0.0, dth]))[:, 0]
    z = np.r_[to_scaled(state0, omega), initial_activations(functions, theta_start, state0, params, u0), np.zeros(n_g)]
    first = z.copy()
    blocks, thetas, pressures_used = [], [], []
    status, stop = "completed", None
    t_wall = time.perf_counter()
    stats_total: dict = {}
    bar = tqdm(total=revolutions, unit="rev", disable=not progress, leave=False)
    try:
        for rev in range(revolutions):
            th0 = theta_start + rev * 2 * np.pi
            edges = th0 + dth * np.arange(N + 1)
            P = _pressures(pressure, edges)
            try:
                out = engine.run(z, params, th0, P)
            except KeyboardInterrupt:
                raise
            except RuntimeError as err:
                part, where = _locate_failure(functions, settings, params, z, th0, P, err)
                if part is not None and part.shape[1]:
                    blocks.append(part)
                    thetas.append(edges[1:1 + part.shape[1]])
                    pressures_used.append(P[:, :part.shape[1]])
                status, stop = "failed", where
                break
            blocks.append(out.z)
            thetas.append(edges[1:])
            pressures_used.append(P)
            for k, v in out.stats.items():
                if k.startswith("n_") and isinstance(v, int | float):
                    stats_total[k] = stats_total.get(k, 0) + v
            chatter = _chattering(out.z, n_g, edges[1:], z[6 + n_g:], settings, functions)
            z_prev = z
            z = out.z[:, -1].copy()
            bar.update(1)
            if chatter is not None:
                status = "chattering"
                stop = StopInfo(chatter.theta - theta_start, _mode(functions, out.z[6:6 + n_g, -1]), str(chatter))
                break
            if until_periodic and rev > 0:
                change = np.max(np.abs(z[:6] - z_prev[:6]) / np.maximum(1.0, np.abs(z[:6])))
                if change < periodic_tol:
                    stats_total["periodic_after"] = rev + 1
                    break
    except KeyboardInterrupt:
        status = "interrupted"
        done = sum(b.shape[1] for b in blocks)
        last = blocks[-1][6:6 + n_g, -1] if blocks else first[6:6 + n_g]
        stop = StopInfo(done * dth, _mode(functions, last), "interrupted by the user (Ctrl-C)")
    finally:
        bar.close()
    wall = time.perf_counter() - t_wall
    result = _assemble(functions, params, blocks, thetas, pressures_used, first, theta_start, omega, n_g)
    result.status, result.stop = status, stop
    result.info = dict(info or {}) | {"method": settings.method, "rtol": settings.rtol, "atol": settings.atol,
                                      "samples_per_revolution": N, "wall_time_s": wall, "solver_stats": stats_total,
                                      "compiled": bool(getattr(engine, "compiled", False))}
    return result


def _pressures(pressure, edges: np.ndarray) -> np.ndarray:
    if pressure is None:
        return np.zeros((2, edges.size - 1))
    return np.asarray(pressure(edges), float)


def _mode(functions, closed) -> str:
    return Mode(tuple(bool(float(c) > 0.5) for c in closed), tuple(functions.guard_names)).label


def _chattering(Z, n_g, thetas, counts_before, settings: RunSettings, functions) -> Chattering | None:
    counts = np.c_[counts_before, Z[6 + n_g:]]
    per_interval = np.diff(counts, axis=1)
    dth = thetas[1] - thetas[0] if thetas.size > 1 else 2 * np.pi
    # events per output interval, scaled to the chatter window
    limit = settings.chatter_events * max(1.0, dth / settings.chatter_window)
    hot = np.argwhere(per_interval > limit)
    if hot.size == 0:
        return None
    i, k = hot[0]
    return Chattering(functions.guard_names[i], float(thetas[k]), int(per_interval[i, k]))


def _locate_failure(functions, settings, params, z, th0, P, err):
    """Re-run the failed revolution interval by interval to keep what can be computed and say where it stopped."""
    N = settings.samples_per_revolution
    dth = 2 * np.pi / N
    n_g = functions.guards.size1_out(0)
    try:
        single = make_engine(functions, settings, n_samples=1, span=dth, compile_c=False)
    except Exception:  # noqa: BLE001
        return None, StopInfo(0.0, _mode(functions, z[6:6 + n_g]), f"solver failed: {err}")
    cols = []
    for k in range(N):
        try:
            out = single.run(z, params, th0 + k * dth, P[:, k:k + 1])
        except RuntimeError as e:
            reason = str(e).strip().splitlines()[-1] if str(e).strip() else repr(e)
            return np.array(cols).T if cols else None, StopInfo(th0 + k * dth, _mode(functions, z[6:6 + n_g]),
                                                                 f"solver failed: {reason}")
        z = out.z[:, -1]
        cols.append(z.copy())
    return np.array(cols).T, StopInfo(th0 + 2 * np.pi, _mode(functions, z[6:6 + n_g]), f"solver failed: {err}")


def _assemble(functions, params, blocks, thetas, pressures, first, theta_start, omega, n_g) -> SimulationResult:
    if blocks:
        Z = np.hstack(blocks)
        theta = np.concatenate(thetas)
        U = np.hstack(pressures)
    else:
        Z = first[:, None]
        theta = np.array([theta_start])
        U = np.zeros((2, 1))
    Z = np.c_[first, Z] if blocks else Z
    theta = np.r_[theta_start, theta] if blocks else theta
    U = np.c_[U[:, :1], U]
    X = to_physical(Z[:6], omega)
    closed = Z[6:6 + n_g] > 0.5
    events = Z[6 + n_g:]
    n = theta.size
    Y = np.array(functions.outputs.map(n)(theta[None, :], X, closed.astype(float), np.repeat(params[:, None], n, 1), U))
    outputs = {name: Y[i] for i, name in enumerate(functions.output_names)}
    g = np.array(functions.guards.map(n)(theta[None, :], X, np.repeat(params[:, None], n, 1), U))
    for i, name in enumerate(functions.guard_names):  # gaps b1..b4, penetration xs5, spring compression
        outputs[{"spring": "spring_compression"}.get(name, name)] = g[i] if name.startswith("b") else -g[i]
    outputs["Pa"], outputs["Pb"] = U[0], U[1]
    modes = [_mode(functions, closed[:, i]) for i in range(n)]
    return SimulationResult(theta - theta_start, (theta - theta_start) / omega, X, closed, events, outputs,
                            tuple(functions.guard_names), modes)
