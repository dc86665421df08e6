"""The features of the paper's case study (Section 4.5, Figs. 12-14) measured on a run.

The paper prints no parameter values, only what it saw:

* Fig. 14 and the text after it: the spectrum of the seal-housing force |Fs5| "centres at around 6 x 10^4 rad/s",
  with smaller peaks near 0.01, 0.05 and 0.78 x 10^4 rad/s;
* Fig. 12a and the text: the displacement x (out of the groove, into the housing) "is of significant magnitude"
  with the seal "approximately at the 3 pi/2 (270 deg) position on the housing", where it digs into the housing
  wall. Compared here with the crank angle of the largest x: one reading of a text that does not settle which angle
  it means (docs/paper-findings.md, finding 3).

:func:`features` measures the same things on the last whole revolution of a result (the start transient left
out): the frequency of the largest peak of the |Fs5| spectrum above ``MIN_CONTACT_HARMONIC`` times the rotor
speed (below it lie the rotor's own harmonics), the largest peak in each band around the paper's smaller
peaks, the crank angle of the largest x, and the housing force's mean and maximum.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ...results.chamber_switches import chamber_switches
from ...results.spectra import housing_force, spectrum

#: the paper's Fig. 14 peaks, rad/s (text after Fig. 14): the main one, then the smaller ones
PAPER_MAIN_PEAK = 6.0e4
PAPER_SMALL_PEAKS = (1.0e2, 5.0e2, 7.8e3)
#: the angle where the paper's x is largest (Section 4.5: "approximately at the 3 pi/2 position on the housing"),
#: taken as a crank angle
PAPER_X_ANGLE_DEG = 270.0
#: peaks below this multiple of the rotor speed are the rotor's harmonics, not a contact's mode
MIN_CONTACT_HARMONIC = 20
#: the spectrum is smoothed over this many bins (one bin = the rotor speed) before its peak is taken
SMOOTH_BINS = 5


@dataclass(frozen=True)
class Features:
    main_peak_rad_s: float  # largest peak of the |Fs5| spectrum above MIN_CONTACT_HARMONIC omega
    small_peaks_rad_s: tuple[float, ...]  # largest peak in a band of a factor 2 around each of PAPER_SMALL_PEAKS
    x_max_deg: float  # crank angle of the largest x (into the housing)
    x_max_um: float
    housing_force_mean_N: float
    housing_force_max_N: float

    def to_dict(self) -> dict:
        return asdict(self)


def last_revolution(result) -> slice:
    """The samples of the last whole revolution (the whole run if it is shorter than one revolution)."""
    turns = (result.theta - result.theta[0]) / (2 * np.pi)
    whole = int(np.floor(turns[-1] + 1e-9))
    if whole < 1:
        return slice(0, result.n)
    start = int(np.searchsorted(turns, whole - 1 - 1e-9))
    return slice(start, result.n)


def force_spectrum(result, window: slice | None = None, bins: int = SMOOTH_BINS) -> tuple[np.ndarray, np.ndarray]:
    """The amplitude spectrum of |Fs5| over ``window`` (default: the last revolution), smoothed over ``bins`` bins
    (1: not smoothed). Over one revolution the bins are the rotor speed apart."""
    window = window or last_revolution(result)
    F = housing_force(result)[window]
    return smoothed_spectrum(F, float(np.mean(np.diff(result.time[window]))), bins)


def smoothed_spectrum(signal: np.ndarray, dt: float, bins: int = SMOOTH_BINS) -> tuple[np.ndarray, np.ndarray]:
    """The amplitude spectrum of ``signal`` (sampled every ``dt`` s), smoothed over ``bins`` bins."""
    w, amp = spectrum(signal, dt)
    return w, np.convolve(amp, np.ones(bins) / bins, mode="same")


def main_peak(w: np.ndarray, amp: np.ndarray, omega: float) -> tuple[float, float]:
    """The frequency (rad/s) and amplitude of the largest peak above ``MIN_CONTACT_HARMONIC`` times the rotor speed
    ``omega`` (nan, nan where the spectrum ends below it)."""
    band = np.flatnonzero(w >= MIN_CONTACT_HARMONIC * omega)
    if band.size == 0:
        return float("nan"), float("nan")
    j = band[np.argmax(amp[band])]
    return float(w[j]), float(amp[j])


def _peak_in(w: np.ndarray, amp: np.ndarray, lo: float, hi: float) -> float:
    band = (w >= lo) & (w <= hi)
    if not band.any():
        return float("nan")
    return float(w[band][np.argmax(amp[band])])


def features(result, omega: float) -> Features:
    """The paper's features measured on the last whole revolution of ``result`` (rotor speed ``omega``, rad/s)."""
    window = last_revolution(result)
    w, amp = force_spectrum(result, window)
    main = main_peak(w, amp, omega)[0]
    small = tuple(_peak_in(w, amp, p / 2, p * 2) for p in PAPER_SMALL_PEAKS)
    x = result.state[0][window]
    deg = np.degrees(result.theta[window]) % 360
    F = housing_force(result)[window]
    return Features(main, small, float(deg[np.argmax(x)]), float(x.max() * 1e6), float(F.mean()), float(F.max()))


def switches_of(result) -> tuple[float, ...]:
    """The crank angles (deg) of the chamber switches in the last whole revolution of ``result``, found from its
    chamber pressures ``Pa``, ``Pb`` (runtime/results/chamber_switches.py): where the largest x lies relative to
    them is part of the calibration's verdict (:mod:`.angle`)."""
    window = last_revolution(result)
    pressures = np.vstack([result.outputs["Pa"][window], result.outputs["Pb"][window]])
    return tuple(s.angle_deg for s in chamber_switches(result.theta[window], pressures))


def angle_error_deg(a: float, b: float) -> float:
    """The smallest difference of two crank angles, degrees (0..180)."""
    d = abs(a - b) % 360
    return min(d, 360 - d)
