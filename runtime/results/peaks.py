"""Peaks of a sampled signal with their prominences: ``scipy.signal.find_peaks(x, prominence=p)`` in numpy.

Same definitions and same results as SciPy (a test compares them on random, flat-topped and spectral data):
a peak is a sample, or the middle (rounded down) of a flat run of samples, that is higher than both its
neighbours; its prominence is its height above the higher of the two lowest points reached on each side before
the signal rises above the peak or ends. Written here because importing ``scipy.signal`` costs about a second,
more than a default run's integration, and summary.json and Fig. 14 need nothing else from it.
"""

from __future__ import annotations

import numpy as np


def local_maxima(x: np.ndarray) -> np.ndarray:
    """Indices of the local maxima of ``x`` (a flat top counts once, at its middle rounded down; the first and
    last samples never count)."""
    x = np.asarray(x, dtype=float)
    if x.size < 3:
        return np.zeros(0, dtype=np.intp)
    starts = np.flatnonzero(np.r_[True, x[1:] != x[:-1]])  # runs of equal values
    ends = np.r_[starts[1:] - 1, x.size - 1]
    v = x[starts]
    inner = np.arange(1, v.size - 1)
    top = inner[(v[inner - 1] < v[inner]) & (v[inner + 1] < v[inner])]
    return (starts[top] + ends[top]) // 2


def prominences(x: np.ndarray, peaks: np.ndarray) -> np.ndarray:
    """The prominence of each peak (``scipy.signal.peak_prominences`` without a window)."""
    x = np.asarray(x, dtype=float)
    out = np.empty(len(peaks))
    for k, i in enumerate(peaks):
        h = x[i]
        left = np.flatnonzero(x[:i] > h)
        right = np.flatnonzero(x[i + 1:] > h)
        lo = left[-1] + 1 if left.size else 0
        hi = i + 1 + right[0] if right.size else x.size
        out[k] = h - max(x[lo:i + 1].min(), x[i:hi].min())
    return out


def find_peaks(x: np.ndarray, prominence: float) -> tuple[np.ndarray, np.ndarray]:
    """The peaks of ``x`` whose prominence is at least ``prominence``, and their prominences, in index order."""
    x = np.asarray(x, dtype=float)
    peaks = local_maxima(x)
    if peaks.size:  # a prominence never exceeds the height above the lowest sample: skip hopeless peaks
        peaks = peaks[x[peaks] - x.min() >= prominence]
    prom = prominences(x, peaks)
    keep = prom >= prominence
    return peaks[keep], prom[keep]
