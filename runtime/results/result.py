"""What a simulation returns, and how it is saved and loaded.

A :class:`SimulationResult` holds one row per output sample: crank angle, time,
state, which contacts are closed (and so the contact case), every contact force,
moment and friction power, the seal-groove gap, and the running event count of
each guard. A failed or interrupted run is still a result: it keeps every sample
computed before it stopped and says where (crank angle, mode) and why.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ...derive.submodels.registry import state_names

STATUS = ("completed", "interrupted", "failed", "chattering")


def run_mean(values: np.ndarray) -> float:
    """The mean of an output over a run: of its samples after the first (each the end of an output interval; the
    start is where the run began, not a computed interval). NaN for a run that ended before its first interval (one
    sample, or none): a value there would be the start's alone (it printed 8.76 W for a run stopped at 0
    revolutions)."""
    values = np.asarray(values, float)
    return float(np.mean(values[1:])) if values.size > 1 else math.nan


@dataclass
class StopInfo:
    theta: float  # crank angle where the run stopped (rad, from the start of the run)
    mode: str
    reason: str

    def describe(self) -> str:
        return f"stopped at crank angle {np.degrees(self.theta):.3f} deg in mode {self.mode}: {self.reason}"


@dataclass(repr=False, eq=False)
class SimulationResult:
    """The trajectory of a run, one column per output sample (``n`` samples, the first at the start state).

    Fields (SI units; the meaning and unit of every column is also in ``docs/outputs.md``):

    * ``theta`` (n,): crank angle in rad, measured from the scene's start angle (``operation.start_angle``);
    * ``time`` (n,): time in s since the start (``theta / omega``);
    * ``state`` (n_x, n): the seal's state in the groove frame (Eq. 10), rows in the order of the tuple
      ``state_names`` = x, y (m), phi (rad), xd, yd (m/s), phid (rad/s), then a submodel's own states (the chamber
      gas);
    * ``closed`` (n_guards, n), bool: True where the contact of ``guard_names[i]`` is closed (Algorithm 3);
    * ``events`` (n_guards, n), float64 holding whole numbers (the integrator's state carries them): the switches
      of each contact counted from the run's start to each sample (events between samples included; never
      decreasing, so ``events[:, -1]`` are the run's); :meth:`event_list` lists them with their crank angle and
      direction;
    * ``outputs``: name -> (n,) array: forces ``F_<contact>_X/_Y`` (N, groove frame), moments ``M_<contact>``
      (N m, about the centre of gravity), friction powers ``Pf_<contact>`` and ``Pf_total`` (W), gaps
      ``b1..b4``, ``b_gap`` (m), housing penetration ``xs5`` (m), ``spring_compression`` (m), chamber
      pressures ``Pa``, ``Pb`` (Pa);
    * ``guard_names``: the contacts, in the model's order, the rows of ``closed`` and ``events``: on the default
      scene ``("xs5", "b1", "b2", "b3", "b4", "spring")`` (the housing contact, the four groove gaps, the spring);
    * ``modes`` (n,): the contact mode at each sample (case of Algorithm 3, then ``h``/``s`` when the
      housing/spring contact is closed);
    * ``status``: ``completed``, ``interrupted``, ``failed`` or ``chattering``; ``stop`` says where and why a
      run that did not complete stopped (every sample before it is kept);
    * ``info``: method, tolerances, wall time, solver statistics (:attr:`solver_stats`), the scene's name and
      content hash, the generated model's hash and the package versions;
    * ``scene``: the scene that ran (overrides and run settings applied), or None for a result loaded
      without one.

    Look at it with :meth:`summary`, :meth:`plot`, :meth:`to_xarray`, :meth:`to_pandas`; compare several with
    :func:`apexseal.plot_comparison`.

    ``a == b`` is ``a is b``, as for the objects of scientific libraries that hold arrays beside other data (a
    field-wise comparison of numpy arrays raised "truth value of an array is ambiguous"): compare the data as
    xarray and pandas compare theirs, ``a.to_xarray().equals(b.to_xarray())`` (every column and coordinate),
    or a column with numpy, ``np.array_equal(a.column("x"), b.column("x"))``.
    """

    theta: np.ndarray  # (n,) crank angle, rad, measured from the scene's start angle
    time: np.ndarray  # (n,) s
    state: np.ndarray  # (n_x, n) x, y (m), phi (rad), their time derivatives, then the submodels' own states
    closed: np.ndarray  # (n_guards, n) bool
    events: np.ndarray  # (n_guards, n) float64, switches of each guard counted from the run's start
    outputs: dict[str, np.ndarray]  # name -> (n,)
    guard_names: tuple[str, ...]
    modes: list[str]
    status: str = "completed"
    stop: StopInfo | None = None
    info: dict = field(default_factory=dict)  # method, tolerances, wall time, solver statistics, versions
    scene: Any = None  # the Scene that ran (apexseal.runtime.scenes.scene.Scene), if known

    def __post_init__(self) -> None:
        if self.status not in STATUS:
            raise ValueError(f"status {self.status!r} not in {STATUS}")

    @property
    def n(self) -> int:
        """Number of samples."""
        return self.theta.size

    @property
    def state_names(self) -> tuple[str, ...]:
        """The names of the state's rows (the seal body's six, then the submodels' own, e.g. the chamber gas)."""
        names = self.info.get("state_names")
        return tuple(names) if names else state_names()[: self.state.shape[0]]

    @property
    def ok(self) -> bool:
        return self.status == "completed"

    @property
    def revolutions(self) -> float:
        """Revolutions covered (crank angle of the last sample / 2 pi), to 1e-9 of a revolution: 88, not the
        87.99999999999999 that the division's round-off gives."""
        return round(float(self.theta[-1] / (2 * np.pi)), 9) if self.n else 0.0

    @property
    def n_events(self) -> int:
        """Contact switches in the whole run."""
        return int(self.events[:, -1].sum()) if self.events.size else 0

    @property
    def friction_power(self) -> float:
        """Mean friction power of all contacts over the run, W: of Pf_total at the samples after the first (each the
        end of an output interval, :func:`run_mean`; ``to_pandas()["Pf_total"].mean()`` counts the start too); 0
        without friction; NaN before the first output interval ends: nothing computed."""
        p = self.outputs.get("Pf_total")
        return run_mean(p) if p is not None else 0.0

    @property
    def solver_stats(self) -> dict:
        """The integrator's statistics summed over the run (steps, rejected steps, right-hand-side calls, events,
        engine calls; a compiled erk/rosenbrock integrator reports calls and events only)."""
        return dict(self.info.get("solver_stats", {}))

    def column(self, name: str) -> np.ndarray:
        """A state (``x`` ... ``phid``, a submodel's own) or output by name, SI, read-only (a view of the result's
        own array: ``x = r.column("x"); x *= 1e6`` changed the result, its summary and what it saved; take
        ``r.column("x") * 1e6``, or ``.copy()``); any other name is a KeyError with the closest known name and the
        list (as :meth:`plot` says it)."""
        if name in self.state_names:
            values = self.state[self.state_names.index(name)]
        elif name in self.outputs:
            values = self.outputs[name]
        else:
            from ...suggest import not_known

            raise KeyError(not_known(f"column {name!r}", name, [*self.state_names, *self.outputs],
                                     "a state nor an output of this result", listing="its columns"))
        view = np.asarray(values).view()
        view.flags.writeable = False
        return view

    # ------------------------------------------------------------------ looking at it
    def __repr__(self) -> str:
        method = self.info.get("method", "?")
        reason = self.stop.reason if self.stop is not None and self.status != "completed" else ""
        why = f" ({reason if len(reason) <= 60 else reason[:59] + '…'})" if reason else ""  # the whole: .stop
        return (f"SimulationResult({self.status}{why}, {self.revolutions:.2f} rev, {self.n} samples, "
                f"{self.n_events} events, {self._outside_model()}"
                f"friction power {self._power(3)}, method {method})")

    def _power(self, digits: int) -> str:
        """The mean friction power with its unit, or "none computed" before the first output interval ended (NaN:
        the console's summary says so, the repr printed "nan W")."""
        p = self.friction_power
        return f"{p:.{digits}g} W" if math.isfinite(p) else "none computed"

    def _sampling(self) -> str:
        """What the output samples resolve, for the HTML repr: their number (per revolution), whether they resolve the
        contacts' ringing (``info["sampling"]``, runtime/solving/ringing.py) and, where the seal's energy balance over
        them does not close (:func:`.energy.energy_balance`), the loads' work they miss as a power: a contact's
        friction power of that size or less is not resolved by them (the console's notes, ``summary()``)."""
        from ..solving.ringing import SAMPLES_PER_PERIOD
        from .energy import energy_balance

        per_revolution = self.info.get("samples_per_revolution")
        parts = [f"{self.n}" + (f" ({per_revolution} per revolution)" if per_revolution else "")]
        ring = self.info.get("sampling")
        if ring is not None:
            parts.append(f"the contacts' ringing ({ring['ringing_rad_s']:.3g} rad/s) "
                         + ("resolved" if ring["resolved"] else
                            f"not resolved ({ring['samples_per_revolution_resolving']} per revolution take "
                            f"{SAMPLES_PER_PERIOD:g} samples per period of it)"))
        block = energy_balance(self)
        if block is not None and not block["closes"]:
            omega = self.scene.parameters["omega"]
            parts.append(f"the energy balance misses {abs(block['residual_J_per_rev']) * omega / (2 * math.pi):.3g} W "
                         f"of the loads' work ({block['residual_fraction']:.0%}): a contact's friction power that "
                         "small is not resolved")
        return "; ".join(parts)

    def _outside_model(self) -> str:
        """``outside the model from 23 deg, `` when the seal left the seal-groove contacts' domain (Eqs. 20-23,
        :func:`.plausibility.flank_check`): the numbers beside it (the friction power) mix samples from outside it."""
        from .plausibility import flank_check

        check = flank_check(self)
        return "" if check is None or check["ok"] else f"outside the model from {check['first_off_deg']:.4g} deg, "

    def _repr_html_(self) -> str:
        from html import escape

        outside = self._outside_model().rstrip(", ")
        rows = [("status", self.status + ("" if self.stop is None else f": {self.stop.describe()}")),
                ("revolutions", f"{self.revolutions:.3f}"), ("samples", self._sampling()),
                ("events", ", ".join(f"{g} {int(self.events[i, -1])}" for i, g in enumerate(self.guard_names))
                 + f" (total {self.n_events})"),
                ("mean friction power", self._power(4) + (f" ({outside}: FlankWarning)" if outside else "")),
                ("method", f"{self.info.get('method', '?')}, rtol {self.info.get('rtol', '?')}"),
                ("wall time", f"{self.info.get('wall_time_s', float('nan')):.3g} s"),
                ("scene", f"{self.info.get('scene', '?')} ({str(self.info.get('scene_hash', ''))[:12]})")]
        body = "".join(f"<tr><th style='text-align:left'>{escape(k)}</th><td style='text-align:left'>{escape(v)}</td>"
                       "</tr>" for k, v in rows)
        return f"<table><caption>SimulationResult</caption>{body}</table>"

    def summary(self) -> dict:
        """The numbers a designer reads first (extremes with crank angles, time in each mode, events, friction
        power, leakage gap, housing-force spectral peaks), as written to summary.json. Its extremes, peak forces
        and deepest penetrations are maxima over the output samples (``samples_per_revolution`` of them per
        revolution), not of the motion between them: denser sampling finds higher impact peaks."""
        from .summary import summarise

        return summarise(self)

    def event_list(self):
        """The contact events as a pandas DataFrame: crank angle (deg), time (s), contact, direction, switches."""
        from .views import event_list

        return event_list(self)

    def to_pandas(self):
        """One row per sample, indexed by crank angle in degrees; SI columns, units in ``df.attrs["units"]``."""
        from .views import to_pandas

        return to_pandas(self)

    def to_xarray(self):
        """An xarray Dataset (dimension ``theta``, coordinate ``time``), variables with ``units`` and
        ``long_name``; ``.to_netcdf(path)`` writes netCDF."""
        from .views import to_xarray

        return to_xarray(self)

    def plot(self, *what: str, **kw):
        """Matplotlib Figures: the paper's ``"fig12"`` (displacements), ``"fig13"`` (forces), ``"fig14"``
        (housing-force spectrum), ``"modes"``, or named quantities (``"x"``, ``"Pf_total"``, ``"F_housing_X"``...)
        against crank angle in one figure. No argument: Fig. 12. One name gives a Figure, several names of
        figures a list; see :func:`apexseal.runtime.results.plots.plot`."""
        from .plots import plot

        return plot(self, *what, **kw)

    # ------------------------------------------------------------------ saving
    def save(self, folder: str | Path, *, csv: bool = False) -> Path:
        """Write the result folder (parts/*.npz, result.json, scene.toml when the scene is known; trajectory.csv
        with ``csv=True``) as one unit.

        See runtime/results/folder.py: written beside ``folder`` and renamed into place, so a failed save leaves
        a previous result there intact; storage errors name the folder and what was kept.

        A saved result loads (:meth:`load`) but cannot be continued: its parts hold the samples, not the
        integrator's state after them (``z_end``, which only a run streamed to its folder records), so
        :func:`apexseal.resume` refuses it with a ResultFolderError. To continue a run later, simulate with
        ``out=folder`` (or on the command line).
        """
        from .folder import save

        return save(self, folder, csv=csv)

    @classmethod
    def load(cls, folder: str | Path) -> SimulationResult:
        """The result in ``folder``, refused (ResultFolderError) unless all its files belong to one run; its
        ``scene`` is loaded from the folder's scene.toml when there is one."""
        from .reading import read

        return read(folder)
