"""Ticks of the saved figures: plain-text decades on logarithmic axes, few crank-angle ticks; the modes figure's cases."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from apexseal.runtime.results.figures import crank_angle_ticks, decade_label, plain_log_ticks


def test_decade_labels_are_plain_text():
    assert decade_label(1e3) == "10³"
    assert decade_label(1e-2) == "10⁻²"
    assert decade_label(1.0) == "10⁰"
    assert decade_label(2e3) == "" and decade_label(0.0) == "" and decade_label(-10.0) == ""


def _labels(fig, axis):
    fig.canvas.draw()
    return [t.get_text() for t in axis.get_ticklabels() if t.get_text()]


def test_log_axes_over_several_decades_get_plain_labels_and_fewer_minor_ticks():
    fig = Figure()
    ax = fig.subplots()
    ax.loglog([10.0, 3e5], [1e-3, 30.0])
    ax.set_xlim(10.0, 3e5)
    ax.set_ylim(1e-3, 30.0)
    plain_log_ticks(ax)
    labels = _labels(fig, ax.xaxis)
    assert labels and all("$" not in t and t.startswith("10") for t in labels)
    lo, hi = ax.get_xlim()
    minor = [t for t in ax.xaxis.get_minorticklocs() if lo <= t <= hi]
    decades = np.log10(hi) - np.log10(lo)
    assert len(minor) <= 2 * (decades + 1)  # 2 and 5 in each decade, not 2..9


def test_a_log_axis_within_one_decade_keeps_matplotlibs_ticks():
    fig = Figure()
    ax = fig.subplots()
    ax.loglog([2.0, 8.0], [2.0, 8.0])
    ax.set_xlim(2.0, 8.0)
    formatter = ax.xaxis.get_major_formatter()
    plain_log_ticks(ax)
    assert ax.xaxis.get_major_formatter() is formatter


def test_crank_angle_ticks():
    fig = Figure()
    ax = fig.subplots()
    ax.plot([0.0, 360.0], [0.0, 1.0])
    ax.set_xlim(0.0, 360.0)
    crank_angle_ticks(ax)
    ticks = [t for t in ax.get_xticks() if 0.0 <= t <= 360.0]
    assert ticks == [0.0, 90.0, 180.0, 270.0, 360.0]
    ax.set_xlim(0.0, 7200.0)  # 20 revolutions
    assert len([t for t in ax.get_xticks() if 0.0 <= t <= 7200.0]) <= 6
    assert len([t for t in ax.get_yticks() if 0.0 <= t <= 1.0]) <= 5


def test_the_skeleton_of_a_figure_keeps_its_axes_and_texts_without_its_data():
    """``figure_timing.skeleton`` (the floor the figure timing prints): same grid cells, projections, scales, tick labels
    and titles as the figure, and a two-point line instead of the data."""
    from apexseal.runtime.bench.figure_timing import skeleton

    fig = Figure(figsize=(6, 4), layout="constrained")
    left, right = fig.subplots(1, 2)
    left.plot(np.linspace(0, 360, 3601), np.sin(np.linspace(0, 20, 3601)))
    left.set_title("forces")
    left.set_ylabel("|F| (N)")
    crank_angle_ticks(left)
    right.loglog([10.0, 3e5], [1e-3, 30.0])
    right.set_xlim(10.0, 3e5)
    plain_log_ticks(right)
    fig.suptitle("figure")
    fig.draw_without_rendering()
    sk = skeleton(fig)
    sk.draw_without_rendering()
    assert len(sk.axes) == 2 and sk.get_suptitle() == "figure"
    assert [ax.get_subplotspec().get_geometry() for ax in sk.axes] == [(1, 2, 0, 0), (1, 2, 1, 1)]
    for a, b in zip(fig.axes, sk.axes, strict=True):
        assert (b.get_xscale(), b.get_yscale(), b.get_title(), b.get_ylabel()) == \
            (a.get_xscale(), a.get_yscale(), a.get_title(), a.get_ylabel())
        for axis in ("x", "y"):
            assert _labels(sk, getattr(b, f"{axis}axis")) == _labels(fig, getattr(a, f"{axis}axis"))
        assert [len(line.get_xdata()) for line in b.get_lines()] == [2]


def test_contact_cases_index_each_sample_by_its_case():
    """figures.contact_cases against its definition: the sorted cases (label before the first ``_``) and each
    sample's index among them; no samples, no cases."""
    from apexseal.runtime.results.figures import contact_cases

    rng = np.random.default_rng(3)
    modes = list(rng.choice(["0", "I_c2_i1", "I_i2", "II_c2_i2_c4", "III", "II"], 500))
    cases, idx = contact_cases(modes)
    assert cases == ["0", "I", "II", "III"]
    assert [cases[i] for i in idx] == [m.split("_")[0] for m in modes]
    cases, idx = contact_cases([])
    assert cases == [] and idx.shape == (0,)
