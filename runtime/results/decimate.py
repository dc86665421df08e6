"""Fewer points for a line than it has samples, drawn the same: what the figures of a long run plot.

A 20-revolution run has 72 000 samples per quantity, a figure panel about a thousand pixel columns. Two
reductions keep what is drawn:

* :func:`envelope` (a line against an increasing x): in each of ``columns`` equal slices of x, the first, the
  lowest, the highest and the last sample, in their order. The line still reaches every extreme of every slice
  (a one-sample spike survives) and joins the slices where it did, so with at least one slice per pixel column
  the drawn envelope is that of the full line.
* :func:`step_changes` (a step plot): the samples where the value changes, and the last one. A step drawn
  through them has exactly the vertices of the full step, less the repeated ones.
"""

from __future__ import annotations

import numpy as np

#: slices of x per pixel column of the figure (more than one: a panel is narrower than the figure)
PER_PIXEL = 2


def envelope(x: np.ndarray, y: np.ndarray, columns: int) -> tuple[np.ndarray, np.ndarray]:
    """``(x, y)`` reduced to the first, lowest, highest and last sample of each of ``columns`` equal slices of
    the range of ``x`` (which must increase); unchanged when that would not make it shorter."""
    keep = envelope_index(x, y, columns)
    return np.asarray(x)[keep], np.asarray(y)[keep]


def envelope_index(x: np.ndarray, y: np.ndarray, columns: int) -> np.ndarray:
    """The indices :func:`envelope` keeps (for a log axis: pass ``log(x)``, plot ``x[index]``): in each slice its
    first and last sample, its lowest (the first of equal ones) and its highest (the last of equal ones; a NaN
    counts as the highest, as in a sort). Linear in the samples: minima and maxima per slice, no sort."""
    x, y = np.asarray(x, dtype=float), np.asarray(y)
    if x.size <= 4 * columns or columns < 1:
        return np.arange(x.size)
    span = float(x[-1] - x[0]) or 1.0
    column = np.minimum(np.floor((x - x[0]) * (columns / span)), columns - 1)  # floor: a cast to int is 15x slower
    starts = np.flatnonzero(np.r_[True, column[1:] != column[:-1]])  # x increases: columns are contiguous
    ends = np.r_[starts[1:] - 1, x.size - 1]
    value = np.where(np.isnan(y), np.inf, y) if y.dtype.kind in "fc" else y
    slice_of = np.repeat(np.arange(starts.size), ends - starts + 1)
    low = np.flatnonzero(value == np.minimum.reduceat(value, starts)[slice_of])
    lowest = low[np.r_[True, slice_of[low][1:] != slice_of[low][:-1]]]  # the first of each slice
    high = np.flatnonzero(value == np.maximum.reduceat(value, starts)[slice_of])
    highest = high[np.r_[slice_of[high][1:] != slice_of[high][:-1], True]]  # the last of each slice
    keep = np.zeros(x.size, bool)
    for index in (starts, ends, lowest, highest):
        keep[index] = True
    return np.flatnonzero(keep)  # sorted, each once


def step_changes(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The samples of a step function (``where="post"``) where ``y`` changes, the first and the last."""
    x, y = np.asarray(x), np.asarray(y)
    if y.size < 3:
        return x, y
    keep = np.flatnonzero(np.r_[True, y[1:] != y[:-1]])
    if keep[-1] != y.size - 1:
        keep = np.r_[keep, y.size - 1]
    return x[keep], y[keep]


def columns_of(fig, dpi: float) -> int:
    """Slices for :func:`envelope` in a panel of ``fig`` saved at ``dpi``: :data:`PER_PIXEL` per pixel column of
    the whole figure (a panel has fewer)."""
    return int(np.ceil(fig.get_figwidth() * dpi * PER_PIXEL))

