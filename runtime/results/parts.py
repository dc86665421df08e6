"""A result in parts: the run loop hands each completed part (a revolution) to a sink as soon as it is assembled.

:class:`InMemory` keeps the parts and joins them at the end (``apexseal.simulate(scene)``);
:class:`~.folder.ResultFolder` writes each part to disk and keeps none (``simulate(scene, out=...)``, the CLI).
Both end with ``sync()`` (every part handed over is stored; a storage error is raised) and ``finish(status, stop,
info)``, which returns the whole :class:`SimulationResult`.
"""

from __future__ import annotations

import copy

import numpy as np

from .result import SimulationResult, StopInfo


def join(parts: list[SimulationResult], status: str = "completed", stop: StopInfo | None = None,
         info: dict | None = None) -> SimulationResult:
    """One result of consecutive parts (same guards and outputs)."""
    if not parts:
        raise ValueError("a result needs at least one part (the initial sample)")
    head = parts[0]
    if len(parts) == 1:
        joined = copy.copy(head)  # its arrays shared; the part itself keeps its status, stop and info
    else:
        joined = SimulationResult(
            np.concatenate([p.theta for p in parts]), np.concatenate([p.time for p in parts]),
            np.hstack([p.state for p in parts]), np.hstack([p.closed for p in parts]),
            np.hstack([p.events for p in parts]),
            {k: np.concatenate([p.outputs[k] for p in parts]) for k in head.outputs},
            head.guard_names, [m for p in parts for m in p.modes])
    joined.status, joined.stop, joined.info = status, stop, dict(info or {})
    return joined


class InMemory:
    """The sink of a run that is not streamed to disk: parts kept in memory, joined by :meth:`finish`."""

    def __init__(self) -> None:
        self.parts: list[SimulationResult] = []
        self.samples = 0

    def begin(self, info: dict) -> None:
        """Nothing to record before the first part: the result exists only once :meth:`finish` joins it."""

    def append(self, part: SimulationResult, z_end: np.ndarray | None = None,
               carried: np.ndarray | None = None) -> None:
        """``z_end``: the integrator's state after the part's last sample, ``carried``: what the integrator carries
        from there into its next call (both kept by a folder, to continue from)."""
        self.parts.append(part)
        self.samples += part.n

    def sync(self) -> None:
        """Nothing to wait for: the parts are in memory."""

    def finish(self, status: str, stop: StopInfo | None, info: dict) -> SimulationResult:
        return join(self.parts, status, stop, info)
