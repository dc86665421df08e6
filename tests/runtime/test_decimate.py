"""Long lines are reduced to their envelope over the pixel columns before the figures are saved; what is drawn
stays the same (every column's extremes, a one-sample spike, exact steps)."""

from __future__ import annotations

import io

import numpy as np
import pytest

from apexseal.runtime.results.decimate import envelope, envelope_index, step_changes
from apexseal.runtime.results.result import SimulationResult

N = 72001  # samples of a 20-revolution default run


def _signal(n=N, seed=3):
    rng = np.random.default_rng(seed)
    x = np.linspace(0.0, 7200.0, n)
    y = np.sin(x / 40) + 0.2 * rng.normal(size=n)
    y[n // 3] = 25.0  # a one-sample impact
    y[2 * n // 3] = -9.0
    return x, y


def test_envelope_keeps_every_columns_extremes_in_order():
    x, y = _signal()
    columns = 2400
    xe, ye = envelope(x, y, columns)
    assert len(xe) <= 4 * columns < N
    assert np.all(np.diff(xe) > 0)  # a subsequence, in order
    assert ye.max() == 25.0 and ye.min() == -9.0
    col = np.minimum((x / 7200.0 * columns).astype(int), columns - 1)
    cole = np.minimum((xe / 7200.0 * columns).astype(int), columns - 1)
    for c in (0, 17, 800, columns - 1):
        assert ye[cole == c].max() == y[col == c].max() and ye[cole == c].min() == y[col == c].min()
        assert xe[cole == c][0] == x[col == c][0] and xe[cole == c][-1] == x[col == c][-1]


@pytest.mark.parametrize("seed", range(6))
def test_envelope_index_is_each_slices_first_last_lowest_and_highest(seed):
    """Against a loop over the slices: the first and last sample, the first of the lowest and the last of the
    highest (NaN counts as the highest), with ties (rounded values) and NaNs."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(500, 5000))
    x = np.sort(rng.random(n)) * 360.0
    y = np.round(rng.normal(size=n), seed % 3)
    if seed % 2:
        y[rng.integers(0, n, 7)] = np.nan
    columns = int(rng.integers(10, n // 4))
    column = np.minimum(np.floor((x - x[0]) * (columns / (x[-1] - x[0]))), columns - 1)
    expected = set()
    for c in np.unique(column):
        idx = np.flatnonzero(column == c)
        v = np.where(np.isnan(y[idx]), np.inf, y[idx])
        expected |= {idx[0], idx[-1], idx[np.flatnonzero(v == v.min())[0]], idx[np.flatnonzero(v == v.max())[-1]]}
    assert envelope_index(x, y, columns).tolist() == sorted(expected)


def test_short_lines_are_left_alone():
    x, y = _signal(n=1000)
    xe, ye = envelope(x, y, 2400)
    assert xe is x or np.array_equal(xe, x)
    assert np.array_equal(ye, y)


def test_step_changes_draw_the_same_steps():
    rng = np.random.default_rng(1)
    x = np.linspace(0.0, 10.0, 5000)
    y = np.cumsum(rng.random(5000) < 0.01) % 3
    xs, ys = step_changes(x, y)
    assert len(xs) < 200 and xs[0] == x[0] and xs[-1] == x[-1]
    held = ys[np.searchsorted(xs, x, side="right") - 1]  # the post-step value at every original sample
    np.testing.assert_array_equal(held, y)


def _long_result() -> SimulationResult:
    x, y = _signal()
    n = x.size
    outputs = {"F_i1_X": y + 30.0, "F_i1_Y": np.zeros(n)}
    return SimulationResult(theta=np.radians(x), time=np.radians(x) / 157.0, state=np.zeros((6, n)),
                            closed=np.zeros((1, n), bool), events=np.zeros((1, n)), outputs=outputs,
                            guard_names=("b1",), modes=["q1"] * n)


def _line_extent(png: bytes, ax_box) -> tuple[np.ndarray, np.ndarray]:
    """Topmost and bottommost drawn (blue) pixel of each pixel column inside an axes box."""
    import matplotlib.image as mpimg

    img = mpimg.imread(io.BytesIO(png))[..., :3]
    h = img.shape[0]
    x0, x1 = int(ax_box.x0) + 2, int(ax_box.x1) - 2
    y0, y1 = h - int(ax_box.y1) + 2, h - int(ax_box.y0) - 2
    panel = img[y0:y1, x0:x1]
    blue = (panel[..., 2] > 0.5) & (panel[..., 0] < 0.6)
    rows = np.where(blue, np.arange(panel.shape[0])[:, None], np.nan)
    return np.nanmin(rows, axis=0), np.nanmax(rows, axis=0)


@pytest.mark.filterwarnings("ignore:All-NaN slice")
def test_fig13_saved_from_the_envelope_draws_the_same_extent_and_the_spike():
    """Fig. 13 of a 72 001-sample run: the panel's line has at most 4 vertices per slice, keeps the impact, and
    in every pixel column reaches the same top and bottom (within a pixel) as the line of every sample."""
    from apexseal.runtime.results.plots import figure

    result = _long_result()
    pngs, boxes = [], []
    for save_dpi in (None, 100):
        fig = figure(result, "fig13", save_dpi=save_dpi)
        buf = io.BytesIO()
        fig.savefig(buf, dpi=100, format="png")
        pngs.append(buf.getvalue())
        boxes.append(fig.axes[0].get_window_extent().frozen())
        line = fig.axes[0].lines[0]
        assert np.max(line.get_ydata()) == 55.0  # |F| of the impact sample
        if save_dpi:
            assert len(line.get_xdata()) <= 4 * 2 * 12 * 100 < N
    assert np.allclose(boxes[0].bounds, boxes[1].bounds)
    (top_a, bottom_a), (top_b, bottom_b) = (_line_extent(p, boxes[0]) for p in pngs)
    drawn = ~np.isnan(top_a) & ~np.isnan(top_b)
    assert drawn.mean() > 0.85  # the line spans the panel less its margins
    assert np.mean(np.abs(top_a - top_b)[drawn] <= 1) > 0.99
    assert np.mean(np.abs(bottom_a - bottom_b)[drawn] <= 1) > 0.99
    assert np.nanmin(top_a) == np.nanmin(top_b)  # the spike's top pixel


def test_fig13_has_one_panel_per_force_the_model_derived():
    """Fig. 13's panels come from the result's force outputs (the model's contacts, as the registry built it): a
    contact that is off has none, a registered extra contact gets one, and nothing else is drawn."""
    from apexseal.runtime.results.figures import force_panels
    from apexseal.runtime.results.plots import figure

    result = _long_result()
    n = result.n
    result.outputs.update({"F_cushion_X": np.ones(n), "F_cushion_Y": np.zeros(n), "M_cushion": np.zeros(n)})
    assert force_panels(result.outputs) == ["i1", "cushion"]
    fig = figure(result, "fig13")
    drawn = [ax for ax in fig.axes if ax.axison]
    assert [ax.get_ylabel() for ax in drawn] == ["|F i1| (N)", "|F cushion| (N)"]
    assert all(ax.get_xlabel() == "crank angle (deg)" for ax in drawn)
