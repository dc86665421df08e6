"""What a simulation returns, and how it is saved and loaded.

A :class:`SimulationResult` holds one row per output sample: crank angle, time,
state, which contacts are closed (and so the contact case), every contact force,
moment and friction power, the seal-groove gap, and the running event count of
each guard. A failed or interrupted run is still a result: it keeps every sample
computed before it stopped and says where (crank angle, mode) and why.
"""

from __future__ import annotations

import csv
import json
import os
import tempfile
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
    def save(self, folder: str | Path) -> Path:
        """Write trajectory.csv, trajectory.npz and result.json into ``folder`` (atomically, file by file)."""
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        arrays = {"theta": self.theta, "time": self.time, "state": self.state, "closed": self.closed,
                  "events": self.events, "modes": np.array(self.modes, dtype="U16")}
        arrays.update({f"out_{k}": v for k, v in self.outputs.items()})
        _atomic(folder / "trajectory.npz", lambda fh: np.savez_compressed(fh, **arrays), binary=True)

        header = ["theta_deg", "time_s", *state_names(), "mode", *[f"closed_{g}" for g in self.guard_names],
                  *self.outputs]

        def write_csv(fh):
            w = csv.writer(fh)
            w.writerow(header)
            for i in range(self.n):
                w.writerow([f"{np.degrees(self.theta[i]):.6f}", f"{self.time[i]:.9e}",
                            *(f"{v:.9e}" for v in self.state[:, i]), self.modes[i],
                            *(int(c) for c in self.closed[:, i]), *(f"{self.outputs[k][i]:.9e}" for k in self.outputs)])

        _atomic(folder / "trajectory.csv", write_csv)
        meta = {"status": self.status, "stop": None if self.stop is None else vars(self.stop),
                "guard_names": list(self.guard_names), "outputs": list(self.outputs), "info": self.info}
        _atomic(folder / "result.json", lambda fh: json.dump(meta, fh, indent=2, default=_jsonable))
        return folder

    @classmethod
    def load(cls, folder: str | Path) -> SimulationResult:
        folder = Path(folder)
        meta = json.loads((folder / "result.json").read_text())
        with np.load(folder / "trajectory.npz") as d:
            outputs = {k: d[f"out_{k}"] for k in meta["outputs"]}
            stop = StopInfo(**meta["stop"]) if meta["stop"] else None
            return cls(d["theta"], d["time"], d["state"], d["closed"], d["events"], outputs,
                       tuple(meta["guard_names"]), [str(m) for m in d["modes"]], meta["status"], stop, meta["info"])


def _jsonable(v):
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, np.ndarray):
        return v.tolist()
    return str(v)


def _atomic(path: Path, write, binary: bool = False) -> None:
    """Write through a temporary file and rename, so a crash never leaves a half file that looks like a result."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb" if binary else "w", newline=None if binary else "") as fh:
            write(fh)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; a result is an ordinary file
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
