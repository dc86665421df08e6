"""What a simulation returns, and how it is saved and loaded.

A :class:`SimulationResult` holds one row per output sample: crank angle, time,
state, which contacts are closed (and so the contact case), every contact force,
moment and friction power, the seal-groove gap, and the running event count of
each guard. A failed or interrupted run is still a result: it keeps every sample
computed before it stopped and says where (crank angle, mode) and why.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...derive.submodels.registry import state_names

STATUS = ("completed", "interrupted", "failed", "chattering")


@dataclass
class StopInfo:
    theta: float  # crank angle where the run stopped (rad, from the start of the run)
    mode: str
    reason: str

    def describe(self) -> str:
        return f"stopped at crank angle {np.degrees(self.theta):.3f} deg in mode {self.mode}: {self.reason}"


@dataclass
class SimulationResult:
    theta: np.ndarray  # (n,) crank angle, rad, measured from the scene's start angle
    time: np.ndarray  # (n,) s
    state: np.ndarray  # (6, n) x, y (m), phi (rad), and their time derivatives
    closed: np.ndarray  # (n_guards, n) bool
    events: np.ndarray  # (n_guards, n) running count of switches of each guard
    outputs: dict[str, np.ndarray]  # name -> (n,)
    guard_names: tuple[str, ...]
    modes: list[str]
    status: str = "completed"
    stop: StopInfo | None = None
    info: dict = field(default_factory=dict)  # method, tolerances, wall time, solver statistics, versions

    def __post_init__(self) -> None:
        if self.status not in STATUS:
            raise ValueError(f"status {self.status!r} not in {STATUS}")

    @property
    def n(self) -> int:
        return self.theta.size

    @property
    def ok(self) -> bool:
        return self.status == "completed"

    def column(self, name: str) -> np.ndarray:
        if name in state_names():
            return self.state[state_names().index(name)]
        return self.outputs[name]

    # ------------------------------------------------------------------ saving
    def save(self, folder: str | Path, *, csv: bool = False) -> Path:
        """Write the result folder (parts/*.npz, result.json; trajectory.csv with ``csv=True``) as one unit.

        See runtime/results/folder.py: written beside ``folder`` and renamed into place, so a failed save leaves
        a previous result there intact; storage errors name the folder and what was kept.
        """
        from .folder import save

        return save(self, folder, csv=csv)

    @classmethod
    def load(cls, folder: str | Path) -> SimulationResult:
        """The result in ``folder``, refused (ResultFolderError) unless all its files belong to one run."""
        from .folder import read

        return read(folder)
