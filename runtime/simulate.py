"""Run a scene: call by call, with progress, failure capture, chattering detection and a wall-time budget.

``simulate(scene)`` integrates the hybrid model with the scene's method (see
runtime/methods.py) and returns a :class:`SimulationResult`. A revolution is one
integrator call, or ``calls_per_revolution`` calls (36, 10 degrees each, when a
wall-time budget is set, so the budget is checked often enough). Nothing computed is lost, and every
run ends with a named reason: on Ctrl-C, a solver failure, a non-finite state, a
missed contact event, chattering or a used-up wall-time budget, the result keeps
every finished sample and says where (crank angle, contact case) and why it
stopped (docs/hard-cases.md lists what each reason means and what to do).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..derive.modes import Mode
from ..derive.symbols import PARAMETER_NAMES
from .euler_integrator import MAX_GROWTH, contact_growth
from .methods import METHODS, check_method
from .result import SimulationResult, StopInfo
from .scaling import LENGTH, to_physical, to_scaled
from .stepper_integrator import WallTimeExceeded

OMEGA = PARAMETER_NAMES.index("omega")
#: methods whose integrators differentiate the right-hand side (Jacobians, or event location on derivatives)
_NEEDS_DERIVATIVES = ("erk", "erk-rk4", "rosenbrock", "cvodes", "cvodes-adams", "idas", "collocation")
#: a contact left open while its gap is below this (µm) is a missed event, not event-location noise
_MISSED_EVENT_UM = 1e-3
#: what to try when contacts chatter (in the chattering message)
CHATTER_ADVICE = ("regularise instead of resolving every switch: more contact damping (contacts.cw/cr/cs), a larger "
                  "friction.v_eps, or method 'euler' (the switches inside the right-hand side, no events); or raise "
                  "solver.chatter_events / max_events_per_revolution if the switches are physical")


@dataclass(frozen=True)
class RunSettings:
    """Solver settings of one run (from the scene's [solver] table, with overrides)."""

    method: str = "erk"
    rtol: float = 1e-6
    atol: float | None = None
    samples_per_revolution: int = 720
    steps_per_revolution: int = 200000  # fixed-step methods (euler, rk, collocation)
    event_tol: float = 1e-10  # crank angle, rad: event location of every method
    max_events_per_revolution: int = 10000
    chatter_window: float = 1e-3  # rad
    chatter_events: int = 50
    compile_c: bool = True
    flags: str = "optimised"
    max_steps_per_interval: int = 200000  # adaptive methods: integrator steps allowed in one output interval
    max_wall_time: float | None = None  # s, checked between integrator calls; None: no budget
    calls_per_revolution: int | None = None  # None: 1, or 36 with a wall-time budget


class Chattering(RuntimeError):
    def __init__(self, guard: str, theta: float, count: int, within: str = "within one output interval"):
        super().__init__(f"chattering on guard {guard}: {count} switches {within} near {np.degrees(theta):.3f} deg; "
                         + CHATTER_ADVICE)
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
                               max_events=settings.max_events_per_revolution, max_steps=settings.max_steps_per_interval,
                               event_tol=settings.event_tol, compile_c=cc, flags=settings.flags)
    if kind == "stepper":
        return StepperIntegrator(functions.rhs, functions.guards, n_par, OMEGA, method=settings.method,
                                 rtol=settings.rtol, atol=settings.atol, n_samples=n, span=span,
                                 steps_per_revolution=settings.steps_per_revolution, event_tol=settings.event_tol,
                                 max_events=settings.max_events_per_revolution,
                                 max_steps=settings.max_steps_per_interval)
    return EulerIntegrator(functions.rhs_switched, functions.guards, n_par, OMEGA, n_samples=n,
                           steps_per_revolution=settings.steps_per_revolution, span=span, compile_c=cc,
                           flags=settings.flags)


def samples_per_call(settings: RunSettings) -> int:
    """Output intervals per integrator call: the revolution cut into ``calls_per_revolution`` equal calls.

    The number of calls is rounded up to a divisor of ``samples_per_revolution`` (every call the same engine).
    """
    n = settings.samples_per_revolution
    calls = settings.calls_per_revolution or (36 if settings.max_wall_time else 1)
    calls = next(d for d in range(max(1, min(calls, n)), n + 1) if n % d == 0)
    return n // calls


def initial_activations(functions, theta: float, X: np.ndarray, params: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Which contacts are closed at the start: g < 0, and a guard exactly at 0 by the way it is heading.

    A guard exactly at 0 is closed if it is about to go negative: judged from a short
    second-order step (positions + h velocities + h²/2 accelerations), so that a seal
    at rest on a contact that the load presses shut counts as closing. The events then
    start from zero functions that grow, the only way CasADi's + to - events can see
    the next switch.
    """
    g = np.array(functions.guards(theta, X, params, u)).ravel()
    closed = g < 0
    on_guard = np.abs(g) <= 1e-15
    if on_guard.any():
        xdot = np.array(functions.rhs(theta, X, closed.astype(float), params, u)).ravel()
        h = 1e-6 / params[OMEGA]  # 1e-6 rad of crank angle
        X2 = X + h * xdot + 0.5 * h * h * np.r_[xdot[3:], np.zeros(3)]
        g2 = np.array(functions.guards(theta + params[OMEGA] * h, X2, params, u)).ravel()
        closed = np.where(on_guard, g2 < 0, closed)
    return closed.astype(float)


def run(functions, params: np.ndarray, settings: RunSettings, *, theta_start: float, state0: np.ndarray,
        revolutions: int, pressure=None, until_periodic: bool = False, periodic_tol: float = 1e-6,
        progress: bool = False, engine=None, info: dict | None = None) -> SimulationResult:
    """Integrate ``revolutions`` revolutions from ``state0`` (physical) at crank angle ``theta_start``.

    ``engine`` (optional) must cover a whole number of output intervals that divides a revolution.
    """
    from tqdm.auto import tqdm

    omega = float(params[OMEGA])
    N = settings.samples_per_revolution
    dth = 2 * np.pi / N
    n_g = functions.guards.size1_out(0)
    t_wall = time.perf_counter()
    deadline = t_wall + settings.max_wall_time if settings.max_wall_time else math.inf
    u0 = _pressures(pressure, theta_start + np.array([0.0, dth]))[:, 0]
    z = np.r_[to_scaled(state0, omega), initial_activations(functions, theta_start, state0, params, u0), np.zeros(n_g)]
    first = z.copy()
    blocks, thetas, pressures_used = [], [], []
    stop = _preflight(functions, settings, params, theta_start, state0, z[6:6 + n_g], u0)
    status = "completed" if stop is None else "failed"
    if engine is None and stop is None:  # no compiling for a run that cannot start
        m = samples_per_call(settings)
        engine = make_engine(functions, settings, n_samples=m, span=m * dth)
    m = engine.n_samples if engine is not None else N
    if N % m:
        raise ValueError(f"the engine covers {m} output intervals, which do not divide samples_per_revolution = {N}")
    calls = N // m
    stats_total: dict = {}
    check = _Checks(functions, settings, params, theta_start, n_g)
    bar = tqdm(total=revolutions, unit="rev", disable=not progress, leave=False)
    z_rev = z.copy()
    try:
        for call in range(revolutions * calls if stop is None else 0):
            rev, c = divmod(call, calls)
            if time.perf_counter() > deadline:
                status, stop = "interrupted", StopInfo(call * m * dth, _mode(functions, z[6:6 + n_g]),
                                                       _out_of_time(settings, t_wall))
                break
            edges = theta_start + rev * 2 * np.pi + dth * (c * m + np.arange(m + 1))
            P = _pressures(pressure, edges)
            if hasattr(engine, "deadline"):
                engine.deadline = deadline
            try:
                out = engine.run(z, params, edges[0], P)
                Z, stats, failure = out.z, out.stats, None
            except WallTimeExceeded as late:
                Z, stats = late.partial, {}
                last = Z[6:6 + n_g, -1] if Z.shape[1] else z[6:6 + n_g]
                failure = "interrupted", StopInfo(edges[Z.shape[1]] - theta_start, _mode(functions, last),
                                                  _out_of_time(settings, t_wall))
            except RuntimeError as err:
                Z, failure = _locate_failure(functions, settings, params, z, edges, P, err, deadline, theta_start)
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
                                      "samples_per_revolution": N, "calls_per_revolution": calls,
                                      "wall_time_s": wall, "solver_stats": stats_total,
                                      "compiled": bool(getattr(engine, "compiled", False))}
    return result


def _out_of_time(settings: RunSettings, t_wall: float, doing: str = "") -> str:
    return (f"wall-time budget used up: max_wall_time = {settings.max_wall_time:g} s (after "
            f"{time.perf_counter() - t_wall:.1f} s{doing})")


def _pressures(pressure, edges: np.ndarray) -> np.ndarray:
    if pressure is None:
        return np.zeros((2, edges.size - 1))
    return np.asarray(pressure(edges), float)


def _mode(functions, closed) -> str:
    return Mode(tuple(bool(float(c) > 0.5) for c in closed), tuple(functions.guard_names)).label


def _preflight(functions, settings: RunSettings, params, theta, X, closed, u) -> StopInfo | None:
    """Refuse to start what cannot give a meaningful result, with the reason.

    * NaN/Inf in the right-hand side;
    * explicit Euler with a step that amplifies a contact oscillation more than
      MAX_GROWTH times per revolution (runtime/euler_integrator.contact_growth);
    * NaN/Inf in the derivative of the right-hand side, for every method but the
      fixed-step ones without Jacobians (euler, rk): an infinite partial derivative
      with respect to a parameter (a function of the parameters at the edge of its domain,
      such as asin(1); beta_o = asin(Ws/(2 ro)) at ro = Ws/2 was one until it became a
      derived parameter) turns every automatic derivative into 0 * inf = NaN, although
      the right-hand side is finite.
    """
    mode = _mode(functions, closed)
    xdot = np.array(functions.rhs(theta, X, closed, params, u)).ravel()
    if not np.isfinite(xdot).all():
        return StopInfo(0.0, mode, "the right-hand side is not finite at the start (NaN or Inf in "
                        f"{_names(functions.state_names, ~np.isfinite(xdot))}): check the scene's values")
    if settings.method == "euler":
        worst = contact_growth(params, settings.steps_per_revolution)[0]
        if worst.log_growth > math.log(MAX_GROWTH):
            return StopInfo(0.0, mode, worst.describe(settings.steps_per_revolution))
    if settings.method not in _NEEDS_DERIVATIVES:
        return None
    try:  # SX Functions; compiled externals may have no derivatives to check
        seeds = [1.0, np.ones(6), *(np.zeros(functions.rhs.size1_in(i)) for i in (2, 3, 4))]
        d = np.array(functions.rhs.forward(1)(theta, X, closed, params, u, xdot, *seeds)).ravel()
        if np.isfinite(d).all():
            return None
        p = functions.rhs.sx_in(3)
        J = np.array(ca.Function("jac_p", [p], [ca.jacobian(functions.rhs(theta, X, closed, p, u), p)])(params))
    except (RuntimeError, NotImplementedError, TypeError):
        return None
    culprits = _names(functions.parameter_names, ~np.isfinite(J).all(axis=0)) or "(none found)"
    return StopInfo(0.0, mode, f"the derivative of the right-hand side is not finite at the start although its value is "
                    f"(an infinite partial derivative with respect to {culprits}, which automatic differentiation turns "
                    f"into 0*inf = NaN); method {settings.method!r} needs derivatives. The scene sits on the edge of "
                    "the model's domain, where a function of these parameters has an infinite slope: move it off the "
                    "edge by a relative 1e-9 (nothing measurable changes) or use method 'euler'")


def _names(names, mask) -> str:
    return ", ".join(n for n, m in zip(names, mask, strict=True) if m)


class _Checks:
    """What is checked after every integrator call: finite states, chattering, missed events, the event budget."""

    def __init__(self, functions, settings: RunSettings, params, theta_start: float, n_g: int):
        self.functions, self.settings, self.params = functions, settings, params
        self.theta_start, self.n_g = theta_start, n_g
        self.omega = float(params[OMEGA])

    def finite(self, Z, thetas) -> tuple[np.ndarray, tuple | None]:
        """Z up to its first non-finite sample, and the failure it means (None if all finite)."""
        ok = np.isfinite(Z).all(axis=0)
        if ok.all():
            return Z, None
        k = int(np.argmin(ok))
        last = Z[6:6 + self.n_g, k - 1] if k else np.zeros(self.n_g)
        reason = f"non-finite state (NaN or Inf) at {np.degrees(thetas[k] - self.theta_start):.3f} deg"
        if self.settings.method == "euler":
            reason += "; " + contact_growth(self.params, self.settings.steps_per_revolution)[0].describe(
                self.settings.steps_per_revolution)
        return Z[:, :k], ("failed", StopInfo(thetas[k] - self.theta_start, _mode(self.functions, last), reason))

    def events(self, Z, z_start, thetas, P, z_rev) -> tuple | None:
        """Chattering, a missed contact event, or more events in this revolution than allowed."""
        if not Z.shape[1]:
            return None
        n_g, st = self.n_g, self.settings
        chatter = _chattering(Z, n_g, thetas - self.theta_start, z_start[6 + n_g:], st, self.functions)
        if chatter is not None:
            return "chattering", StopInfo(chatter.theta, _mode(self.functions, Z[6:6 + n_g, -1]), str(chatter))
        if METHODS[st.method][1] != "euler":
            missed = self.missed_event(Z, thetas, P)
            if missed is not None:
                return missed
        in_rev = Z[6 + n_g:] - z_rev[6 + n_g:, None]  # switches of each guard since the revolution began
        over = in_rev.sum(axis=0) > st.max_events_per_revolution
        if over.any():
            k = int(np.argmax(over))  # the sample where the budget ran out
            i = int(np.argmax(in_rev[:, k]))
            where = float(thetas[k] - self.theta_start)
            c = Chattering(self.functions.guard_names[i], where, int(in_rev[i, k]),
                           f"in less than one revolution (of {int(in_rev[:, k].sum())} > max_events_per_revolution = "
                           f"{st.max_events_per_revolution})")
            return "chattering", StopInfo(where, _mode(self.functions, Z[6:6 + n_g, k]), str(c))
        return None

    def missed_event(self, Z, thetas, P) -> tuple | None:
        """A contact the integrator holds open while its gap is negative: a lost event (the seal would pass the wall)."""
        n, n_g = Z.shape[1], self.n_g
        X = to_physical(Z[:6], self.omega)
        g = np.array(self.functions.guards.map(n)(thetas[None, :], X, np.repeat(self.params[:, None], n, 1), P))
        bad = (Z[6:6 + n_g] < 0.5) & (g / LENGTH < -_MISSED_EVENT_UM)
        if not bad.any():
            return None
        i, k = (int(v[0]) for v in np.nonzero(bad))
        return "failed", StopInfo(thetas[k] - self.theta_start, _mode(self.functions, Z[6:6 + n_g, k]),
                                  f"missed contact event: guard {self.functions.guard_names[i]} is open in the "
                                  f"integrator's mode but its gap is {g[i, k] / LENGTH:.4g} µm (a bug: please report "
                                  "the scene)")


def _chattering(Z, n_g, thetas, counts_before, settings: RunSettings, functions) -> Chattering | None:
    counts = np.c_[counts_before, Z[6 + n_g:]]
    per_interval = np.diff(counts, axis=1)
    dth = thetas[1] - thetas[0] if thetas.size > 1 else 2 * np.pi / settings.samples_per_revolution
    # events per output interval, scaled to the chatter window
    limit = settings.chatter_events * max(1.0, dth / settings.chatter_window)
    hot = np.argwhere(per_interval > limit)
    if hot.size == 0:
        return None
    i, k = hot[0]
    return Chattering(functions.guard_names[i], float(thetas[k]), int(per_interval[i, k]))


def _locate_failure(functions, settings, params, z, edges, P, err, deadline, theta_start):
    """Re-run a failed call interval by interval with the interpreted integrator.

    Returns the samples computed and the stop (status, StopInfo) at the first interval
    that fails on its own, with the reason diagnosed; or every sample and no stop when
    each interval passes alone (the run goes on from there).
    """
    n_g = functions.guards.size1_out(0)
    dth = edges[1] - edges[0]
    single = make_engine(functions, settings, n_samples=1, span=dth, compile_c=False)
    if hasattr(single, "deadline"):
        single.deadline = deadline
    cols = []
    for k in range(edges.size - 1):
        where = StopInfo(edges[k] - theta_start, _mode(functions, z[6:6 + n_g]), "")
        if time.perf_counter() > deadline:
            where.reason = _out_of_time(settings, deadline - settings.max_wall_time, ", while re-running a failed call "
                                        f"interval by interval; the call failed with: {_last_line(err)}")
            return _cols(cols, z), ("interrupted", where)
        try:
            out = single.run(z, params, edges[k], P[:, k:k + 1])
        except WallTimeExceeded:
            where.reason = _out_of_time(settings, deadline - settings.max_wall_time, ", while re-running a failed call "
                                        "interval by interval")
            return _cols(cols, z), ("interrupted", where)
        except RuntimeError as e:
            status, where.reason = _diagnose(functions, settings, single, e, z, edges[k], dth, params, P[:, k],
                                             theta_start, deadline)
            return _cols(cols, z), (status, where)
        z = out.z[:, -1]
        cols.append(z.copy())
    return _cols(cols, z), None


def _cols(cols, z):
    return np.array(cols).T if cols else np.zeros((z.size, 0))


def _last_line(err) -> str:
    text = str(err).strip()
    return text.splitlines()[-1] if text else repr(err)


def _diagnose(functions, settings: RunSettings, engine, err, z, theta, dth, params, u,
              theta_start: float, deadline: float = math.inf) -> tuple[str, str]:
    """(status, reason) of one output interval that failed, from the interpreted integrator's statistics.

    Compiled integrators only say 'Evaluation failed'; the interpreted one counts
    its steps, rejections and events, which tell an event limit (chattering) and a
    step limit (too stiff) apart. Otherwise the longest head of the interval that
    still passes shows whether the model itself turns non-finite just ahead (the
    state has left the model's domain). The search for that head stops at the
    wall-time ``deadline`` with what it has found.
    """
    msg = _last_line(err)
    try:
        stats = dict(engine.function.stats())
    except Exception:  # noqa: BLE001 - the stepper engines have no single function
        stats = {}
    n_g = functions.guards.size1_out(0)
    where = f"{np.degrees(theta - theta_start):.3f} deg"
    if not _finite_ahead(functions, z, theta, params, u):
        return "failed", f"the right-hand side is not finite at {where}: {msg}"
    if "max_events" in str(err) or stats.get("n_events", 0) >= settings.max_events_per_revolution:
        z_end, _ = _longest_head(functions, settings, params, z, theta, dth, u, deadline)
        switches = z_end[6 + n_g:] - z[6 + n_g:]
        guard = functions.guard_names[int(np.argmax(switches))] if switches.any() else "(unknown)"
        c = Chattering(guard, theta - theta_start, int(switches.max()), f"in {np.degrees(dth):.3g} deg or less (more "
                       f"than max_events_per_revolution = {settings.max_events_per_revolution} in one output interval)")
        return "chattering", str(c)
    if stats.get("n_steps", 0) >= settings.max_steps_per_interval:
        return "failed", (f"step limit: more than max_steps_per_interval = {settings.max_steps_per_interval} steps in "
                          f"one output interval; the problem is too stiff for {settings.method!r} here: use method "
                          "'rosenbrock' (stiff contacts, a small friction.v_eps) or a larger friction.v_eps")
    z_end, head = _longest_head(functions, settings, params, z, theta, dth, u, deadline)
    if not _finite_ahead(functions, z_end, theta + head, params, u):
        omega = float(params[OMEGA])
        x, y, phi = to_physical(z_end[:6], omega)[:3]
        g = np.array(functions.guards(theta + head, to_physical(z_end[:6], omega), params, u)).ravel()
        g[[i for i, name in enumerate(functions.guard_names) if name == "spring"]] = np.inf  # compressed by design
        deepest = int(np.argmin(g))
        return "failed", (f"the state leaves the model's domain at {np.degrees(theta + head - theta_start):.3f} deg: "
                          f"the right-hand side turns non-finite just ahead of x = {x * 1e6:.4g} um, y = {y * 1e6:.4g} "
                          f"um, phi = {phi * 1e3:.4g} mrad (deepest contact {functions.guard_names[deepest]}: "
                          f"{-g[deepest] * 1e6:.4g} um); contacts this soft for these loads let the seal go where the "
                          "geometry of Eqs. 20-43 no longer holds: stiffer contacts (contacts.kw, kg1..kg4) or a lower "
                          f"speed (CasADi: {msg})")
    if stats.get("n_reject", 0):
        return "failed", (f"the step size fell below its minimum after {stats.get('n_steps', 0)} steps and "
                          f"{stats['n_reject']} rejected ones (CasADi: {msg})")
    return "failed", f"solver failed: {msg}"


def _finite_ahead(functions, z, theta, params, u) -> bool:
    """The right-hand side is finite at z and along its direction a little ahead (1e-9 .. 1e-7 s)."""
    n_g = functions.guards.size1_out(0)
    X = to_physical(z[:6], float(params[OMEGA]))
    xdot = np.array(functions.rhs(theta, X, z[6:6 + n_g], params, u)).ravel()
    if not (np.isfinite(z).all() and np.isfinite(xdot).all()):
        return False
    return all(np.isfinite(np.array(functions.rhs(theta, X + h * xdot, z[6:6 + n_g], params, u))).all()
               for h in (1e-9, 1e-8, 1e-7))


def _longest_head(functions, settings: RunSettings, params, z, theta, dth, u,
                  deadline: float = math.inf) -> tuple[np.ndarray, float]:
    """The state at the end of the longest head of a failing interval that the interpreted integrator passes,
    and the head's length: bisection on the length, 12 halvings or until the deadline (z itself and 0 when no
    head passes)."""
    lo, hi, end = 0.0, dth, z
    for _ in range(12):
        if time.perf_counter() > deadline:
            break
        mid = 0.5 * (lo + hi)
        try:
            out = make_engine(functions, settings, n_samples=1, span=mid, compile_c=False).run(
                z, params, theta, u[:, None])
        except RuntimeError:
            hi = mid
            continue
        lo, end = mid, out.z[:, -1]
    return end, lo


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
