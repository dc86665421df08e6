"""How close a run came to the chatter detectors: the densest cluster of one contact's switches, said after a run
that completed near them.

Two detectors stop a run whose contacts chatter (:mod:`.checks`): more switches of one guard in one interval than
:func:`~.checks.interval_limit` allows, and more switches in a revolution than ``max_events_per_revolution``. A run
can complete just below them: a user's expander scene completed with 2888 switches of guard b3 between 288° and
297° (61 in one 0.1° interval, 70 % of the 87 the detector allows) and stopped as chattering at rtol 1e-8.
:class:`SwitchClusters` follows each guard's switches call by call and keeps the cluster (a stretch of consecutive
intervals in which that guard switched) with the most switches in one interval, and the most switches of a
revolution; :func:`apexseal.simulate` warns with :class:`NearChatterWarning` when a completed run used
:data:`NEAR_SHARE` of either limit, and ``apexseal simulate`` prints it as a note (docs/hard-cases.md, "Close to
the chatter limit", has the measurements behind the note's remedy).
"""

from __future__ import annotations

import numpy as np

from ..scenes.units import PlausibilityWarning
from .checks import interval_limit
from .settings import RunSettings

#: a completed run that used this share of a chatter detector's limit (switches of one guard in one interval, or
#: switches in a revolution) is close to it: the expander scene of the module docstring used 70 % and chattered at a
#: tighter rtol
NEAR_SHARE = 0.5


class NearChatterWarning(PlausibilityWarning):
    """A completed run whose switches came close to a chatter detector's limit (:data:`NEAR_SHARE` of it): another
    tolerance or method may stop it as chattering (a kind of the scene's
    :class:`~apexseal.runtime.scenes.units.PlausibilityWarning`: filtering that one filters this one too)."""


class SwitchClusters:
    """The densest cluster of switches of a run, fed with each integrator call's event counts (:meth:`add`)."""

    def __init__(self, guard_names, settings: RunSettings, omega: float | None, dth: float):
        """``dth``: the run's integrator intervals (rad), at which the chatter detector counts."""
        self.guard_names = tuple(guard_names)
        self.limit = interval_limit(settings, dth, omega)
        self.cap = settings.max_events_per_revolution
        self.best: dict | None = None  # the cluster with the most switches in one interval
        self.open: dict[int, dict] = {}  # each guard's cluster still going at the end of the last call
        self.most_in_revolution = 0

    def add(self, counts_before, counts, thetas, revolution_before) -> None:
        """A call's samples: ``counts`` (n_guards, n), each guard's switches from the run's start at ``thetas`` (rad
        from the run's start, the ends of the call's intervals), ``counts_before`` and ``revolution_before`` the
        counts at the start of the call and of its revolution."""
        counts = np.asarray(counts, float)
        if not counts.shape[1]:
            return
        thetas = np.asarray(thetas, float)
        starts = np.r_[thetas[0] - (thetas[1] - thetas[0] if thetas.size > 1 else 0.0), thetas[:-1]]
        self.most_in_revolution = max(self.most_in_revolution,
                                      int((counts - np.asarray(revolution_before, float)[:, None]).sum(axis=0).max()))
        per = np.diff(np.c_[counts_before, counts], axis=1)
        still_open: dict[int, dict] = {}
        for i in np.flatnonzero(per.any(axis=1)):
            edges = np.diff(np.r_[0, (per[i] > 0).astype(np.int8), 0])
            for a, b in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1), strict=True):
                k = a + int(np.argmax(per[i, a:b]))
                run = {"guard": self.guard_names[i], "from": starts[a], "to": thetas[b - 1],
                       "switches": int(per[i, a:b].sum()), "peak": int(per[i, k]), "peak_at": thetas[k]}
                if a == 0 and i in self.open:  # the cluster the call before ended in
                    run = _joined(self.open[i], run)
                if b == per.shape[1]:
                    still_open[i] = run
                if self.best is None or (run["peak"], run["switches"]) > (self.best["peak"], self.best["switches"]):
                    self.best = run
        self.open = still_open

    def record(self) -> dict | None:
        """The densest cluster (``guard``, ``from_deg``..``to_deg`` of crank angle from the run's start, its
        ``switches``, the most in one interval ``peak_per_interval`` at ``peak_at_deg``), the detectors' limits
        (``interval_limit``, ``max_events_per_revolution``), the most switches of one revolution, and ``near``:
        either limit used to :data:`NEAR_SHARE`; None for a run without switches."""
        if self.best is None:
            return None
        b = self.best
        near = b["peak"] >= NEAR_SHARE * self.limit or self.most_in_revolution >= NEAR_SHARE * self.cap
        return {"guard": b["guard"], "from_deg": float(np.degrees(b["from"])), "to_deg": float(np.degrees(b["to"])),
                "switches": b["switches"], "peak_per_interval": b["peak"],
                "peak_at_deg": float(np.degrees(b["peak_at"])), "interval_limit": float(self.limit),
                "revolution_switches": self.most_in_revolution, "max_events_per_revolution": int(self.cap),
                "near": bool(near)}


def _joined(before: dict, after: dict) -> dict:
    """One cluster of two parts that meet at a call's boundary."""
    peak = before if before["peak"] >= after["peak"] else after
    return {"guard": before["guard"], "from": before["from"], "to": after["to"],
            "switches": before["switches"] + after["switches"], "peak": peak["peak"], "peak_at": peak["peak_at"]}


def describe_near_chatter(record: dict) -> str:
    """One line for a :class:`NearChatterWarning`: which guard, where, how many switches against which limit, what
    it means, how to inspect it and the remedy measured (docs/hard-cases.md)."""
    g, peak, limit = record["guard"], record["peak_per_interval"], record["interval_limit"]
    in_rev, cap = record["revolution_switches"], record["max_events_per_revolution"]
    from ...derive.submodels.registry import guard_label

    return (f"the run is close to the chatter limit: guard {guard_label(g)} switched {record['switches']} times "
            "between "
            f"{record['from_deg']:.1f}° and {record['to_deg']:.1f}° of crank angle ({peak} in one interval at "
            f"{record['peak_at_deg']:.1f}°, {peak / limit:.0%} of the {limit:.4g} the chatter detector allows, "
            f"solver.chatter_events per solver.chatter_window; {in_rev} switches in one revolution, {in_rev / cap:.0%} "
            f"of max_events_per_revolution = {cap}): another rtol or method may stop it as chattering. Inspect the "
            f"switches with result.event_list() (its rows of contact '{g}'), the events_{g} variable of to_xarray() "
            "and the figure of the contact modes (mode_timeline.png, result.plot(\"modes\")). Method 'euler' with a fine "
            "step (solver.euler_steps_per_revolution) switches inside the right-hand side, without events: on the scene "
            "measured in docs/hard-cases.md (\"Close to the chatter limit\") it removed such a cluster; check that it "
            "leaves your numbers as they are with apexseal compare")
