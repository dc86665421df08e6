"""The figure timing command's whole-run pairs (``python -m apexseal.runtime.bench.figure_timing 7 --pairs``).

No time is asserted (the machine is shared); what is checked is that each run of a pair is the run it claims to be
(figures written, or not) and that the medians and ratios are those of the measured runs.
"""

from __future__ import annotations

import statistics

from apexseal.runtime.bench import figure_timing


def test_a_whole_run_is_timed_from_outside_with_the_processes_it_waited_for(tmp_path):
    wall, cpu = figure_timing._whole_run(str(tmp_path / "with"), figures=True)
    assert wall > 0 and cpu > 0
    assert sorted(p.name for p in (tmp_path / "with").glob("*.png"))  # the figures were drawn in that run
    figure_timing._whole_run(str(tmp_path / "without"), figures=False)
    assert (tmp_path / "without" / "result.json").is_file() and not list((tmp_path / "without").glob("*.png"))


def test_pairs_report_the_medians_of_the_runs_and_of_their_differences(monkeypatch):
    measured = iter([(1.0, 2.0), (0.5, 0.6),  # the warm-up pair (without first), not counted
                     (1.1, 2.1), (0.6, 0.7),  # pair 1: with figures first
                     (0.4, 0.5), (1.3, 2.0),  # pair 2: without first
                     (1.0, 1.8), (0.5, 0.6)])  # pair 3
    calls = []

    def fake(folder, figures):
        calls.append(figures)
        return next(measured)

    monkeypatch.setattr(figure_timing, "_whole_run", fake)
    m = figure_timing.measure_pairs(3)
    assert calls == [False, True, True, False, False, True, True, False]
    assert m["wall_with_s"] == statistics.median([1.1, 1.3, 1.0]) and m["wall_without_s"] == 0.5
    assert m["wall_added_s"] == statistics.median([1.1 - 0.6, 1.3 - 0.4, 1.0 - 0.5])
    assert m["cpu_added_s"] == statistics.median([2.1 - 0.7, 2.0 - 0.5, 1.8 - 0.6])
    assert m["wall_added_over_without"] == m["wall_added_s"] / m["wall_without_s"]


def test_the_least_figure_is_one_constrained_axes_with_the_runs_x(tmp_path, monkeypatch):
    """``figure_timing.single_axes`` is the floor the README quotes against the ``simulate()`` call: it must stay one axes
    with constrained layout holding the run's x (in the unit of its label), saved as a 640 x 480 PNG."""
    import numpy as np
    from matplotlib.figure import Figure

    from apexseal.runtime.results.outputs import describe

    class Run:
        theta = np.linspace(0.0, 2 * np.pi, 361)

        @staticmethod
        def column(name):
            assert name == "x"
            return 1e-6 * np.sin(Run.theta)

    drawn = []
    save = Figure.savefig

    def keep(fig, *args, **kwargs):
        drawn.append(fig)
        return save(fig, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", keep)
    figure_timing.single_axes(Run, tmp_path / "least.png")
    (fig,) = drawn
    assert fig.get_layout_engine() is not None and len(fig.axes) == 1
    (line,) = fig.axes[0].get_lines()
    np.testing.assert_allclose(line.get_ydata(), Run.column("x") * describe("x").scale)
    assert fig.axes[0].get_ylabel() == describe("x").label
    png = (tmp_path / "least.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    assert int.from_bytes(png[16:20], "big") == 640 and int.from_bytes(png[20:24], "big") == 480
