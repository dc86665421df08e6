"""Run a scene: call by call, with progress, failure capture, chattering detection and a wall-time budget.

``simulate(scene)`` integrates the hybrid model with the scene's method (see
:mod:`.methods`) and returns a :class:`SimulationResult`. A revolution is one
integrator call, or ``calls_per_revolution`` calls (36, 10 degrees each, when a
wall-time budget is set, so the budget is checked often enough; once the next call would end past the deadline,
calls interval by interval, :mod:`.pace`; 36 too for a run far costlier than the default scene's, announced before its
first step, :mod:`.cost`). Nothing computed is lost, and every
run ends with a named reason: on SIGINT or SIGTERM (acted on between calls, :mod:`.signals`), a solver
failure, a non-finite state, a fixed-step method's step beyond a sticking friction's (:mod:`.friction_stability`), a missed
contact event, chattering or a used-up wall-time budget, the result keeps
every finished sample and says where (crank angle, contact case) and why it
stopped (docs/hard-cases.md lists what each reason means and what to do).
The checks after each call are in :mod:`.checks`, the diagnosis of a failed call in :mod:`.diagnosis`.
Each completed revolution is assembled and handed to a sink at once (runtime/results/parts.py; streamed to disk
by runtime/results/folder.py), so the loop holds one revolution whatever the length of the run.
"""

from __future__ import annotations

import contextlib
import functools
import math
import sys
import time
import warnings

import numpy as np

from ...generated.layout import HybridLayout
from ...generated.scaling import to_scaled
from ...progress import advanced, bar_output, stage
from ...signals import StopSignals
from ..results.assemble import assemble_blocks
from ..results.folder import ResultStorageError
from ..results.parts import InMemory
from ..results.result import SimulationResult, StopInfo
from . import engine_pool
from .accuracy import accuracy
from .checks import RunChecks
from .cost import SlowRunWarning, estimate, slow_rotor_note
from .diagnosis import locate_failure
from .methods import WallTimeExceeded, edge_params, make_engine
from .near_chatter import SwitchClusters
from .pace import FailedInterval, IntervalByInterval, Pace
from .periodicity import PeriodicWatch
from .preflight import far_outside_practice, initial_activations, preflight
from .ringing import ringing, sampling
from .settings import RunSettings, out_of_time, samples_per_call

#: samples from which a run says that it joins its result once the revolutions' bar has ended (about a second
#: and more: 3.3 s for 300 revolutions of 3600 samples)
LONG_RESULT = 500_000
#: integrator calls per revolution of a run announced as slow (runtime/solving/cost.py) that sets none: 10 degrees
#: each, as under a wall-time budget, so that its bar moves within a revolution (a whole revolution of erk at 1 rpm
#: was one call of 52 s, the bar at 0 all along) and a failed call's re-run covers 10 degrees at most
SLOW_CALLS = 36
#: seconds between the progress reports of a failed call's re-run, interval by interval
RERUN_REPORT = 0.2


def run(functions, params: np.ndarray, settings: RunSettings, *, theta_start: float, state0: np.ndarray,
        revolutions: int | None = None, pressure=None, until_periodic: bool = False, periodic_tol: float = 3e-2,
        progress: bool = False, engine=None, info: dict | None = None, sink=None,
        pressure_values=None, continue_from: tuple | None = None, path=None) -> SimulationResult:
    """Integrate ``revolutions`` (default ``settings.revolutions``) revolutions from ``state0`` (physical) at crank
    angle ``theta_start``.

    ``continue_from = (k, z)`` or ``(k, z, carried)`` continues a run that completed ``k`` revolutions from its
    integrator state ``z`` after them and what its engine carried into the next call (``carried``, see
    :meth:`.methods.Engine.carried`; None or left out: nothing) (runtime/results/continuation.py): revolutions
    k+1 .. ``revolutions``, each call made as the uninterrupted run makes it, so the samples are the same to the
    bit; the sink holds the first k already. Each part goes to the sink with its end state and what the engine
    carries from it (``sink.append(part, z_end, carried)``).

    ``engine`` (optional) must cover a whole number of output intervals that divides a revolution; without it,
    the run builds its own, on a grid at least as fine as the pressure table (:func:`pressure_substeps`). ``sink``
    receives each completed revolution as it is assembled (default: kept in memory; a
    :class:`~..results.folder.ResultFolder` writes it to disk and keeps none in memory). ``pressure`` is the
    scene's pressure source (``scene.pressure``: its ``interval_means(edges)`` and its values ``pressure(theta)``,
    whichever ``settings.pressure`` integrates), or a function giving the means over intervals (``pressure(edges)``)
    with ``pressure_values(theta)`` giving the values at crank angles for ``settings.pressure = "linear"``; None:
    no chamber pressure. ``path`` (a scene's schedule, ``Scene.parameter_path``; None: none) gives the parameters
    at given crank angles: each call then takes their values at its interval edges (an engine whose
    ``parameter_profiles`` hold "linear"), and the start checks and the outputs take them where they are.
    """
    if revolutions is not None:
        settings = settings.replace(revolutions=revolutions)
    revolutions = settings.revolutions
    sink = sink if sink is not None else InMemory()
    lay = HybridLayout.of(functions)
    omega = functions.omega(params)
    N = settings.samples_per_revolution
    sub = pressure_substeps(pressure, N) if engine is None else 1
    dth = 2 * np.pi / (N * sub)  # the integrator's intervals: sub of them per output interval
    t_wall = time.perf_counter()
    deadline = t_wall + settings.max_wall_time if settings.max_wall_time else math.inf
    if hasattr(pressure, "interval_means"):  # a pressure source: its means and its values
        pressure, pressure_values = pressure.interval_means, pressure_values or pressure
    if settings.pressure == "linear" and pressure is not None and pressure_values is None:
        raise ValueError("pressure = 'linear' needs pressure_values, the chamber pressures at given crank angles")
    values, linear = pressure_values, settings.pressure == "linear"
    u0 = _pressures(pressure, theta_start + np.array([0.0, dth]), values, linear)[:, 0]
    p0 = params if path is None else path(theta_start)[:, 0]  # the parameters at the start
    z = lay.pack(to_scaled(state0, omega, lay.state_names), initial_activations(functions, theta_start, state0, p0, u0))
    ring = ringing(functions, p0, theta_start, state0)  # for the speed check and the sampling record
    if continue_from is None:
        done = 0  # revolutions in the sink before the first call
        part = _Part(functions, params, theta_start, omega, sink, first=z.copy(), first_pressures=u0, path=path)
        stop = preflight(functions, settings, p0, theta_start, state0, z[lay.active], u0, dth, ring)
    else:  # the run was checked when it started from its scene's state
        done, z = continue_from[0], np.array(continue_from[1], float)
        carried = continue_from[2] if len(continue_from) > 2 else None
        part = _Part(functions, params, theta_start, omega, sink, first=None, first_pressures=None, path=path)
        part.after(done * 2 * np.pi, z, carried)
        stop = None
    cost = estimate(ring, omega, settings, done)  # said before the first step, where it is far above the default's
    note = slow_rotor_note(cost, ring, omega) if stop is None else None
    if note is not None:
        warnings.warn(note, SlowRunWarning, stacklevel=3)
        if engine is None and settings.calls_per_revolution is None and not settings.max_wall_time:
            settings = settings.replace(calls_per_revolution=SLOW_CALLS)  # the bar moves within a revolution
    status = "completed" if stop is None else "failed"
    leased = None
    if engine is None and stop is None:  # no compiling for a run that cannot start
        m = samples_per_call(settings) * sub
        with StopSignals.abandoning():  # nothing computed yet: a signal abandons the integrator's compilation
            leased = engine_pool.lease(functions, settings, n_samples=m, span=m * dth, make=make_engine)
        engine = leased.engine
    if continue_from is not None and engine is not None:
        _carry_on(engine, z, carried)  # its first call is the one the uninterrupted run made there
    t_engine = time.perf_counter()
    m = engine.n_samples if engine is not None else N * sub
    if (N * sub) % m:
        raise ValueError(f"the engine covers {m} output intervals, which do not divide samples_per_revolution = {N}")
    calls = N * sub // m
    info = dict(info or {}) | {"state_names": list(lay.state_names), "method": settings.method,
                               "rtol": settings.rtol, "atol": settings.atol, "samples_per_revolution": N,
                               "pressure_substeps": sub, "pressure": settings.pressure, "calls_per_revolution": calls,
                               "revolutions_asked": revolutions,
                               # its error control, and what a loose tolerance or a fixed step costs (accuracy.py)
                               "accuracy": accuracy(settings),
                               # erk's steps and time, where they follow the ringing (runtime/solving/cost.py)
                               "cost_estimate": None if cost is None else cost.record(),
                               # do the samples resolve the contacts' ringing (runtime/solving/ringing.py)?
                               "sampling": None if stop is not None else sampling(functions, params, ring, N),
                               # refused by the start check (preflight): the scene's values decide it, no rerun can
                               # change it (a sweep's point is then "invalid", not one to retry)
                               "refused_at_start": stop is not None}
    sink.begin(info)  # what is known before the first step: a killed run's progress record says how it was run
    stats_total: dict = {}
    check = RunChecks(functions, settings, p0, theta_start, dth, state0, path=path)
    clusters = SwitchClusters(lay.guard_names, settings, omega, dth)  # how close to the chatter detectors
    # until_periodic: each revolution against the one before (runtime/solving/periodicity.py)
    watch = PeriodicWatch(periodic_tol, revolutions, lay.state_names) if until_periodic else None
    # on a terminal a bar redrawn in place; in a log (stderr not a terminal) a line every LOG_INTERVAL s, kept
    bar = revolutions_bar(total=revolutions, initial=done, unit="rev", disable=not progress,
                          leave=not sys.stderr.isatty(), **bar_output())
    z_rev = z.copy()
    report = _Progress(bar, revolutions)
    pace, split = Pace(deadline), None  # near the deadline, calls interval by interval (runtime/solving/pace.py)
    with StopSignals() as signals:
        signals.watch(engine)
        try:
            for call in range(done * calls, revolutions * calls if stop is None else 0):
                rev, c = divmod(call, calls)
                if signals.requested:
                    status, stop = "interrupted", StopInfo(part.theta_done, lay.mode(z[lay.active]), signals.reason())
                    break
                if time.perf_counter() > deadline:
                    status, stop = "interrupted", StopInfo(part.theta_done, lay.mode(z[lay.active]),
                                                           out_of_time(settings, t_wall))
                    break
                edges = theta_start + rev * 2 * np.pi + dth * (c * m + np.arange(m + 1))
                P_in = _pressures(pressure, edges, values, linear)
                P = P_in if settings.pressure == "steps" else P_in[:, 1:]  # the pressures at the samples
                line = params if path is None else path(edges)  # the parameters, or their values at the edges
                if split is None and m > 1 and pace.would_overrun(m) and not engine.stops_at_deadline:
                    split = IntervalByInterval(functions, settings, engine, dth, make_engine)
                    split.carry_on(z, _carried(engine, z))
                    signals.watch(split)
                use = split or engine
                use.deadline = deadline if not signals.requested else -math.inf
                t_call = time.perf_counter()
                try:
                    out = use.run(z, line, edges[0], P_in)
                    Z, stats, failure = out.z, out.stats, None
                    pace.record(time.perf_counter() - t_call, m)
                except WallTimeExceeded as late:
                    Z, stats = late.partial, {"n_calls_split": 1} if use is split else {}
                    last = Z[lay.active, -1] if Z.shape[1] else z[lay.active]
                    why = signals.reason() if signals.requested else out_of_time(settings, t_wall)
                    failure = "interrupted", StopInfo(edges[Z.shape[1]] - theta_start, lay.mode(last), why)
                except RuntimeError as err:
                    # a call made interval by interval keeps the intervals before the one that failed
                    head = err.partial if isinstance(err, FailedInterval) else np.zeros((z.size, 0))
                    k = head.shape[1]
                    Z, failure = locate_failure(functions, settings, edge_params(line, k, m - k),
                                                head[:, -1] if k else z, edges[k:],
                                                P_in[:, k:], err, deadline, theta_start, make_engine,
                                                counts_before=z_rev[lay.counts],
                                                advance=lambda j, c0=call * m + k: report((c0 + j) / m / calls))
                    Z = np.hstack([head, Z])
                    stats = {"n_recovered_calls": 1} if failure is None else {}
                Z, bad = check.finite(Z, edges[1:])
                if bad is None:
                    Z, bad = check.tilt(Z, edges[1:])
                if bad is None:
                    Z, bad = check.friction(Z, edges[1:], P)
                    if bad is not None:  # found in the samples before the call failed: the earlier stop, and its cause
                        failure = None
                failure = check.explained(failure) or bad
                n = Z.shape[1]  # fewer than the call's intervals where a re-run stopped at the revolution's event cap
                found = failure or check.events(Z, z, edges[1:1 + n], P[:, :n], z_rev)
                Z = _up_to_stop(Z, edges, theta_start, found)
                clusters.add(z[lay.counts], Z[lay.counts], edges[1:1 + Z.shape[1]] - theta_start, z_rev[lay.counts])
                z_end = Z[:, -1].copy() if Z.shape[1] else z  # where the next call starts
                Z, P, ends = Z[:, sub - 1::sub], P[:, sub - 1::sub], edges[sub::sub]  # the output samples
                stats = dict(stats)
                stats["n_engine_calls"] = 1
                if "n_events" not in stats:  # a compiled integrator reports no statistics: count
                    stats["n_events"] = int(z_end[lay.counts].sum() - z[lay.counts].sum())  # from the hybrid state
                if Z.shape[1]:
                    part.add(Z, ends[:Z.shape[1]], P[:, :Z.shape[1]], z_end, _carried(use, z_end))
                    if watch is not None:
                        watch.add(Z[lay.x])
                z = z_end
                for k, v in stats.items():
                    if k.startswith("n_") and isinstance(v, int | float):
                        stats_total[k] = stats_total.get(k, 0) + v
                if found is not None:
                    status, stop = found
                    break
                report((call + 1) / calls, every=True)
                if c == calls - 1:
                    part.flush()  # a completed revolution goes to the sink (to disk when streaming)
                    z_rev = z.copy()
                    if watch is not None and watch.revolution_done(rev + 1):  # the whole revolution repeats
                        stats_total["periodic_after"] = rev + 1
                        break
        except KeyboardInterrupt:  # outside the main thread, or raised by an engine: the same as a signal
            status = "interrupted"
            stop = StopInfo(part.theta_done, lay.mode(part.last_active(lay)), "interrupted by the user (Ctrl-C)")
        except ResultStorageError as err:
            status, stop = "failed", StopInfo(part.theta_done, lay.mode(part.last_active(lay)), str(err))
        finally:
            bar.close()
        try:
            part.flush()  # the completed calls of an unfinished revolution are kept too
            part.sync()  # the last part written: a failure of its writing is the run's failure
        except ResultStorageError as err:
            status, stop = "failed", StopInfo(part.theta_done, lay.mode(part.last_active(lay)), str(err))
        wall = time.perf_counter() - t_wall
        uncounted = engine is not None and engine.compiled and not engine.counts_steps
        info = info | {"wall_time_s": wall, "solver_stats": stats_total,
                       "solver_stats_note": "" if not uncounted else
                       "a compiled integrator reports engine calls and events only; set "
                       "solver.interpreted = true for CasADi's step counts",
                       "compiled": bool(engine is not None and engine.compiled),
                       # the densest cluster of one contact's switches (runtime/solving/near_chatter.py)
                       "switch_cluster": clusters.record()}
        if watch is not None:  # until_periodic: where it stopped, or how far from periodic the last revolution was
            info["periodic"] = watch.record()
        if signals.requested:
            info["signals"] = [int(s) for s in signals.received]
        if leased is not None:
            leased.release()  # for the next run of this model with these settings
        t_finish = time.perf_counter()
        long = progress and part.samples_done >= LONG_RESULT  # seconds after the bar ends: said, not silent
        with stage(f"joining the result's {part.samples_done:,} samples") if long else contextlib.nullcontext():
            if status == "failed" and stop is not None:  # the key to change, when the scene holds an absurd value
                stop = StopInfo(stop.theta, stop.mode, stop.reason + far_outside_practice(functions, params,
                                                                                          values))
            result = sink.finish(status, stop, info)
        # wall seconds: start checks and building the engine (compiling, or loading the cached library), integrating
        # (checks between calls included), assembling the outputs (per revolution, and joining them at the end),
        # handing each revolution to the sink (writing it, when it streams to disk)
        assembling = part.assemble_s + time.perf_counter() - t_finish
        result.info["timings_s"] = {"compile": t_engine - t_wall,
                                    "integrate": t_finish - t_engine - part.assemble_s - part.save_s,
                                    "assemble": assembling, "save": part.save_s}
        return result


def revolutions_bar(**kwargs):
    """tqdm's bar of the revolutions done, which are fractions while a revolution is cut into calls or re-run: shown
    to two decimals (tqdm printed 0.1111111111111111/1)."""
    return _revolutions_bar_class()(**kwargs)


@functools.cache
def _revolutions_bar_class():
    """The bar's class, made once per process: tqdm starts a monitor thread for each class it meets, so a class made
    per run left a thread behind after every run (300 runs in a notebook: 300 threads)."""
    from tqdm.auto import tqdm

    class RevolutionsBar(tqdm):
        @property
        def format_dict(self):
            d = super().format_dict
            n = round(float(d["n"]), 2)
            d["n"] = int(n) if n.is_integer() else n
            return d

    return RevolutionsBar


class _Progress:
    """The revolutions' bar and the listeners of :func:`~apexseal.progress.following_runs` (a sweep shows its long
    points this way), told the revolutions done: after each call, and while a failed call is re-run interval by
    interval (runtime/solving/diagnosis.py) at most every :data:`RERUN_REPORT` s, so that a long re-run moves the
    bar too (at 1 rpm an interpreted revolution of erk takes 13 minutes, at 0.45 deg/s)."""

    def __init__(self, bar, revolutions: int):
        self.bar, self.revolutions, self.last = bar, revolutions, 0.0

    def __call__(self, done: float, every: bool = False) -> None:
        now = time.perf_counter()
        if not every and now - self.last < RERUN_REPORT:
            return
        self.last = now
        self.bar.update(done - self.bar.n)  # to the revolutions done: a sum of 1/calls overshot 1
        advanced(done, self.revolutions)


def pressure_substeps(pressure, samples_per_revolution: int) -> int:
    """Integrator intervals per output interval, so that a revolution has at least as many as the pressure table has
    rows: the pressures are linear (or held at their mean) over each integrator interval, so a coarser output grid
    would cut the corners of the table's rows and make the physics depend on how often the run is sampled. 1 for
    pressures without a table (none, constant, the chamber gas model) and for output grids at least as fine as the
    table. A table's rows closer together than its mean spacing (the steep ramps of hard/pressure-square-wave) are
    still seen as ramps over one integrator interval."""
    rows = pressure.rows_per_revolution() if hasattr(pressure, "rows_per_revolution") else 0
    return max(1, -(-rows // samples_per_revolution))


def _carried(engine, z: np.ndarray):
    """What ``engine`` carries into a call from ``z`` (:meth:`.methods.Engine.carried`; None for an engine without
    the method, as a wrapper of tests has)."""
    carried = getattr(engine, "carried", None)
    return None if carried is None else carried(z)


def _carry_on(engine, z: np.ndarray, carried) -> None:
    """Hand ``engine`` what a stopped run's engine carried from ``z`` (:meth:`.methods.Engine.carry_on`)."""
    if hasattr(engine, "carry_on"):
        engine.carry_on(z, None if carried is None else np.asarray(carried, float))


def _up_to_stop(Z: np.ndarray, edges: np.ndarray, theta_start: float, found) -> np.ndarray:
    """The samples of a call up to where the run stopped: nothing past a stop is presented as a result."""
    if found is None or not Z.shape[1]:
        return Z
    keep = int(np.searchsorted(edges[1:1 + Z.shape[1]] - theta_start, found[1].theta, side="right"))
    return Z[:, :keep]


class _Part:
    """The integrator calls of the revolution in progress; :meth:`flush` hands them to the sink as one part."""

    def __init__(self, functions, params, theta_start, omega, sink, first, first_pressures, path=None):
        self.functions, self.params, self.theta_start, self.omega, self.sink = functions, params, theta_start, omega, sink
        self.path = path  # the parameters along a schedule (None: params at every sample)
        self.first, self.first_pressures = first, first_pressures
        self.blocks, self.thetas, self.pressures = [], [], []
        self.theta_done = 0.0  # crank angle of the last sample, from the start
        self._last = self.z_end = first
        self.carried = None  # what the engine carries from z_end into the next call
        self.assemble_s = self.save_s = 0.0  # wall seconds of flush(): assembling, then handing to the sink
        self.samples_done = 0  # samples handed to the sink by this run

    def after(self, theta_done: float, z, carried=None) -> None:
        """Continue a run whose samples up to ``theta_done`` (from the start) are in the sink, ending in state ``z``
        (its engine carrying ``carried`` from there)."""
        self.theta_done, self._last, self.z_end, self.carried = theta_done, z, z, carried

    def add(self, Z, thetas, P, z_end, carried=None) -> None:
        """The samples ``Z`` of a call at ``thetas``, and ``z_end``, the state the next call starts from, with what
        the engine carries into it (``carried``, :meth:`.methods.Engine.carried`)."""
        self.z_end, self.carried = z_end, carried
        self.blocks.append(Z)
        self.thetas.append(thetas)
        self.pressures.append(P)
        self.theta_done = float(thetas[-1] - self.theta_start)
        self._last = Z[:, -1]

    def last_active(self, lay):
        return self._last[lay.active]

    def flush(self) -> None:
        if not self.blocks and self.first is None:
            return
        w0 = time.perf_counter()
        part = assemble_blocks(self.functions, self.params, self.blocks, self.thetas, self.pressures,
                               self.theta_start, self.omega, first=self.first, first_pressures=self.first_pressures,
                               path=self.path)
        z_end = self.z_end  # where a run continuing this one starts (runtime/results/continuation.py)
        self.blocks, self.thetas, self.pressures, self.first = [], [], [], None
        w1 = time.perf_counter()
        self.samples_done += part.n
        self.sink.append(part, z_end, self.carried)
        self.assemble_s += w1 - w0
        self.save_s += time.perf_counter() - w1

    def sync(self) -> None:
        """Wait for the sink to store every part (timed as saving)."""
        w0 = time.perf_counter()
        self.sink.sync()
        self.save_s += time.perf_counter() - w0


def _pressures(pressure, edges: np.ndarray, values=None, linear: bool = False) -> np.ndarray:
    """What the engine takes: (2, n) interval means (``pressure(edges)``), or with ``linear`` the (2, n + 1)
    values at the edges (``values(edges)``, the pressures at given crank angles)."""
    if pressure is None:
        return np.zeros((2, edges.size - (not linear)))
    return np.asarray(values(edges) if linear else pressure(edges), float)
