"""One point of a sweep: simulate a scene within a wall-time budget and keep a row of numbers, whatever happens.

This is what a worker runs. It uses only the public API (``apexseal.simulate``) and the run summary, so a point
gives exactly what ``apexseal simulate`` of the same scene gives. A point never raises: a run that fails, chatters
or uses up its budget is a row with its status and stop reason (and the quantities of what it computed); a run its
start check refuses (its scene's values alone decide it) is a row with status ``invalid``; an exception is a row
with status ``error`` and the exception's text.

On Dask no signal reaches the thread a point runs in: a sweep that a signal stops runs :func:`stop_points` on
every worker, which stops that sweep's running points as the signal stops a serial sweep's (at the run's next
check) and any of its points that starts afterwards at once.
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import signal
import socket
import sys
import time
import warnings
from typing import Any

#: CasADi's notice printed by every construction of an event integrator: said once per sweep, not once per point
_REPEATED_NOTICE = "Event support is experimental"
_noticed = False

#: statuses of a point: those of a run (SimulationResult.status), "invalid" (the run's start check refused it:
#: its scene's values give no meaningful run, runtime/solving/preflight.py) and "error" (the run raised)
STATUSES = ("completed", "interrupted", "failed", "chattering", "invalid", "error")
#: statuses that computing the point again cannot change: --retry-failed leaves them (an invalid point is decided by
#: its values alone; change the study's values instead)
FINAL = ("completed", "invalid")


#: the sweeps :func:`stop_points` stopped in this process, and the stop signal of each
_STOPPED: dict[str, int] = {}
#: the points running in this process, by their sweep's ``stop_key``: the StopSignals of each
_RUNNING: dict[str, list] = {}


def stop_points(stop_key: str, signum: int = signal.SIGTERM) -> int:
    """Stop the points of the sweep ``stop_key`` in this process as the signal ``signum`` stops a run: those running
    at their next check, those starting later at once. Returns how many were running. A sweep that a signal stops
    runs this on every Dask worker (``Client.run``)."""
    _STOPPED[stop_key] = signum
    running = list(_RUNNING.get(stop_key, ()))
    for signals in running:
        signals.request(signum)
    return len(running)


#: the points running in this process, by (their sweep's ``stop_key``, point): [revolutions done, revolutions asked,
#: time.monotonic() at its start]
_PROGRESS: dict[tuple[str | None, int], list] = {}


def running_points(stop_key: str | None = None) -> dict[int, tuple[float, int, float]]:
    """The points of the sweep ``stop_key`` (None: a serial sweep's) running in this process now: point ->
    (revolutions done, revolutions asked, seconds running). The sweep shows its long points with them (serially
    read here, on Dask from every worker through ``Client.run``: runtime/studies/sweep/watch.py)."""
    now = time.monotonic()
    return {i: (p[0], p[1], now - p[2]) for (key, i), p in list(_PROGRESS.items()) if key == stop_key}


@contextlib.contextmanager
def _followed(index: int, stop_key: str | None):
    """The block's runs report their revolutions to :func:`running_points` as the point ``index``."""
    from ....progress import following_runs

    entry = _PROGRESS[stop_key, index] = [0.0, 0, time.monotonic()]

    def advanced(done: float, total: int) -> None:
        entry[0], entry[1] = done, total

    try:
        with following_runs(advanced):
            yield
    finally:
        _PROGRESS.pop((stop_key, index), None)


class _Stopped(Exception):
    """A point whose sweep was stopped before it started."""


@contextlib.contextmanager
def _stoppable(stop_key: str | None):
    """The block as one unit :func:`stop_points` can stop (nothing without ``stop_key``): yields its StopSignals,
    which the run inside shares (src/apexseal/signals.py), or None."""
    if stop_key is None:
        yield None
        return
    from ....signals import StopSignals

    with StopSignals() as signals:
        _RUNNING.setdefault(stop_key, []).append(signals)
        try:
            if stop_key in _STOPPED:
                signals.request(_STOPPED[stop_key])
            yield signals
        finally:
            _RUNNING[stop_key].remove(signals)
            if not _RUNNING[stop_key]:
                del _RUNNING[stop_key]


def run_point(index: int, scene, overrides: dict[str, Any], quantities: tuple[str, ...],
              max_wall_time: float, stop_key: str | None = None) -> dict[str, Any]:
    """Simulate ``scene`` (the study's base scene with ``overrides`` applied) and return its row. ``stop_key``: the
    key :func:`stop_points` stops it with (a point on Dask)."""
    import apexseal

    from ...results.quantities import collect
    from ...solving import engine_pool

    t0 = time.perf_counter()
    row: dict[str, Any] = {"point": int(index), "scene_hash": scene.content_hash(), **overrides}
    asks_periodic = bool(scene.operation.until_periodic)
    if asks_periodic:  # a point that did not run (or not far enough to compare) did not become periodic
        row.update(periodic=False, periodic_change=math.nan)
    try:
        with _stoppable(stop_key) as signals:
            if signals is not None and signals.requested:  # its sweep was stopped before it started
                raise _Stopped(f"not run: its sweep was stopped by {signals.sender()} before it started")
            caught: list = []
            try:
                with _quiet_notice(), engine_pool.reusing(), _followed(index, stop_key), \
                        warnings.catch_warnings(record=True) as caught:  # a model's points share one engine
                    warnings.simplefilter("always")
                    result = apexseal.simulate(scene, max_wall_time=max_wall_time)
            finally:
                row["warnings"] = _plausibility(caught)
        values = collect(result, quantities)
        if asks_periodic:  # operation.until_periodic: whether this point's run became periodic (summary's run.periodic)
            record = result.info.get("periodic") or {}
            row.update(periodic=bool(record.get("periodic")),
                       periodic_change=math.nan if record.get("change") is None else float(record["change"]))
        status = "invalid" if result.info.get("refused_at_start") else result.status
        # a start refusal has no crank angle nor mode to say: its reason alone (key, value, allowed range)
        stop = "" if result.stop is None else result.stop.reason if status == "invalid" else result.stop.describe()
        row.update(status=status, stop=stop)
        run_time = float(result.info.get("wall_time_s", math.nan))
    except _Stopped as stopped:
        values, run_time = dict.fromkeys(quantities, math.nan), math.nan
        row.update(status="interrupted", stop=str(stopped))
    except Exception as err:  # noqa: BLE001 - a point records its failure, the sweep goes on
        values, run_time = dict.fromkeys(quantities, math.nan), math.nan
        row.update(status="error", stop=f"{type(err).__name__}: {err}")
    row.update(values)
    row["wall_time_s"] = time.perf_counter() - t0  # the whole point: scene, integrator, run, summary
    row["run_time_s"] = run_time  # the integration alone (SimulationResult.info["wall_time_s"])
    row["worker"] = f"{socket.gethostname()}:{os.getpid()}"
    return row



def _plausibility(caught: list) -> str:
    """The point's run's plausibility warnings (penetration, groove mouth corners, lift-off), one text for its row:
    a warning printed by a worker, or once per sweep by Python's filter, could not be told to its point. The others are
    warned again, from here, so that Python's filter says each once per process, not once per point (a compiler
    fallback, a stale artefact). The warnings are caught process-wide: a worker runs one point at a time (one thread
    per worker, as the sweep starts them and docs/sweeps.md asks of a cluster's)."""
    from ...scenes.units import PlausibilityWarning

    said = []
    for w in caught:
        if issubclass(w.category, PlausibilityWarning):
            if str(w.message) not in said:
                said.append(str(w.message))
        else:
            warnings.warn(w.message, w.category, stacklevel=2)
    return "; ".join(said)


@contextlib.contextmanager
def _quiet_notice():
    """Pass on what the run writes to stderr, except CasADi's repeated notice after its first time."""
    global _noticed
    buf = io.StringIO()
    try:
        with contextlib.redirect_stderr(buf):
            yield
    finally:
        lines = buf.getvalue().splitlines(keepends=True)
        keep = [ln for ln in lines if _REPEATED_NOTICE not in ln or not _noticed]
        _noticed = _noticed or len(keep) < len(lines) or any(_REPEATED_NOTICE in ln for ln in lines)
        sys.stderr.write("".join(keep))
