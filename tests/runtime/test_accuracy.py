"""Numerical settings that cost accuracy say so: a loose rtol or atol warns, a fixed-step run notes that it controls
no error (runtime/solving/accuracy.py)."""

from __future__ import annotations

import warnings

import pytest
from click.testing import CliRunner

import apexseal
from apexseal.cli import main
from apexseal.cli_common import describe_result
from apexseal.runtime.api import settings_of
from apexseal.runtime.results.summary import summarise
from apexseal.runtime.solving.accuracy import (
    LOOSE_ATOL,
    LOOSE_RTOL,
    AccuracyWarning,
    UnusedToleranceWarning,
    accuracy,
    loose_tolerances,
)
from apexseal.runtime.solving.methods import METHODS
from apexseal.runtime.solving.settings import LIMITS, RunSettings

QUICK = dict(samples_per_revolution=36, compile_c=False)


def test_a_loose_rtol_warns_what_it_costs_through_the_api(default_scene, default_functions):
    """``apexseal.simulate(scene, rtol=1e-2)`` ran silently, though on the default scene rtol 1e-4 and looser move the
    peaks by 20-80 %: it warns before the run, naming the setting, its value and the loosest that keeps the peaks,
    and the result's summary records it."""
    with pytest.warns(AccuracyWarning, match=r"loose tolerance: solver.rtol = 0.01 and the atol that follows it "
                      r"\(peaks within 2 % need at most 1e-05\): the means .* hold, but the peaks"):
        r = apexseal.simulate(default_scene, rtol=1e-2, functions=default_functions.sx, **QUICK)
    record = summarise(r)["accuracy"]
    assert record["error_control"] is True and record["note"].startswith("loose tolerance: solver.rtol = 0.01")


def test_a_loose_rtol_in_the_scene_warns_too(default_scene, default_functions):
    """solver.rtol = 1e-4 in a scene (the same check as the API's: the run's settings)."""
    loose = default_scene.with_overrides(**{"solver.rtol": 1e-4})
    with pytest.warns(AccuracyWarning, match=r"solver.rtol = 0.0001"):
        apexseal.simulate(loose, functions=default_functions.sx, **QUICK)


def test_a_loose_atol_warns_naming_it(default_scene, default_functions):
    with pytest.warns(AccuracyWarning, match=r"solver.atol = 0.01 \(peaks within 2 % need at most 0.001, in µm"):
        apexseal.simulate(default_scene, atol=1e-2, functions=default_functions.sx, **QUICK)


def test_the_default_tolerances_are_quiet(default_scene, default_functions):
    with warnings.catch_warnings():
        warnings.simplefilter("error", AccuracyWarning)
        r = apexseal.simulate(default_scene, functions=default_functions.sx, **QUICK)
    assert summarise(r)["accuracy"] == {"error_control": True, "note": None}


def test_the_thresholds_lie_inside_the_ranges():
    """Nonsense stays an error (the ranges); a plausible but loose value between the threshold and the range's top
    warns, and the threshold itself does not."""
    assert LIMITS["rtol"][1].holds(1e-2) and LIMITS["rtol"][1].holds(LOOSE_RTOL) and not LIMITS["rtol"][1].holds(0.5)
    assert LIMITS["atol"][1].holds(LOOSE_ATOL) and LIMITS["atol"][1].holds(1.0)
    assert loose_tolerances(RunSettings(rtol=LOOSE_RTOL)) is None
    assert loose_tolerances(RunSettings(rtol=1e-6, atol=LOOSE_ATOL)) is None
    assert "solver.rtol = 0.0001 and" in loose_tolerances(RunSettings(rtol=1e-4))
    assert "solver.atol = 1 (" in loose_tolerances(RunSettings(atol=1.0))


def test_the_command_line_warns_of_a_loose_rtol(tmp_path):
    """``apexseal simulate --rtol 1e-2`` was accepted silently."""
    r = CliRunner().invoke(main, ["simulate", "--rtol", "1e-2", "-n", "1", "-q", "--no-figures", "--set",
                                  "solver.samples_per_revolution=36", "--out", str(tmp_path / "o")])
    assert r.exit_code == 0, r.output
    assert "warning: loose tolerance: solver.rtol = 0.01" in r.output
    assert r.output.count("loose tolerance") == 1  # once, with the summary (not also as Python's warning)


def test_fixed_step_methods_read_no_tolerance():
    """A fixed-step method reads neither rtol nor atol: a loose one is no warning there, and the note says why."""
    assert sorted(n for n, m in METHODS.items() if m.fixed_step) == ["collocation", "erk-rk4", "euler", "rk"]
    assert loose_tolerances(RunSettings(method="euler", rtol=1e-2)) is None
    record = accuracy(RunSettings(method="rk", steps_per_revolution=3000))
    assert record["error_control"] is False and "euler_steps_per_revolution=6000" in record["note"]
    assert "Euler" not in record["note"]  # explicit Euler's measured example is not RK4's


def test_a_tolerance_given_to_a_fixed_step_method_warns_that_it_has_no_effect(default_scene):
    """``apexseal simulate --method euler --rtol 1e-8`` (and the API's ``rtol=``) was taken silently, and the run
    controlled no error: the warning names the tolerance, the method and the step setting it reads instead. The
    scene's own rtol (every written scene.toml has one) and an adaptive method's are quiet."""
    with pytest.warns(UnusedToleranceWarning) as caught:
        settings_of(default_scene, method="euler", rtol=1e-8, atol=1e-9)
    (w,) = caught
    assert str(w.message).startswith("rtol = 1e-08 and atol = 1e-09 have no effect: method 'euler' takes fixed steps "
                                     "(solver.euler_steps_per_revolution = 200000)")
    assert w.filename == __file__  # points at the caller's line
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnusedToleranceWarning)
        settings_of(default_scene, method="erk", rtol=1e-8)
        settings_of(default_scene, method="rk")  # the scene's rtol, not given
        settings_of(default_scene, method="collocation", rtol=None)
    with pytest.warns(UnusedToleranceWarning, match="^rtol = 0.001 has no effect: method 'erk-rk4'"):
        settings_of(default_scene, method="erk-rk4", rtol=1e-3)


@pytest.mark.filterwarnings("ignore::apexseal.runtime.results.plausibility.PenetrationWarning")  # soft contacts
def test_an_euler_run_says_it_controls_no_error(soft_scene, capsys):
    """Explicit Euler completed with no accuracy note, though on the default scene its largest housing force is 1.6
    times erk's: its summary and its console lines say that it estimates no error and how to check it (erk, and
    half the step, compared with apexseal compare); an erk run says nothing."""
    euler = apexseal.simulate(soft_scene, method="euler", samples_per_revolution=360, flags="quick")
    summary = summarise(euler)
    assert summary["accuracy"]["error_control"] is False
    note = summary["accuracy"]["note"]
    assert note.startswith("method 'euler' takes fixed steps (solver.euler_steps_per_revolution = 200000) and "
                           "estimates no error")
    assert "--method erk and apexseal compare the two folders" in note
    assert "--set solver.euler_steps_per_revolution=400000" in note
    describe_result(euler, summary)
    assert f"  note: {note}" in capsys.readouterr().out
    # a run refused before its first step (its steps would amplify a contact's ringing) has no error to speak of:
    # the note said it "completes whatever its error" beside the refusal
    from dataclasses import replace

    refused = replace(euler, info={**euler.info, "refused_at_start": True})
    describe_result(refused, summary)
    assert "estimates no error" not in capsys.readouterr().out
