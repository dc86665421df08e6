"""The solver settings of one run, and how a revolution is cut into integrator calls."""

from __future__ import annotations

import time
from dataclasses import dataclass


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


def samples_per_call(settings: RunSettings) -> int:
    """Output intervals per integrator call: the revolution cut into ``calls_per_revolution`` equal calls.

    The number of calls is rounded up to a divisor of ``samples_per_revolution`` (every call the same engine).
    """
    n = settings.samples_per_revolution
    calls = settings.calls_per_revolution or (36 if settings.max_wall_time else 1)
    calls = next(d for d in range(max(1, min(calls, n)), n + 1) if n % d == 0)
    return n // calls


def out_of_time(settings: RunSettings, t_wall: float, doing: str = "") -> str:
    """The stop reason of a run whose wall-time budget ran out (``t_wall``: when the run started)."""
    return (f"wall-time budget used up: max_wall_time = {settings.max_wall_time:g} s (after "
            f"{time.perf_counter() - t_wall:.1f} s{doing})")
