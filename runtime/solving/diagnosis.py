"""When an integrator call fails: re-run it interval by interval, keep what passes, and name the reason.

Compiled integrators only say 'Evaluation failed'; the interpreted one counts its steps, rejections and
events, which tell an event limit (chattering) and a step limit (too stiff) apart. Otherwise the longest
head of the interval that still passes shows whether the model itself turns non-finite just ahead (the state
has left the model's domain). Every search stops at the run's wall-time deadline, or at a SIGINT or SIGTERM
(:mod:`.signals`), with what it has found.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ...generated.layout import HybridLayout
from ...generated.scaling import to_physical
from ...progress import announce
from ...signals import StopSignals
from ..results.plausibility import METAL_STIFFNESS
from ..results.result import StopInfo
from .checks import Chattering, chatter_advice, tilt_reason
from .methods import WallTimeExceeded, edge_params, first_params, make_engine, single_interval_engine
from .preflight import MAX_START_PENETRATION, penetration_guards
from .settings import MAX_TILT, RunSettings, out_of_time


def locate_failure(functions, settings, params, z, edges, P, err, deadline, theta_start, make=make_engine,
                   counts_before=None, advance=None):
    """Re-run a failed call interval by interval (see the module docstring).

    ``make`` builds the engines (the run's engine factory, so that what is re-run is what ran). The intervals are
    re-run compiled where the run compiles and has no wall-time budget (:func:`_compiled_single`: a compiled
    revolution of erk at 1 rpm ran at 3.05 deg/s, 7 times as fast as the interpreted re-run); an
    interval that fails is re-run interpreted, whose statistics the diagnosis reads.

    ``counts_before``: the hybrid state's event counts when the revolution began; the re-run stops after the
    interval in which the revolution's events pass ``max_events_per_revolution``, the cap at which CasADi's call
    stops too (a compiled call only says 'Evaluation failed'; re-run interval by interval, each with a cap of its
    own, every interval passed, and only after the whole revolution did the run's event check name the cap). The
    samples then end there, with no stop: the run's event check stops the run at that sample, naming the cap.
    ``advance(k)`` (optional) is called after each of the first k intervals passed: the run's progress.

    Returns the samples computed and the stop (status, StopInfo) at the first interval
    that fails on its own, with the reason diagnosed; or the samples and no stop when
    each interval passes alone (the run goes on from there).
    """
    what, t0 = f"re-running a failed integrator call ({edges.size - 1} output intervals) interval by interval", \
        time.perf_counter()
    fast = _compiled_single(functions, settings, edges[1] - edges[0], make, deadline)
    announce(f"{what}, {'compiled' if fast is not None else 'interpreted'} ...")
    with StopSignals() as signals:
        Z, stop = _interval_by_interval(functions, settings, params, z, edges, P, err, deadline, theta_start, make,
                                        signals, fast, counts_before, advance)
    outcome = (f"{stop[0]} at {np.degrees(stop[1].theta):.3f} deg" if stop is not None else "every interval passed"
               if Z.shape[1] == edges.size - 1 else "the revolution's events passed max_events_per_revolution = "
               f"{settings.max_events_per_revolution}, the cap of CasADi's call")
    announce(f"{what}: {outcome}, {Z.shape[1]} passed, in {time.perf_counter() - t0:.1f} s")
    return Z, stop


def _compiled_single(functions, settings, dtheta: float, make, deadline: float):
    """A compiled engine of one interval of ``dtheta`` rad for the re-run, or None: for an interpreted run, under a
    wall-time budget (no compiling while it runs out, as runtime/solving/pace.py) and where nothing compiles."""
    if not settings.compile_c or math.isfinite(deadline):
        return None
    try:
        engine = make(functions, settings, n_samples=1, span=dtheta, compile_c=True)
    except (RuntimeError, OSError):  # the interpreted re-run is the fallback of a compilation that failed too
        return None
    return engine if engine.compiled else None


def _interval_by_interval(functions, settings, params, z, edges, P, err, deadline, theta_start, make, signals,
                          fast=None, counts_before=None, advance=None):
    lay = HybridLayout.of(functions)
    dth = edges[1] - edges[0]
    linear = int(P.shape[1] == edges.size)  # pressure = "linear": the values at the edges, one more than intervals
    single = single_interval_engine(functions, settings, dth, make)
    single.deadline = deadline if not signals.requested else -math.inf
    context = f", while re-running a failed call interval by interval; the call failed with: {_last_line(err)}"
    with signals.watching(single):  # a signal stops it at its next deadline check
        cols = []
        for k in range(edges.size - 1):
            where = StopInfo(edges[k] - theta_start, lay.mode(z[lay.active]), "")
            if signals.requested or time.perf_counter() > deadline:
                where.reason = _stopped(signals, settings, deadline, context)
                return _cols(cols, z), ("interrupted", where)
            try:
                try:
                    out = (fast or single).run(z, edge_params(params, k), edges[k], P[:, k:k + 1 + linear])
                except RuntimeError as e:
                    if fast is None or isinstance(e, WallTimeExceeded):
                        raise
                    out = single.run(z, edge_params(params, k), edges[k], P[:, k:k + 1 + linear])  # statistics
            except WallTimeExceeded:
                where.reason = _stopped(signals, settings, deadline, context)
                return _cols(cols, z), ("interrupted", where)
            except RuntimeError as e:
                status, where.reason = _diagnose(functions, settings, single, e, z, edges[k], dth,
                                                 edge_params(params, k), P[:, k:k + 1 + linear], theta_start,
                                                 deadline, make)
                if signals.requested:  # the diagnosis was cut short: the signal is the run's reason
                    status, where.reason = "interrupted", _stopped(signals, settings, deadline, ", while diagnosing a "
                                                                   f"failed interval ({where.reason})")
                return _cols(cols, z), (status, where)
            z = out.z[:, -1]
            cols.append(z.copy())
            if advance is not None:
                advance(k + 1)
            if counts_before is not None and (z[lay.counts] - counts_before).sum() > settings.max_events_per_revolution:
                break  # the run's event check names the cap
        return _cols(cols, z), None


def _stopped(signals, settings: RunSettings, deadline: float, context: str) -> str:
    """The reason of a re-run stopped early: the signal it got, or the wall-time budget."""
    if signals.requested:
        return signals.reason() + context
    return out_of_time(settings, deadline - settings.max_wall_time, context)


def _cols(cols, z):
    return np.array(cols).T if cols else np.zeros((z.size, 0))


def _last_line(err) -> str:
    text = str(err).strip()
    return text.splitlines()[-1] if text else repr(err)


def _diagnose(functions, settings: RunSettings, engine, err, z, theta, dth, line, P,
              theta_start: float, deadline: float = math.inf, make=make_engine) -> tuple[str, str]:
    """(status, reason) of one output interval that failed, from the interpreted integrator's statistics.

    ``P`` is the interval's pressure input as the engine takes it: (2, 1), its mean, or (2, 2), its values at
    the two ends (``pressure = "linear"``); ``line`` the parameters likewise: the vector, or its values at the
    two ends (a scene's schedule).

    Compiled integrators only say 'Evaluation failed'; the interpreted one counts
    its steps, rejections and events, which tell an event limit (chattering) and a
    step limit (too stiff) apart. Otherwise the longest head of the interval that
    still passes shows whether the model itself turns non-finite just ahead (the
    state has left the model's domain). The search for that head stops at the
    wall-time ``deadline`` with what it has found.
    """
    msg = _last_line(err)
    u = P[:, 0]  # the pressures at the interval's start, as the run sees them
    params = first_params(line)  # the parameters there
    try:
        stats = dict(engine.function.stats())
    except Exception:  # noqa: BLE001 - the stepper engines have no single function
        stats = {}
    lay = HybridLayout.of(functions)
    where = f"{np.degrees(theta - theta_start):.3f} deg"
    if not _finite_ahead(functions, z, theta, params, u):
        if np.isfinite(z).all() and np.isfinite(u).all():  # a state the call reached, outside the model's domain
            return "failed", _leaves_domain(functions, z, theta, theta_start, params, u, msg)
        return "failed", f"the right-hand side is not finite at {where}: {msg}"
    if "max_events" in str(err) or stats.get("n_events", 0) >= settings.max_events_per_revolution:
        z_end, head = _longest_head(functions, settings, line, z, theta, dth, P, deadline, make)
        switches = z_end[lay.counts] - z[lay.counts]
        guard = functions.guard_names[int(np.argmax(switches))] if switches.any() else "(unknown)"
        # the integrator stopped at its event limit inside the interval; the longest head of it that passes on its
        # own shows which contact switched, and how often there (the rest of the interval is not counted)
        c = Chattering(guard, theta - theta_start, int(switches.max()), f"in the first {np.degrees(head):.3g} deg "
                       f"of a {np.degrees(dth):.3g}-deg output interval whose switches reached the integrator's event "
                       f"limit (max_events_per_revolution = {settings.max_events_per_revolution})",
                       chatter_advice(guard, functions.parameter_names, params))
        return "chattering", str(c)
    if stats.get("n_steps", 0) >= settings.max_steps_per_interval or "step limit" in msg:  # (the composite says so)
        advice = ("use method 'rosenbrock' (stiff contacts, a small friction.v_eps) or a larger friction.v_eps"
                  if settings.method != "rosenbrock" else "a larger friction.v_eps, softer contacts or a larger "
                  "solver.rtol; or raise max_steps_per_interval if the stiffness is physical")
        return "failed", (f"step limit: more than max_steps_per_interval = {settings.max_steps_per_interval} steps in "
                          f"one output interval; the problem is too stiff for {settings.method!r} here: {advice}")
    z_end, head = _longest_head(functions, settings, line, z, theta, dth, P, deadline, make)
    if not _finite_ahead(functions, z_end, theta + head, params, u):
        return "failed", _leaves_domain(functions, z_end, theta + head, theta_start, params, u, msg)
    where_seal, depth = _seal_at(functions, z_end, theta + head, params, u)
    phi = to_physical(z_end[lay.x], functions.omega(params), lay.state_names)[2]
    if abs(phi) > MAX_TILT:  # turned over inside the interval, before the run's check at its samples could see it
        return "failed", f"{tilt_reason(phi, theta + head - theta_start)} (CasADi: {msg})"
    deep = ("" if depth <= MAX_START_PENETRATION * params[list(functions.parameter_names).index("Ws")] else
            f"; the seal is that deep inside a wall: {_soft_advice(functions, params)}")
    if stats.get("n_reject", 0):
        return "failed", (f"the step size fell below its minimum after {stats.get('n_steps', 0)} steps and "
                          f"{stats['n_reject']} rejected ones, {head_at(head)}{where_seal}{deep} (CasADi: {msg})")
    return "failed", f"solver failed {head_at(head)}{where_seal}{deep} (CasADi: {msg})"


def _head(values: np.ndarray, frac: float) -> np.ndarray:
    """An interval's input over its first ``frac``: a column (held) or a vector as it is; the values at the
    interval's two ends as those at the ends of the head, on the interval's line."""
    V = np.asarray(values, float)
    if V.ndim == 1 or V.shape[1] == 1:
        return V
    return np.c_[V[:, 0], V[:, 0] + (V[:, 1] - V[:, 0]) * frac]


def head_at(head: float) -> str:
    return f"{np.degrees(head):.4g} deg into the interval, "


#: the advice where the seal sinks into a wall or leaves the model's domain, on contacts softer than metal
SOFT_CONTACTS = ("contacts this soft for these loads let the seal go where the geometry of Eqs. 20-43 no longer "
                 "holds: stiffer contacts (contacts.kw, kg1..kg4) or a lower speed")
#: the same on metal contacts (:data:`~..results.plausibility.METAL_STIFFNESS`): then the loads are the cause
OVERLOADED = ("the loads drive the seal where the geometry of Eqs. 20-43 no longer holds, although its contacts are "
              "as stiff as metal: a lower speed, or the scene's pressures (their unit) and preload as meant; its "
              "plausibility warnings at the start name doubtful keys")


def _soft_advice(functions, params) -> str:
    """:data:`SOFT_CONTACTS`, or :data:`OVERLOADED` when every contact stiffness of ``params`` is a metal's, or, for
    a model without the groove contacts (``effects.groove_contact`` off, their stiffnesses not among its
    parameters), that nothing holds the seal across its groove."""
    names = list(functions.parameter_names)
    if "kg1" in names:
        stiffnesses = [float(params[names.index(k)]) for k in ("kw", "kg1", "kg2", "kg3", "kg4") if k in names]
        return OVERLOADED if min(stiffnesses) >= METAL_STIFFNESS else SOFT_CONTACTS
    return ("with effects.groove_contact off nothing holds the seal across its groove, and it drifts out of the "
            "geometry of Eqs. 20-43: switch the groove contact on (contacts.kg1..kg4)")


def _seal_at(functions, z, theta, params, u) -> tuple[str, float]:
    """Where the seal is in state ``z`` at crank angle ``theta`` ("at x = ... um, ..., deepest contact ...") and the
    depth (m) of its deepest contact inside its wall (the spring's compression, closed at rest, is not one)."""
    lay = HybridLayout.of(functions)
    X = to_physical(z[lay.x], functions.omega(params), lay.state_names)
    x, y, phi = X[:3]
    g = np.array(functions.guards(theta, X, params, u)).ravel()
    g = np.where(np.isin(np.arange(g.size), penetration_guards(functions.guard_names)), g, np.inf)
    deepest = int(np.argmin(g))
    return (f"at x = {x * 1e6:.4g} um, y = {y * 1e6:.4g} um, phi = {phi * 1e3:.4g} mrad (deepest contact "
            f"{functions.guard_names[deepest]}: {-g[deepest] * 1e6:.4g} um)"), float(-g[deepest])


def _leaves_domain(functions, z, theta, theta_start, params, u, msg) -> str:
    """The reason of a failure where the right-hand side turns non-finite just ahead of the finite state ``z`` at
    crank angle ``theta``: where the seal is, its deepest contact, and what to change."""
    where_seal, _ = _seal_at(functions, z, theta, params, u)
    return (f"the state leaves the model's domain at {np.degrees(theta - theta_start):.3f} deg: the right-hand side "
            f"turns non-finite just ahead, {where_seal}; {_soft_advice(functions, params)} (CasADi: {msg})")


def _finite_ahead(functions, z, theta, params, u) -> bool:
    """The right-hand side is finite at z and along its direction a little ahead (1e-9 .. 1e-7 s)."""
    lay = HybridLayout.of(functions)
    X = to_physical(z[lay.x], functions.omega(params), lay.state_names)
    xdot = np.array(functions.rhs(theta, X, z[lay.active], params, u)).ravel()
    if not (np.isfinite(z).all() and np.isfinite(xdot).all()):
        return False
    return all(np.isfinite(np.array(functions.rhs(theta, X + h * xdot, z[lay.active], params, u))).all()
               for h in (1e-9, 1e-8, 1e-7))


def _longest_head(functions, settings: RunSettings, line, z, theta, dth, P,
                  deadline: float = math.inf, make=make_engine) -> tuple[np.ndarray, float]:
    """The state at the end of the longest head of a failing interval that the interpreted integrator passes,
    and the head's length: bisection on the length, 12 halvings or until the deadline (z itself and 0 when no
    head passes). ``P``, ``line``: the interval's pressure and parameter input (see :func:`_diagnose`); a head of
    a "linear" interval ends at the value on the interval's line."""
    lo, hi, end = 0.0, dth, z
    for _ in range(12):
        if time.perf_counter() > deadline or StopSignals.pending():
            break
        mid = 0.5 * (lo + hi)
        try:
            engine = single_interval_engine(functions, settings, mid, make)
            engine.deadline = deadline
            with StopSignals() as signals, signals.watching(engine):
                out = engine.run(z, _head(line, mid / dth), theta, _head(P, mid / dth))
        except WallTimeExceeded:
            break
        except RuntimeError:
            hi = mid
            continue
        lo, end = mid, out.z[:, -1]
    return end, lo

