"""The seal tip off the housing: its part of a run in every summary, a warning when it is most of the run, and a
Fig. 14 that says why it has no spectrum (runtime/results/liftoff.py)."""

from __future__ import annotations

import logging
import warnings
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

import apexseal
from apexseal.runtime.results.figures import fig14_spectrum
from apexseal.runtime.results.liftoff import LiftOffWarning, liftoff
from apexseal.runtime.results.quantities import collect
from apexseal.runtime.results.summary import summarise

SAMPLES = 360  # the integrator of tests/runtime/test_simulate.py: compiled once per session
#: a constant 100 bar on one side, the seal started 20 µm inside its groove: the side load holds it there by
#: friction, off the housing for the whole revolution (the case of a user's walk-through)
HELD_OFF = {"pressure.source": "constant", "pressure.Pa": "100 bar", "pressure.Pb": "1 bar",
            "operation.initial_state.x": "-20 um"}


def _run(scene, functions):
    """A revolution of ``scene`` at SAMPLES, and the warnings it gave."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = apexseal.simulate(scene, samples_per_revolution=SAMPLES, functions=functions.sx)
    return result, caught


@pytest.fixture(scope="module")
def default_run(default_scene, default_functions):
    return _run(default_scene, default_functions)


@pytest.fixture(scope="module")
def held_off(default_scene, default_functions):
    return _run(default_scene.with_overrides(**HELD_OFF), default_functions)


def _tip_off(modes) -> np.ndarray:
    """Each mode label's tip state, counted here from the labels themselves: ``h0`` is the housing contact open."""
    return np.array(["h0" in m.split("_") for m in modes])


def test_the_part_off_the_housing_is_counted_from_the_modes_with_its_longest_stretch():
    """The fraction is the share of the samples after the start whose mode has the tip open (``*_h0_*``; it was
    the sweeps' and compare's alone, read off ``mode_fraction``, and no run's summary had it); the longest
    stretch counts each lifted sample from the sample before it."""
    modes = ["q1_h0_s", "q1_h_s", "q1_h0_s", "p2_h0_s0", "q1_h_s", "q1_h0_s", "q1_h0_s", "q1_h0_s"]
    theta = np.radians(np.arange(8) * 45.0)
    check = liftoff(SimpleNamespace(n=8, modes=modes, theta=theta))
    assert check == {"fraction": pytest.approx(5 / 7), "longest_deg": pytest.approx(135.0),
                     "longest_from_deg": pytest.approx(180.0), "ok": False}  # 5/7 of the run is most of it
    assert liftoff(SimpleNamespace(n=3, modes=["q1_s"] * 3, theta=theta[:3])) is None  # no housing contact
    brief = liftoff(SimpleNamespace(n=8, modes=["q1_h_s"] * 7 + ["q1_h0_s"], theta=theta))
    assert brief["fraction"] == pytest.approx(1 / 7) and brief["longest_deg"] == pytest.approx(45.0) and brief["ok"]


def test_a_default_run_reports_the_lift_off_fraction_that_sweeps_and_compare_collect(default_run):
    """summary.json had no lift-off fraction: only a sweep's or a comparison's row had one. A default revolution
    lifts the tip off for a few samples at the chamber switches: its summary says how much, the same number a sweep
    collects, and warns of nothing."""
    result, caught = default_run
    check = summarise(result)["liftoff"]
    off = _tip_off(result.modes[1:])
    assert check["fraction"] == pytest.approx(off.mean(), rel=1e-12) and 0 < check["fraction"] < 0.05
    assert collect(result, ("liftoff_fraction",))["liftoff_fraction"] == check["fraction"]
    step = 360 / SAMPLES
    assert step * (1 - 1e-9) <= check["longest_deg"] <= off.sum() * step * (1 + 1e-9)
    assert check["ok"] and check["longest_from_deg"] is not None
    assert not [w for w in caught if issubclass(w.category, LiftOffWarning)]


def test_a_tip_held_off_the_housing_for_the_whole_revolution_is_warned_of_once(held_off):
    """A constant 100 bar on one side, with the seal held in its groove by friction, kept the tip off the housing
    for the whole revolution without a word: the run warns once, with the numbers and what they mean."""
    result, caught = held_off
    said = [w for w in caught if issubclass(w.category, LiftOffWarning)]
    assert len(said) == 1, [str(w.message) for w in caught]
    text = str(said[0].message)
    assert text.startswith("the seal tip is off the housing for 100.0% of the samples of 1 revolution (longest 360° "
                           "in one stretch, from 0°)"), text
    for part in ("does not seal the chambers", "contact force Fs5 is zero", "chamber pressures", "spring preload"):
        assert part in text, part
    check = summarise(result)["liftoff"]
    assert check == {"fraction": 1.0, "longest_deg": pytest.approx(360.0), "longest_from_deg": 0.0, "ok": False}
    assert _tip_off(result.modes[1:]).all() and not np.any(result.outputs["F_housing_X"][1:])
    assert collect(result, ("liftoff_fraction",))["liftoff_fraction"] == 1.0


def _drawn_quietly(fig, caplog) -> None:
    """Draw ``fig``; fail on any warning, or any record of matplotlib's logger."""
    with warnings.catch_warnings(), caplog.at_level(logging.WARNING, logger="matplotlib"):
        warnings.simplefilter("error")
        FigureCanvasAgg(fig).draw()
    assert not [r for r in caplog.records if r.name.startswith("matplotlib")], caplog.text


def test_fig14_of_a_tip_never_on_the_housing_says_why_and_warns_nothing(held_off, caplog):
    """Fig. 14 of a run with no housing force was an empty log plot, and matplotlib warned of a non-positive
    limit on the log axis: it now says why it has no spectrum, without a warning."""
    result, _ = held_off
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fig = fig14_spectrum(result, save_dpi=100)
    _drawn_quietly(fig, caplog)
    ax = fig.axes[0]
    assert [t.get_text() for t in ax.texts] == ["the seal tip is off the housing for the whole run:\nno contact force "
                                                "Fs5, so no spectrum\n(summary.json: liftoff)"]
    assert ax.get_yscale() == "linear" and not ax.lines


def test_fig14_of_a_constant_housing_force_says_so(default_run, caplog):
    """A constant force's spectrum is round-off (zero after the mean is taken out): drawn, it set a log axis's
    limits from nothing and matplotlib warned; the figure says the force is constant."""
    result, _ = default_run
    outputs = dict(result.outputs, F_housing_X=np.full(result.n, -50.0), F_housing_Y=np.zeros(result.n))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fig = fig14_spectrum(replace(result, outputs=outputs))
    _drawn_quietly(fig, caplog)
    assert [t.get_text() for t in fig.axes[0].texts] == ["the seal-housing force Fs5 is constant (50 N): no spectrum"]


def test_fig14_of_a_default_run_is_still_a_log_spectrum(default_run, caplog):
    fig = fig14_spectrum(default_run[0])
    _drawn_quietly(fig, caplog)
    ax = fig.axes[0]
    assert ax.get_xscale() == ax.get_yscale() == "log" and ax.lines
    assert not any("no spectrum" in t.get_text() for t in ax.texts)


def test_the_warning_says_the_spring_is_off_and_the_console_names_its_class(held_off, capsys):
    """With the spring off (``--set effects.spring=false``) the warning still asked to check "the spring preload
    (spring.delta_s, spring.ks)", keys that do nothing then; and the console's line of it lacked the
    "(LiftOffWarning)" tag the other warnings show. The run's contacts say whether the spring is on."""
    from apexseal.cli_common import describe_result
    from apexseal.runtime.results.liftoff import describe_liftoff

    result, _ = held_off
    check = summarise(result)["liftoff"]
    off = tuple(g for g in result.guard_names if g != "spring")
    text = describe_liftoff(check, 1.0, off)
    assert "the spring, which is off (effects.spring = false)" in text and "spring.delta_s" not in text, text
    assert "spring preload (spring.delta_s, spring.ks)" in describe_liftoff(check, 1.0, result.guard_names)
    describe_result(replace(result, guard_names=off), summarise(result))
    line = next(x for x in capsys.readouterr().err.splitlines() if "off the housing for" in x)
    assert "effects.spring = false" in line and line.endswith("(LiftOffWarning)"), line
