"""Where the chambers switch: the crank angles at which the pressure difference across the seal, Pa - Pb (Eq. 75),
changes by a large part of its range in a few degrees (a port opens: the chamber on the seal's other side becomes
the high-pressure one), found from the chamber pressures at the samples of one revolution: a run's outputs ``Pa``,
``Pb``, or a scene's pressure source sampled (:func:`scene_switches`).

The rule is that of the preload study's advice (runtime/studies/preload/advice.py ``shortfall_kind``): a step of
Pa - Pb of more than ``PRESSURE_STEP`` of its range over the revolution between two samples. Between two samples
alone it depends on the sampling: the default scene's table opens its ports over 5 deg
(runtime/scenes/pressure_default.py), so at 720 samples per revolution or more no step between two samples exceeds
9 % of the range. :func:`chamber_switches` also takes the change over ``SWITCH_WIDTH_DEG`` before each sample, so
that it finds the same switches at any sampling.
"""

from __future__ import annotations

import math

import numpy as np

#: a chamber switch: a step of Pa - Pb larger than this fraction of its range over the revolution
PRESSURE_STEP = 0.25
#: crank angle (deg) over which :func:`chamber_switches` also measures the step: a port's opening ramp on the
#: default scene's table
SWITCH_WIDTH_DEG = 5.0


def pressure_steps(pressures) -> tuple[np.ndarray, np.ndarray, float]:
    """Pa - Pb at each sample of ``pressures`` (2 x samples, Pa; the samples of one revolution in order), the step
    into each sample from the one before (periodically: the first from the last) and the range of Pa - Pb."""
    dp = np.asarray(pressures[0], float) - np.asarray(pressures[1], float)
    return dp, np.abs(dp - np.roll(dp, 1)), float(np.ptp(dp)) if dp.size else 0.0


def chamber_switches(thetas, pressures, width_deg: float = SWITCH_WIDTH_DEG) -> list[tuple[float, float]]:
    """The chamber switches of one revolution: ``(crank angle in deg, change of Pa - Pb in Pa)`` for each, in
    increasing angle. ``thetas`` (rad; taken modulo 2 pi, a sample repeated a revolution later counted once) and
    ``pressures`` (2 x samples, Pa) at the samples. A sample is in a switch where Pa - Pb has changed by more than
    ``PRESSURE_STEP`` of its range since the sample before or since ``width_deg`` before it (interpolated,
    periodically); each run of such samples is one switch. Its change is that from ``width_deg`` (or the sample)
    before the run to the run's last sample, and its angle that of the first sample of the run past the middle of
    that change (the sample a step leads into; the middle of a ramp). [] where Pa - Pb is constant (no chamber
    pressure)."""
    deg = np.degrees(np.asarray(thetas, float)) % 360.0
    deg, first = np.unique(np.round(deg, 9), return_index=True)  # sorted; a whole revolution's end is its start
    P = np.asarray(pressures, float)[:, first]
    dp, steps, span = pressure_steps(P)
    if deg.size < 2 or span <= 0:
        return []
    back = np.interp(deg - width_deg, deg, dp, period=360.0) if width_deg > 0 else dp
    inside = np.maximum(steps, np.abs(dp - back)) > PRESSURE_STEP * span
    if inside.all():  # Pa - Pb changes everywhere that fast: no switch stands out
        return []
    starts = np.flatnonzero(inside & ~np.roll(inside, 1))
    out = []
    n = deg.size
    for s in starts:
        run = [s]
        while inside[(run[-1] + 1) % n]:
            run.append((run[-1] + 1) % n)
        gap = (deg[s] - deg[s - 1]) % 360.0  # to the sample before the run
        before = np.interp(deg[s] - width_deg, deg, dp, period=360.0) if width_deg > gap else dp[s - 1]
        change = float(dp[run[-1]] - before)
        j = next((i for i in run if (dp[i] - before) * math.copysign(1.0, change) >= abs(change) / 2), run[-1])
        out.append((float(deg[j]), change))
    return sorted(out)


def scene_switches(scene, samples: int | None = None) -> list[tuple[float, float]]:
    """:func:`chamber_switches` of ``scene``'s pressure source (its table, or constant pressures) over one revolution
    of ``samples`` samples (default: the scene's ``solver.samples_per_revolution``), at the crank angles a run's
    ``theta`` measures (from ``operation.start_angle``). [] for the chamber gas model, whose pressures are a run's
    states: take them from a run's outputs ``Pa``, ``Pb``."""
    n = samples or scene.solver.samples_per_revolution
    thetas = np.arange(n) * (2 * math.pi / n)
    source = scene.pressure
    absolute = scene.operation.start_angle + thetas
    return chamber_switches(thetas, np.vstack([source.Pa(absolute), source.Pb(absolute)]))
