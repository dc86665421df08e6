"""The numpy peak finder of summary.json and Fig. 14 gives SciPy's peaks and prominences (it replaced
``scipy.signal.find_peaks``, whose import cost more than a default run's integration)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import find_peaks as scipy_find_peaks

from apexseal.runtime.results.peaks import find_peaks, local_maxima


def _signals():
    rng = np.random.default_rng(7)
    yield "noise", rng.normal(size=2000)
    yield "rounded noise (flat tops)", np.round(rng.normal(size=2000), 1)
    yield "integers (many plateaus)", rng.integers(0, 5, size=500).astype(float)
    w = np.linspace(0, 1e5, 4001)
    hump = 7 * np.exp(-(((w - 1.5e4) / 3e3) ** 2)) * (1 + 0.08 * np.sin(w / 300))
    yield "rippled hump", hump + 2 * np.exp(-(((w - 6e4) / 2e3) ** 2)) + 0.01
    t = np.linspace(0, 1, 3600, endpoint=False)
    s = np.abs(np.sin(2 * np.pi * 3 * t)) + 0.3 * np.sin(2 * np.pi * 170 * t) + 0.05 * rng.normal(size=t.size)
    yield "spectrum", np.abs(np.fft.rfft((s - s.mean()) * np.hanning(s.size)))
    yield "flat ends", np.array([3.0, 3.0, 1.0, 2.0, 2.0, 2.0, 1.0, 5.0, 5.0])


@pytest.mark.parametrize("name,x", list(_signals()), ids=[n for n, _ in _signals()])
@pytest.mark.parametrize("fraction", [0.0, 0.05, 0.3])
def test_same_peaks_and_prominences_as_scipy(name, x, fraction):
    p = fraction * float(np.ptp(x))
    expected, props = scipy_find_peaks(x, prominence=p)
    idx, prom = find_peaks(x, prominence=p)
    np.testing.assert_array_equal(idx, expected)
    np.testing.assert_allclose(prom, props["prominences"], rtol=0, atol=0)


def test_plateau_peak_is_its_middle_and_ends_never_count():
    x = np.array([5.0, 1.0, 2.0, 2.0, 2.0, 2.0, 0.0, 1.0, 1.0, 3.0])
    assert local_maxima(x).tolist() == [3]  # the middle of indices 2..5, rounded down
    assert local_maxima(np.array([1.0, 2.0])).size == 0
