"""One point of a sweep: simulate a scene within a wall-time budget and keep a row of numbers, whatever happens.

This is what a worker runs. It uses only the public API (``apexseal.simulate``) and the run summary, so a point
gives exactly what ``apexseal simulate`` of the same scene gives. A point never raises: a run that fails, chatters
or uses up its budget is a row with its status and stop reason (and the quantities of what it computed); an
exception is a row with status ``error`` and the exception's text.
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import socket
import sys
import time
from typing import Any

#: CasADi's notice printed by every construction of an event integrator: said once per sweep, not once per point
_REPEATED_NOTICE = "Event support is experimental"
_noticed = False

#: statuses of a point: those of a run (SimulationResult.status), and "error" (the run raised)
STATUSES = ("completed", "interrupted", "failed", "chattering", "error")


def run_point(index: int, scene, overrides: dict[str, Any], quantities: tuple[str, ...],
              max_wall_time: float) -> dict[str, Any]:
    """Simulate ``scene`` (the study's base scene with ``overrides`` applied) and return its row."""
    import apexseal

    from ...results.quantities import collect
    from ...solving import engine_pool

    t0 = time.perf_counter()
    row: dict[str, Any] = {"point": int(index), "scene_hash": scene.content_hash(), **overrides}
    try:
        with _quiet_notice(), engine_pool.reusing():  # the points of a model and settings share one engine
            result = apexseal.simulate(scene, max_wall_time=max_wall_time)
        values = collect(result, quantities)
        row.update(status=result.status, stop="" if result.stop is None else result.stop.describe())
        run_time = float(result.info.get("wall_time_s", math.nan))
    except Exception as err:  # noqa: BLE001 - a point records its failure, the sweep goes on
        values, run_time = dict.fromkeys(quantities, math.nan), math.nan
        row.update(status="error", stop=f"{type(err).__name__}: {err}")
    row.update(values)
    row["wall_time_s"] = time.perf_counter() - t0  # the whole point: scene, integrator, run, summary
    row["run_time_s"] = run_time  # the integration alone (SimulationResult.info["wall_time_s"])
    row["worker"] = f"{socket.gethostname()}:{os.getpid()}"
    return row


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
