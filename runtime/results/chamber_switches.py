"""Where the chambers switch: the crank angles at which the pressure difference across the seal, Pa - Pb (Eq. 75),
changes by a large part of its range in a few degrees (a port opens: the chamber on the seal's other side becomes
the high-pressure one), found from the chamber pressures at the samples of one revolution: a run's outputs ``Pa``,
``Pb``, or a scene's pressure source sampled (:func:`scene_switches`). The preload study's advice
(runtime/studies/preload/advice.py) and the calibration's verdict on the largest x (runtime/studies/calibration/
angle.py) both read them here.

A switch is a change of Pa - Pb by more than ``PRESSURE_STEP`` of its range over the revolution between two samples
``SWITCH_WIDTH_DEG`` apart (one sample apart where the samples are coarser), not a step between two neighbouring
samples: the default scene's table opens each port over 5 deg (runtime/scenes/pressure_default.py) and a run's
pressures are linear between its samples, so that the largest step between two samples is 8.6 % of the range at
720 samples per revolution and 1.7 % at 3600; a rule on neighbouring samples saw no switch there. Within the 5 deg
a switch changes Pa - Pb by 55 % of its range, the smooth expansion by at most 2.9 % (tests/runtime/
test_preload_advice.py).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

#: a chamber switch: Pa - Pb changes by more than this fraction of its range over the revolution within
#: SWITCH_WIDTH_DEG
PRESSURE_STEP = 0.25
#: crank angle (deg) within which a chamber switch changes Pa - Pb: a port's opening ramp on the default scene's table
SWITCH_WIDTH_DEG = 5.0


class Switch(NamedTuple):
    """A chamber switch of a revolution's samples (:func:`chamber_switches`)."""

    angle_deg: float  # where Pa - Pb passes halfway through its change (mod 360, linear between the samples)
    change: float  # Pa - Pb after less before, Pa
    width_deg: float  # the window it changed within


def chamber_switches(thetas, pressures, width_deg: float = SWITCH_WIDTH_DEG) -> list[Switch]:
    """The chamber switches of one revolution, in increasing angle. ``thetas`` (rad): the samples of one
    revolution, equally spaced (taken modulo 2 pi; a sample repeated a revolution later counted once);
    ``pressures`` (2 x samples, Pa): Pa and Pb there. A window of ``width_deg`` (at least one sample) is in a switch
    where Pa - Pb changes across it by more than :data:`PRESSURE_STEP` of its range; each run of such windows is one
    switch, at the window of the largest change, where Pa - Pb passes halfway through it. [] where Pa - Pb is
    constant (no chamber pressure) or changes that fast everywhere (no switch stands out)."""
    deg = np.degrees(np.asarray(thetas, float)) % 360.0
    deg, first = np.unique(np.round(deg, 9), return_index=True)  # sorted; a whole revolution's end is its start
    P = np.asarray(pressures, float)[:, first]
    dp = P[0] - P[1]
    n = dp.size
    span = float(np.ptp(dp)) if n else 0.0
    if n < 2 or not span > 0:
        return []
    k = min(max(1, math.ceil(width_deg * n / 360.0 - 1e-9)), n - 1)  # samples in a window
    change = np.roll(dp, -k) - dp  # from each sample to the one k after it
    hit = np.abs(change) > PRESSURE_STEP * span
    if hit.all():
        return []
    out = []
    for run in _runs(hit):
        j = run[int(np.argmax(np.abs(change[run])))]
        idx = (j + np.arange(k + 1)) % n
        at = deg[j] + (deg[idx] - deg[j]) % 360.0  # the window's angles, increasing across 0
        rel = (dp[idx] - (dp[j] + change[j] / 2)) * np.sign(change[j])  # < 0 before halfway, >= 0 from it
        m = int(np.argmax(rel >= 0))
        a = at[m - 1] + (at[m] - at[m - 1]) * -rel[m - 1] / (rel[m] - rel[m - 1])
        out.append(Switch(float(a % 360.0), float(change[j]), float(at[-1] - at[0])))
    return sorted(out)


def _runs(hit: np.ndarray) -> list[np.ndarray]:
    """The indices of each run of True in ``hit``, cyclically (a run may cross the end); ``hit`` has a False."""
    n = hit.size
    first = int(np.argmin(hit))  # a False: no run crosses it
    runs, current = [], []
    for i in (first + 1 + np.arange(n)) % n:
        if hit[i]:
            current.append(i)
        elif current:
            runs.append(np.array(current))
            current = []
    return runs


def scene_switches(scene, samples: int | None = None) -> list[Switch]:
    """:func:`chamber_switches` of ``scene``'s pressure source (its table, or constant pressures) over one revolution
    of ``samples`` samples (default: the scene's ``solver.samples_per_revolution``), at the crank angles a run's
    ``theta`` measures (from ``operation.start_angle``). [] for the chamber gas model, whose pressures are a run's
    states: take them from a run's outputs ``Pa``, ``Pb``."""
    n = samples or scene.solver.samples_per_revolution
    thetas = np.arange(n) * (2 * math.pi / n)
    source = scene.pressure
    absolute = scene.operation.start_angle + thetas
    return chamber_switches(thetas, np.vstack([source.Pa(absolute), source.Pb(absolute)]))
