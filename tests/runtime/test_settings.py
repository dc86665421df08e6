"""One settings model: the same ranges and messages from the scene, the CLI and the API (runtime/solving/settings.py)."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from click.testing import CliRunner

import apexseal
from apexseal.cli import main
from apexseal.runtime.api import settings_of
from apexseal.runtime.scenes.errors import SceneError
from apexseal.runtime.solving.settings import LIMITS, RunSettings, SettingsError

# field, bad value, fragment of the message (each case of the issue)
BAD = [
    ("revolutions", -1, "1 <= n <= 100000"),
    ("revolutions", 0, "1 <= n <= 100000"),
    ("revolutions", 1e20, "expected an integer"),
    ("revolutions", 10**20, "1 <= n <= 100000"),
    ("rtol", -1.0, "1e-12 <= value <= 0.01"),
    ("rtol", 0.0, "1e-12 <= value <= 0.01"),
    ("rtol", math.nan, "nan is out of range"),
    ("event_tol", math.nan, "nan rad is out of range; allowed: 0 < value <= 1e-06 rad"),
    ("event_tol", 0.0, "0 rad is out of range; allowed: 0 < value <= 1e-06 rad"),
    ("event_tol", 1e-5, "0 < value <= 1e-06"),
    ("event_tol", -1e-9, "0 < value <= 1e-06"),
    ("samples_per_revolution", 7, "36 <= n <= 100000"),
    ("samples_per_revolution", 0, "36 <= n <= 100000"),
    ("max_events_per_revolution", -1, "1 <= n <= 1e+08"),
    ("chatter_events", 1, "2 <= n <= 1e+08"),
    ("chatter_window", 7.0, "7 rad is out of range; allowed: 0 < value <= 6.28319 rad"),  # as the scene's key says
    ("max_wall_time", math.inf, "inf s is out of range; allowed: 0 < value <= 1e+07 s"),
    ("max_wall_time", "10 m", 'wrong unit: expected a time in s (e.g. "600 s"), got m ([length]); allowed: 0 < value'),
    ("max_wall_time", "-1 s", "-1 s is out of range; allowed: 0 < value <= 1e+07 s"),
    ("method", "rk45", "not a method"),
    ("flags", "fast", "not allowed"),
    ("compile", "fast", "not allowed"),  # the scene's names are the API's too
    ("interpreted", "no", "expected true or false"),
    ("euler_steps_per_revolution", 0, "1 <= n <= 1e+09"),
]


@pytest.mark.parametrize("field,value,fragment", BAD, ids=[f"{f}={v}" for f, v, _ in BAD])
def test_api_refuses_bad_settings_naming_field_value_and_range(default_scene, field, value, fragment):
    with pytest.raises(SettingsError) as err:
        apexseal.simulate(default_scene, **{field: value})  # refused before anything is built
    assert err.value.keys() == [field]
    line = str(err.value).splitlines()[1]
    assert line.strip().startswith(f"{field} = ") and fragment in line, line


def test_a_setting_with_a_unit_takes_a_quantity_as_the_scene_does():
    """`simulate(max_wall_time="10 s")` was refused ("expected a number") where the scene, the command line and
    --set take "600 s"."""
    st = RunSettings(max_wall_time="2 min", event_tol="1e-9 rad", chatter_window="0.1 deg")
    assert (st.max_wall_time, st.event_tol) == (120.0, 1e-9) and st.chatter_window == pytest.approx(math.radians(0.1))


def test_unknown_setting_is_named_with_a_suggestion():
    with pytest.raises(SettingsError, match=r"rtl = 1e-06: unknown setting \(did you mean 'rtol'\?\)"):
        RunSettings(rtl=1e-6)


def test_the_api_takes_the_scene_s_names_of_settings(default_scene):
    """``solver.compile``, ``solver.interpreted`` and ``solver.euler_steps_per_revolution`` are the fields
    ``flags``, ``compile_c`` (negated) and ``steps_per_revolution``; either name sets them, and the scene's value
    of the one is replaced by an override under the other."""
    scene = default_scene.with_overrides(**{"solver.interpreted": True, "solver.compile": "quick"})
    st = settings_of(scene, compile="optimised", interpreted=False, euler_steps_per_revolution=1000)
    assert (st.flags, st.compile_c, st.steps_per_revolution) == ("optimised", True, 1000)
    assert settings_of(scene).compile_c is False and settings_of(scene, compile_c=True).compile_c is True
    assert RunSettings(interpreted=True).replace(compile="quick") == RunSettings(compile_c=False, flags="quick")
    with pytest.raises(SettingsError, match=r"interpreted = true: the scene's name of the setting compile_c, also "
                                            r"given \(compile_c = True\): give one of the two"):
        RunSettings(interpreted=True, compile_c=True)
    with pytest.raises(SettingsError, match=r"interpretd = true: unknown setting \(did you mean 'interpreted'\?\)"):
        RunSettings(interpretd=True)
    with pytest.raises(SettingsError) as err:  # every problem at once, a scene name's among them
        RunSettings(interpreted="no", rtol=-1, compile="fast")
    assert err.value.keys() == ["interpreted", "rtol", "compile"]


def test_every_problem_is_reported_at_once():
    with pytest.raises(SettingsError) as err:
        RunSettings(rtol=-1, samples_per_revolution=7, revolutions=0)
    assert sorted(err.value.keys()) == ["revolutions", "rtol", "samples_per_revolution"]


def test_the_same_range_in_scene_cli_and_api(default_scene, tmp_path):
    """rtol = 0.5: the scene, the CLI and the API print the same allowed range."""
    text = "1e-12 <= value <= 0.01"
    with pytest.raises(SettingsError, match=text):
        settings_of(default_scene, rtol=0.5)
    with pytest.raises(SceneError, match=text):
        default_scene.with_overrides(**{"solver.rtol": 0.5})
    for value in ("0.5", "nan"):
        r = CliRunner().invoke(main, ["simulate", "--rtol", value, "--out", str(tmp_path / "o")])
        assert r.exit_code == 2 and "--rtol" in r.output and text in r.output, r.output
    assert not (tmp_path / "o").exists()


def test_cli_refuses_1e20_revolutions(tmp_path):
    r = CliRunner().invoke(main, ["simulate", "-n", "100000000000000000000", "--out", str(tmp_path / "o")])
    assert r.exit_code == 2 and "--revolutions" in r.output and "1 <= n <= 100000" in r.output


@pytest.mark.parametrize("args, shown", [(["-n", "-1"], "-1 is out of range"), (["--rtol", "2"], "2 is out of range")])
def test_cli_names_the_bad_value(tmp_path, args, shown):
    """The command line's error names the option, the value and the range, for integers as for numbers."""
    r = CliRunner().invoke(main, ["simulate", *args, "--out", str(tmp_path / "o")])
    assert r.exit_code == 2 and shown in r.output and "allowed:" in r.output


def test_scene_refuses_1e20_revolutions(default_scene):
    with pytest.raises(SceneError, match="operation.revolutions.*1 <= n <= 100000"):
        default_scene.with_overrides(**{"operation.revolutions": 10**20})


def test_scene_bounds_come_from_the_settings_table():
    from apexseal.runtime.scenes.schema import OperationSection, SolverSection, validator_of

    assert validator_of(SolverSection, "rtol").range == LIMITS["rtol"][1]
    assert validator_of(SolverSection, "samples_per_revolution").range == LIMITS["samples_per_revolution"][1]
    assert validator_of(OperationSection, "revolutions").range == LIMITS["revolutions"][1]


def test_simulate_accepts_a_path_and_names_a_wrong_type(tmp_path):
    with pytest.raises(TypeError, match="expected a Scene .* not int"):
        apexseal.simulate(42)
    with pytest.raises(SceneError, match="x.toml"):
        apexseal.simulate(str(tmp_path / "x.toml"))


@pytest.mark.parametrize("call, error, fragment", [
    (lambda sc, r: apexseal.load_scene(123), TypeError, "path = 123: expected the path of a scene file"),
    (lambda sc, r: apexseal.simulate(sc, out=123), TypeError, "out = 123: expected a folder"),
    (lambda sc, r: apexseal.Model(None), TypeError, "scene: expected a Scene"),
    (lambda sc, r: apexseal.Model(sc).pressures(math.nan), ValueError, "theta = nan: expected a finite crank angle"),
    (lambda sc, r: apexseal.compare(str(r)), TypeError, "a list of at least two results"),  # not its characters
    (lambda sc, r: apexseal.resume(r, revolutions=-5), SettingsError, "-5 is out of range; allowed: 1 <= n"),
    (lambda sc, r: apexseal.resume(r, revolutions=0), SettingsError, "0 is out of range; allowed: 1 <= n"),
    (lambda sc, r: apexseal.plot_comparison([r], []), ValueError, "name at least one quantity"),
    # a path no file system holds: os said only "embedded null byte", naming no argument
    (lambda sc, r: apexseal.load_scene("a\0b.toml"), ValueError, "path = 'a\\x00b.toml': a path cannot contain a NUL"),
    (lambda sc, r: apexseal.simulate(sc, out="o\0"), ValueError, "out = 'o\\x00': a path cannot contain a NUL"),
    (lambda sc, r: apexseal.resume("r\0"), ValueError, "folder = 'r\\x00': a path cannot contain a NUL"),
    (lambda sc, r: apexseal.resume(5), TypeError, "folder = 5: expected a result folder"),
    # taken silently before ("no" even turned the report on)
    (lambda sc, r: apexseal.simulate(sc, progress="yes"), SettingsError, 'progress = "yes": must be True or False'),
    (lambda sc, r: apexseal.simulate(sc, progress=print), SettingsError, "a callback is not taken"),
])
def test_the_api_names_an_argument_of_the_wrong_kind(default_scene, default_functions, tmp_path, call, error,
                                                      fragment):
    """Each gave an AttributeError, a bare pathlib TypeError, a plot of characters or a message without the range."""
    folder = tmp_path / "r"
    apexseal.simulate(default_scene, functions=default_functions.sx, samples_per_revolution=36, compile_c=False,
                      out=folder)
    with pytest.raises(error, match=re.escape(fragment)):
        call(default_scene, folder)


def test_plot_comparison_takes_folders_and_one_quantity_by_name(default_scene, default_functions, tmp_path):
    folder = tmp_path / "r"
    apexseal.simulate(default_scene, functions=default_functions.sx, samples_per_revolution=36, compile_c=False,
                      out=folder)
    fig = apexseal.plot_comparison([folder, str(folder)], "phi")  # was: three panels, 'p', 'h' and 'i'
    assert len(fig.axes) == 1 and len(fig.axes[0].lines) == 2


@pytest.mark.parametrize("state,fragment", [
    (0.0, "shape ()"), ([1e-6], "shape (1,)"), (None, "got shape ()"), (np.zeros((6, 2)), "shape (6, 2)"),
    ([0, 0, 0, 0, 0, math.nan], "not finite in phid"), ("abc", "expected 6 numbers"),
])
def test_model_rhs_validates_the_state(default_scene, default_functions, state, fragment):
    model = apexseal.Model(default_scene, functions=default_functions.sx)
    with pytest.raises(ValueError) as err:
        model.rhs(0.4, state)
    assert fragment in str(err.value)


def test_model_rhs_validates_theta(default_scene, default_functions):
    model = apexseal.Model(default_scene, functions=default_functions.sx)
    with pytest.raises(ValueError, match="theta"):
        model.rhs(math.nan, np.zeros(6))


def test_interpreted_through_the_api_runs_the_interpreted_functions(default_scene, monkeypatch):
    """``simulate(scene, interpreted=True, compile="quick")`` loads the model as ``solver.interpreted = true``
    and ``solver.compile = "quick"`` do (it was loaded from the scene as given, compiled, while its saved scene
    said interpreted)."""
    import apexseal.generated.load as load

    asked, real = [], load.load_functions

    def spy(*args, **kwargs):
        asked.append((kwargs.get("compiled"), kwargs.get("flags")))
        return real(*args, **kwargs)

    monkeypatch.setattr(load, "load_functions", spy)
    r = apexseal.simulate(default_scene, interpreted=True, compile="quick", samples_per_revolution=36,
                          method="rk", steps_per_revolution=3600)
    assert asked == [(False, "quick")] and r.info["compiled"] is False and r.scene.solver.interpreted is True


@pytest.mark.filterwarnings("ignore::apexseal.runtime.solving.accuracy.AccuracyWarning")  # atol 1e-2: loose
def test_the_absolute_tolerance_and_the_chamber_pressures_reach_the_run(default_scene, default_functions):
    """solver.atol is the integrator's abstol (it was rtol whatever the scene said, and no test noticed), and the
    result's Pa and Pb columns are chamber a's and chamber b's (a swap of the two went unnoticed too)."""
    scene = default_scene.with_overrides(pressure={"source": "constant", "Pa": "6 bar", "Pb": "1 bar"})
    kw = dict(functions=default_functions.sx, samples_per_revolution=36, compile_c=False, revolutions=1)
    tight = apexseal.simulate(scene, rtol=1e-6, **kw)
    loose = apexseal.simulate(scene, rtol=1e-6, atol=1e-2, **kw)
    assert tight.status == loose.status == "completed"
    assert np.abs(tight.state - loose.state).max() > 0  # another step sequence: the atol was used
    assert np.all(tight.outputs["Pa"] == 6e5) and np.all(tight.outputs["Pb"] == 1e5)


def test_resume_takes_progress_as_simulate_does(tmp_path):
    """resume(progress="no") turned the report on, where simulate refuses it."""
    with pytest.raises(SettingsError, match="progress"):
        apexseal.resume(tmp_path, progress="no")


def test_model_rhs_takes_a_column_vector_as_casadi_gives_it(default_scene, default_functions):
    """Model.rhs refused the (6, 1) column CasADi hands back (`got shape (6, 1)`): a column or row is the state."""
    model = apexseal.Model(default_scene, functions=default_functions.sx)
    flat = model.rhs(0.4, np.zeros(6))
    assert np.array_equal(model.rhs(0.4, np.zeros((6, 1))), flat)
    assert np.array_equal(model.rhs(0.4, np.zeros((1, 6))), flat)
