"""A contact's force on the seal, and the seal-housing contact force's spectrum (Fig. 14): the signal, its one-sided
amplitude spectrum and its distinct peaks, for the summary, the figures, the plausibility check and the calibration
against the paper's features."""

from __future__ import annotations

import numpy as np

from .peaks import find_peaks
from .result import SimulationResult


def contact_force(outputs, contact: str) -> np.ndarray | None:
    """The magnitude of a contact's force on the seal, |F_<contact>| from its X and Y outputs (N); None for a contact
    the model does not have."""
    if f"F_{contact}_X" not in outputs:
        return None
    return np.hypot(np.asarray(outputs[f"F_{contact}_X"], float), np.asarray(outputs[f"F_{contact}_Y"], float))


def housing_force(result: SimulationResult) -> np.ndarray:
    """|Fs5|, the seal-housing contact force (Eq. 68), N."""
    force = contact_force(result.outputs, "housing")
    return np.zeros(result.n) if force is None else force


def spectrum(signal: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """One-sided amplitude spectrum (angular frequency in rad/s, amplitude) of a uniformly sampled signal."""
    s = np.asarray(signal, float) - np.mean(signal)
    n = s.size
    window = np.hanning(n)
    amp = np.abs(np.fft.rfft(s * window)) * 2 / window.sum()
    w = 2 * np.pi * np.fft.rfftfreq(n, dt)
    return w, amp


def spectral_peaks(w: np.ndarray, amp: np.ndarray, count: int = 5, *, min_prominence: float = 0.05,
                   hump: float = 0.5) -> list[dict]:
    """The distinct peaks of a spectrum, largest first (``scipy.signal.find_peaks`` with prominence; computed by
    :func:`.peaks.find_peaks`, which gives the same peaks without importing ``scipy.signal``).

    A peak counts if its prominence (its height above the higher of the two valleys that separate it from
    higher ground) is at least ``min_prominence`` times the largest amplitude and at least ``hump`` times its
    own amplitude: a ripple on the flank of a hump rises little above its valley and is not listed apart.
    """
    if amp.size < 3 or not np.any(amp > 0):
        return []
    idx, prom = find_peaks(amp, prominence=min_prominence * float(amp.max()))
    keep = prom >= hump * amp[idx]
    idx, prom = idx[keep], prom[keep]
    order = np.argsort(amp[idx])[::-1][:count]
    return [{"omega_rad_s": float(w[idx[i]]), "amplitude_N": float(amp[idx[i]]), "prominence_N": float(prom[i])}
            for i in order]
