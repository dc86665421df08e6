"""``operation.until_periodic``: stop a run once a revolution repeats the one before it.

The measure compares the whole revolution, not its first state: the seal's position at every output sample of a
revolution against the same crank angle one revolution earlier, and the whole state at its end
(:func:`revolution_change`).
"""

from __future__ import annotations

import numpy as np


def revolution_change(current: np.ndarray, previous: np.ndarray, positions: np.ndarray) -> float:
    """The change of the scaled state (n_x, samples) from one revolution to the next: the largest
    |z_k - z_(k-1)| / max(1, |z_k|) over the ``positions`` (the states that are no rates: x, y, phi, a chamber's
    gas) at every output sample, and over the whole state at the revolution's last sample (its end, where the
    next revolution starts).

    Why this measure:

    * **Every sample, not the revolution's start.** The output samples are a whole number per revolution, so
      sample j of two revolutions lies at the same crank angle: comparing them compares the two trajectories phase
      by phase. The state at the start of a revolution alone (the earlier check, still part of this one) can
      repeat while the motion in between does not: a lift-off or a ringing after a chamber switch that moved, and
      decayed by the revolution's end. The measure is never smaller than the start state's.
    * **Positions within the revolution, the whole state at its end.** The rates at the samples alias the contacts'
      ringing (the run's sampling note: 5.07e5 rad/s in the example below, above the 2.83e5 rad/s Nyquist frequency
      of its 3600 samples per revolution), so sample by sample they differ by the ringing's phase, which the
      integrator's tolerance does not fix: on the default scene without chamber pressure (``apexseal simulate --set
      pressure.source=none --set effects.chamber_pressure=false --set operation.until_periodic=true --set
      operation.periodic_tol=1e-4 -n 20``, rtol 1e-6), revolution 20 differed from revolution 19 by 1.78 with the
      rates at every sample, by 0.00148 (µm or mrad) in x, y and phi. The positions are what the results report
      (extremes, gaps, lift-off); the rates at the end, with them, fix the revolution that follows.
    * **Scaled state, relative above 1.** The integrator's state is in micrometres, milliradians and their rates
      per radian of crank angle (generated/scaling.py), so max(1, |z|) makes the change relative for values above
      1 µm (1 mrad) and absolute, in those units, below: a state at rest near 0 does not turn noise into a
      relative change of 100 %. ``operation.periodic_tol`` is this number; it must lie above what the
      integrator's tolerance resolves (the example above with periodic_tol=2e-3: periodic after 3 revolutions,
      a change of 0.000223).
    * **Cheap.** One subtraction per state and sample, once a revolution (O(samples x states), nothing next to the
      integrator's steps), and one revolution of the state kept (3600 x 6 numbers on the default scene).
    """
    def worst(a: np.ndarray, b: np.ndarray) -> float:
        return float(np.max(np.abs(a - b) / np.maximum(1.0, np.abs(a)))) if a.size else 0.0

    return max(worst(current[positions], previous[positions]), worst(current[:, -1], previous[:, -1]))


class PeriodicWatch:
    """The output samples of the revolution in progress, and the change from the previous one once it ends.

    :meth:`add` each call's output samples of the scaled state (``Z[layout.x]``); :meth:`revolution_done` at the
    end of each revolution gives its :func:`revolution_change` (None for the first revolution of the run, or one
    with fewer samples: a run stopped inside it). :meth:`record` is what the run's ``info["periodic"]`` holds."""

    def __init__(self, tolerance: float, revolutions_asked: int, state_names) -> None:
        from ...generated.scaling import declared_scales

        self.tolerance, self.revolutions_asked = float(tolerance), int(revolutions_asked)
        self.positions = ~declared_scales(state_names)[1]  # the states that are no rates
        self._samples: list[np.ndarray] = []
        self._previous: np.ndarray | None = None
        self.revolution: int | None = None  # the last revolution compared (1-based, counted from the run's start)
        self.change: float | None = None  # its change from the revolution before it
        self.periodic = False

    def add(self, x: np.ndarray) -> None:
        self._samples.append(np.array(x, float))

    def revolution_done(self, revolution: int) -> bool:
        """Whether revolution ``revolution`` (1-based) repeats the one before it within the tolerance."""
        current = np.hstack(self._samples) if self._samples else None
        self._samples = []
        previous, self._previous = self._previous, current
        if current is None or previous is None or previous.shape != current.shape:
            return False
        self.revolution, self.change = revolution, revolution_change(current, previous, self.positions)
        self.periodic = self.change < self.tolerance
        return self.periodic

    def record(self) -> dict:
        """``info["periodic"]`` (summary.json's ``run.periodic``): whether the run stopped as periodic, the last
        revolution compared, its change from the one before and the tolerance."""
        return {"periodic": self.periodic, "revolution": self.revolution, "change": self.change,
                "tolerance": self.tolerance, "revolutions_asked": self.revolutions_asked,
                "measure": "max of |z_k - z_(k-1)| / max(1, |z_k|), z the scaled state (µm, mrad, their rates per "
                           "rad) at the same crank angles of revolutions k and k-1: the positions at every output "
                           "sample, the whole state at the revolution's end"}


class UntilPeriodicWarning(UserWarning):
    """``operation.until_periodic`` asked of a run that cannot compare two revolutions (one revolution asked)."""


def single_revolution(until_periodic: bool, revolutions: int) -> str | None:
    """What to say when ``until_periodic`` is asked of a run of fewer than two revolutions (the default scene has
    one): it has no revolution to compare with the one before, so it neither stops early nor says whether it is
    periodic. None otherwise."""
    if not until_periodic or revolutions >= 2:
        return None
    return (f"operation.until_periodic = true does nothing with operation.revolutions = {revolutions}: a run of one "
            "revolution has no revolution before it to compare with; ask for more (operation.revolutions, or -n on "
            "the command line), the most the run may take")


def describe_periodic(record: dict) -> str | None:
    """The console line of ``info["periodic"]`` (:meth:`PeriodicWatch.record`); None before two revolutions were
    compared."""
    if record.get("revolution") is None:
        return None
    k, change, tol = record["revolution"], record["change"], record["tolerance"]
    measured = (f"revolution {k} differs from revolution {k - 1} by {change:.3g} at most over its samples "
                f"(operation.periodic_tol = {tol:g})")
    if record["periodic"]:
        asked = record["revolutions_asked"]
        return f"periodic after {k} revolutions: {measured}" + (f"; stopped before the {asked} asked" if k < asked
                                                                 else "")
    return f"not periodic: {measured}; more revolutions (operation.revolutions) or a looser tolerance"
