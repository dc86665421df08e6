"""The command line end to end: simulate the default scene, derive, bad input."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from apexseal.cli import main
from apexseal.runtime.results.result import SimulationResult


def test_simulate_default_scene_end_to_end(tmp_path):
    out = tmp_path / "run"
    r = CliRunner().invoke(main, ["simulate", "--revolutions", "1", "-o", str(out), "--quiet", "--csv"])
    assert r.exit_code == 0, r.output
    for name in ("trajectory.csv", "parts/part-00000.npz", "result.json", "summary.json", "scene.toml",
                 "pressure.csv", "fig12_displacements.png", "fig13_forces.png", "fig14_housing_spectrum.png",
                 "mode_timeline.png"):
        assert (out / name).stat().st_size > 0, name
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]  # written beside it, renamed into place
    assert "apexseal:" not in r.output  # -q: no progress lines
    assert "Event support is experimental" not in r.output

    # the saved scene re-runs the result to the same numbers
    again = tmp_path / "again"
    r2 = CliRunner().invoke(main, ["simulate", str(out / "scene.toml"), "--out", str(again), "--quiet", "--no-figures"])
    assert r2.exit_code == 0, r2.output
    a, b = SimulationResult.load(out), SimulationResult.load(again)
    assert np.array_equal(a.state, b.state) and np.array_equal(a.events, b.events)
    assert a.info["scene_hash"] == b.info["scene_hash"] == b.scene.content_hash()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["run_id"] == json.loads((out / "result.json").read_text())["run_id"]
    assert summary["status"] == "completed"
    assert summary["run"]["method"] == "erk"
    assert summary["events_total"] > 0
    assert set(summary["extremes"]) == {"x", "y", "phi"}
    assert "wrote" in r.output and str(out) in r.output


def test_a_run_with_a_wall_time_budget_writes_a_scene_that_re_runs_it_without_the_budget(tmp_path):
    """A budget cuts each revolution into 36 integrator calls (checked between them), and each call starts the
    integrator afresh, which moves the numbers within the tolerance: the result's scene.toml records the calls, so
    that re-running it without the budget gives the same numbers (before, it re-ran one call per revolution)."""
    out, again = tmp_path / "budget", tmp_path / "again"
    r = CliRunner().invoke(main, ["simulate", "--max-wall-time", "600", "--out", str(out), "-q", "--no-figures"])
    assert r.exit_code == 0, r.output
    a = SimulationResult.load(out)
    assert a.info["calls_per_revolution"] == 36 and a.scene.solver.calls_per_revolution == 36
    assert "calls_per_revolution = 36" in (out / "scene.toml").read_text()
    r2 = CliRunner().invoke(main, ["simulate", str(out / "scene.toml"), "--out", str(again), "-q", "--no-figures"])
    assert r2.exit_code == 0, r2.output
    b = SimulationResult.load(again)
    assert b.info["calls_per_revolution"] == 36
    assert np.array_equal(a.state, b.state) and np.array_equal(a.events, b.events)


def test_a_bad_wall_time_budget_is_reported_against_its_option(tmp_path):
    r = CliRunner().invoke(main, ["simulate", "--max-wall-time", "0", "--out", str(tmp_path / "o")])
    assert r.exit_code == 2
    assert "--max-wall-time: 0 s is out of range; allowed: 0 < value <= 1e+07 s" in r.output, r.output
    assert not (tmp_path / "o").exists()


def test_simulate_rejects_a_bad_scene_with_the_key_named(tmp_path):
    scene = tmp_path / "bad.toml"
    from apexseal.runtime.scenes.scene import default_scene_text

    scene.write_text(default_scene_text().replace('ks = "5e3 N/m"', 'ks = "-5e3 N/m"'))
    r = CliRunner().invoke(main, ["simulate", str(scene), "--out", str(tmp_path / "o")])
    assert r.exit_code != 0
    assert "spring.ks" in r.output and "-5e3" in r.output
    assert not (tmp_path / "o" / "summary.json").exists()


@pytest.mark.slow
def test_set_replaces_scene_keys_and_the_saved_scene_holds_them(tmp_path):
    """--set KEY=VALUE: units, booleans and words as in a scene file; the result's scene.toml re-runs it."""
    import apexseal

    out = tmp_path / "o"
    r = CliRunner().invoke(main, ["simulate", "-n", "1", "-q", "--no-figures", "--out", str(out),
                                  "--set", "spring.ks=7e3 N/m", "--set", "effects.groove_friction=false",
                                  "--set", "solver.samples_per_revolution=360"])
    assert r.exit_code == 0, r.output
    assert "with spring.ks=7e3 N/m, effects.groove_friction=false, solver.samples_per_revolution=360;" in r.output
    saved = apexseal.load_scene(out / "scene.toml")
    assert saved.parameters["ks"] == 7e3 and not saved.effects.groove_friction
    assert saved.solver.samples_per_revolution == 360
    assert SimulationResult.load(out).theta.size == 361


@pytest.mark.parametrize(("args", "names"), [
    (["simulate", "--set", "spring.ks=5e3 kg"], ["spring.ks", "5e3 kg", "N/m"]),
    (["simulate", "--set", "spring.kss=5e3"], ["spring.kss", "did you mean 'ks'"]),
    (["optimise-preload", "--set", "solver.method=erkk"], ["solver.method", "erkk", "allowed"]),
    (["derive", "--set", "effects.spring=maybe"], ["effects.spring", "maybe", "true or false"]),
    (["scene", "--set", "spring.ks"], ["--set", "KEY=VALUE"]),
])
def test_set_refuses_a_bad_key_or_value_naming_both(args, names, tmp_path):
    writes = args[0] in ("simulate", "optimise-preload")  # the commands with an output folder
    r = CliRunner().invoke(main, [*args, "--out", str(tmp_path / "o")] if writes else args)
    assert r.exit_code != 0 and "Traceback" not in r.output
    assert all(n in r.output for n in names), r.output
    assert not (tmp_path / "o").exists()


def test_set_repairs_a_scene_file_that_would_not_load_alone(tmp_path, monkeypatch):
    """--set replaces the keys before the file is checked: it was applied to the loaded scene, so a file with a bad
    value could not be repaired from the command line (the bad value was still reported)."""
    import re

    monkeypatch.chdir(tmp_path)
    r = CliRunner().invoke(main, ["scene", "--default"])  # writes its pressure table here
    assert r.exit_code == 0
    bad = tmp_path / "bad.toml"
    bad.write_text(re.sub(r"^ks = .*$", 'ks = "-5e3 N/m"', r.stdout, flags=re.M))
    alone = CliRunner().invoke(main, ["scene", str(bad)])
    assert alone.exit_code != 0 and "spring.ks" in alone.output
    repaired = CliRunner().invoke(main, ["scene", str(bad), "--set", "spring.ks=6e3 N/m", "--resolved"])
    assert repaired.exit_code == 0, repaired.output
    assert re.search(r"^ks = \"6000(\.0)? N/m\"", repaired.output, re.M), repaired.output


def test_derive_and_generate_refuse_a_bad_scene_file_naming_the_key(tmp_path):
    scene = tmp_path / "bad.toml"
    from apexseal.runtime.scenes.scene import default_scene_text

    scene.write_text(default_scene_text().replace('ks = "5e3 N/m"', 'ks = "-5e3 N/m"'))
    for command in (["derive", str(scene)], ["generate", str(scene), "--no-compile"]):
        r = CliRunner().invoke(main, command)
        assert r.exit_code == 1 and r.exception is None or isinstance(r.exception, SystemExit), r.output
        assert "spring.ks" in r.output and "-5e3" in r.output, r.output


def test_simulate_refuses_an_unwritable_output_folder(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    r = CliRunner().invoke(main, ["simulate", "--out", str(blocker / "sub")])
    assert r.exit_code != 0
    assert "--out" in r.output and "cannot create the output folder" in r.output


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="no proc file system")
@pytest.mark.parametrize("command", [["simulate", "-n", "1"], ["sweep", "--example", "preload-map"],
                                     ["bench", "--quick"]])
def test_an_output_folder_nothing_can_be_created_in_is_refused_before_any_work(command, monkeypatch):
    """/proc passes the permission test (as root) but creates nothing: simulate started the run (compiled, said
    "writing to") and only then failed with a bare "[Errno 2]" naming no option."""
    from apexseal.runtime.bench import runner

    monkeypatch.setattr(runner, "run_benchmark", lambda *a, **k: pytest.fail("the benchmark ran before --out was checked"))
    r = CliRunner().invoke(main, [*command, "--out", "/proc/nope"])
    assert r.exit_code == 2 and "Traceback" not in r.output, r.output
    assert "Invalid value for --out: cannot create the output folder /proc/nope" in r.output, r.output
    assert "No such file or directory; allowed: a folder" in r.output and "writing to" not in r.output, r.output


def test_derive_reports_cold_and_cached_times():
    r = CliRunner().invoke(main, ["derive"])
    assert r.exit_code == 0, r.output
    assert "contact guards" in r.output and "cached call" in r.output


def test_derive_q_silences_its_progress_and_keeps_its_results():
    """The README says -q silences progress wherever a command takes it; derive had no -q ("No such option")."""
    quiet = CliRunner().invoke(main, ["derive", "-q"])
    assert quiet.exit_code == 0, quiet.output
    assert "contact guards" in quiet.output and "cached call" in quiet.output
    assert "deriving the equations of motion" not in quiet.output
    assert "deriving the equations of motion" in CliRunner().invoke(main, ["derive"]).output


def test_scene_default_writes_a_loadable_scene(tmp_path, monkeypatch):
    """The README said to copy runtime/scenes/default.toml, which a pip user does not have."""
    from apexseal.runtime.scenes.scene import default_scene_text, load_scene

    runner = CliRunner()
    (tmp_path / "work").mkdir()
    monkeypatch.chdir(tmp_path / "work")
    r = runner.invoke(main, ["scene", "--default"])
    assert r.exit_code == 0 and r.stdout == default_scene_text()
    Path("my.toml").write_text(r.stdout)
    assert load_scene("my.toml") == load_scene()  # its pressure table was written beside it
    r = runner.invoke(main, ["scene", "--default", "--out", str(tmp_path / "start")])
    assert r.exit_code == 0 and load_scene(tmp_path / "start" / "default.toml") == load_scene()
    resolved = CliRunner().invoke(main, ["scene", "--resolved"])
    assert resolved.exit_code == 0 and 'Ws = "0.003 m"' in resolved.output
    # printed, it writes nothing here and says how to get it with its table (the printed file could not load, and
    # nothing said why); --out writes both, and they load as the same scene
    assert not Path("pressure.csv").exists() and "--out FOLDER` writes the scene with it" in resolved.output
    r = runner.invoke(main, ["scene", "--resolved", "--out", str(tmp_path / "resolved")])
    assert r.exit_code == 0 and load_scene(tmp_path / "resolved" / "scene.toml") == load_scene()


@pytest.mark.slow
def test_report_commands_write_under_apexseal_out_not_docs(tmp_path, monkeypatch):
    """derive --check and bench wrote into ./docs/ of whatever folder they ran in."""
    from apexseal.commands_bench import bench

    monkeypatch.chdir(tmp_path)
    r = CliRunner().invoke(main, ["derive", "--check"])
    assert r.exit_code == 0, r.output
    assert Path("apexseal-out/paper-check.md").is_file() and not Path("docs").exists()
    # the check takes seconds: it reports its stage (it was silent between the derivation and its result)
    assert "checking every derived equation against the paper's print (sympy): done in" in r.output
    out = next(p for p in bench.params if p.name == "out")
    assert str(out.default) == "apexseal-out/bench"


def test_derive_check_of_a_scene_says_the_check_is_of_the_paper_model(tmp_path, monkeypatch):
    """`derive SCENE --check` derived SCENE's model and printed its effects, then checked the paper's full model at the
    default scene's values without saying so: a scene's effect off (or a submodel of one's own on) looked checked."""
    from types import SimpleNamespace

    import apexseal.derive.cache
    import apexseal.derive.paper_check

    monkeypatch.setattr(apexseal.derive.cache, "cached_model", lambda *a, **k: SimpleNamespace(guards=(), outputs=()))
    monkeypatch.setattr(apexseal.derive.paper_check, "main_check", lambda path, echo: 0)
    args = ["derive", "--check", "--report", str(tmp_path / "r.md")]
    r = CliRunner().invoke(main, [*args, "--set", "effects.groove_friction=false"])
    assert r.exit_code == 0, r.output
    assert ("(of the paper's full model at the default scene's values: the effects, modelling choices and values of "
            "scene (embedded default: the paper case study) with effects.groove_friction=false do not enter the "
            "check)") in r.output
    assert "full model" not in CliRunner().invoke(main, args).output  # the default scene: the model checked


def test_progress_reports_stages_with_elapsed_time(capsys):
    from apexseal import progress

    with progress.enabled(True), progress.stage("compiling something"):
        pass
    err = capsys.readouterr().err
    assert "apexseal: compiling something ..." in err and "compiling something: done in" in err
    with pytest.raises(KeyboardInterrupt), progress.enabled(True), progress.stage("deriving"):
        raise KeyboardInterrupt  # a stage left by an exception is not "done"
    err = capsys.readouterr().err
    assert "deriving: abandoned after" in err and "done in" not in err
    with progress.stage("silent"):  # no handler: nothing printed
        pass
    assert "silent" not in capsys.readouterr().err


@pytest.mark.parametrize(("args", "names"), [
    (["generate", "--no-compile", "--effects", "foo=on"], ["--effects", "effects.foo is not an effect"]),
    (["generate", "--no-compile", "--effects", "housing_contact=off,housing_friction=on"],
     ["--effects", "needs effects.housing_contact = true"]),
    (["generate", "--no-compile", "--assumptions", "damping=bogus"], ["--assumptions", "'bogus'", "allowed"]),
    (["generate", "--no-compile", "--assumptions", "foo=bar"], ["--assumptions", "not a modelling choice"]),
    (["sweep", "--example", "preload-map", "--scheduler", "foo"], ["--scheduler", "'foo'", "missing port"]),
    (["bench", "--quick", "--scenes", "bogus"], ["--scenes", "unknown scene(s) bogus",
                                                 "in the quick run (its scenes: default)"]),
    (["bench", "--quick", "--methods", "bogus"], ["--methods", "unknown method(s) bogus"]),
    # what is no number names the range too (click said only "not a valid integer"); NaN is no number (it passed
    # click's range and ended in a traceback)
    (["bench", "--quick", "--span", "nan"], ["--span", "nan is not a number", "allowed: 1<=x<=360"]),
    (["bench", "--quick", "--span", "abc"], ["--span", "'abc' is not a number", "allowed: 1<=x<=360"]),
    (["bench", "--quick", "--samples", "abc"], ["--samples", "'abc' is not an integer", "allowed: 4<=x<=100000"]),
    (["sweep", "--example", "preload-map", "-w", "abc"], ["--workers", "'abc' is not an integer", "allowed: 1<=x<="]),
    (["optimise-preload", "--nodes", "x"], ["--nodes", "nodes = 'x': must be an integer in 2..64"]),  # the API's words
    (["optimise-preload", "--max-rate", "abc"], ["--max-rate", "max_rate = 'abc': expected a length per angle"]),
    (["optimise-preload", "--max-rate", "nan"], ["--max-rate", "max_rate = 'nan': expected a length per angle"]),
    (["optimise-preload", "--max-rate", "-1"],
     ["--max-rate", "max_rate = '-1 mm/deg' (= -0.001 in SI units): must be > 0 m per degree"]),
    (["simulate", "-n", "1e20"], ["--revolutions", "'1e20' is not an integer", "allowed: 1 <= n <= 100000"]),
    (["simulate", "--rtol", "abc"], ["--rtol", "'abc' is not a number", "allowed: 1e-12 <= value <= 0.01"]),
    (["simulate", "--max-wall-time", "x"], ["--max-wall-time", "'x' is not a number", "allowed: 0 < value <= 1e+07 s"]),
    (["optimise-preload", "--max-rate", "0.05", "--out", "{tmp}/o"], ["--max-rate", "with --schedule"]),
    (["simulate", "--method", "cvode"], ["--method", "'cvode' is not allowed (did you mean 'cvodes'?)", "erk"]),
    (["scene", "--out", "{tmp}/o"], ["--out", "with --default"]),
    (["scene", "--default", "--out", "{tmp}/file/sub"], ["--out", "file is a file"]),
    (["derive", "--report", "{tmp}/r.md"], ["--report", "with --check"]),
    (["derive", "--check", "--report", "{tmp}/file/r.md"], ["--report", "file is a file"]),
])
def test_a_bad_option_is_refused_naming_it_before_any_work(args, names, tmp_path):
    """Exit code 2 (click's usage error), the option and the value named, no traceback, nothing written."""
    (tmp_path / "file").write_text("not a folder")
    r = CliRunner().invoke(main, [a.replace("{tmp}", str(tmp_path)) for a in args])
    assert r.exit_code == 2 and "Traceback" not in r.output, r.output
    assert all(n in r.output for n in names), r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]


def test_bench_refuses_an_output_folder_it_cannot_create_before_measuring(tmp_path, monkeypatch):
    """The benchmark measured for minutes (hours without --quick) and only then failed to write its report."""
    from apexseal.runtime.bench import runner

    def measured(*args, **kwargs):
        raise AssertionError("the benchmark ran before --out was checked")

    monkeypatch.setattr(runner, "run_benchmark", measured)
    (tmp_path / "file").write_text("not a folder")
    r = CliRunner().invoke(main, ["bench", "--quick", "--out", str(tmp_path / "file" / "sub")])
    assert r.exit_code == 2 and "Traceback" not in r.output, r.output
    assert "--out" in r.output and "file is a file; allowed: a folder" in r.output, r.output


def test_scene_default_never_overwrites_a_different_file(tmp_path):
    out = tmp_path / "s"
    assert CliRunner().invoke(main, ["scene", "--default", "-o", str(out)]).exit_code == 0
    assert CliRunner().invoke(main, ["scene", "--default", "-o", str(out)]).exit_code == 0  # the same files again
    table = next(out.glob("*.csv"))
    table.write_text(table.read_text() + "# mine\n")
    r = CliRunner().invoke(main, ["scene", "--default", "-o", str(out)])
    assert r.exit_code == 2 and table.name in r.output and "nothing is overwritten" in r.output, r.output
    assert table.read_text().endswith("# mine\n")


def test_a_study_s_default_folder_is_not_a_simulation_result_s(tmp_path, monkeypatch):
    """optimise-preload wrote preload.json into apexseal-out/default, a result folder, which a later simulate then
    refused to replace ("holds files that are not part of an apexseal result")."""
    from apexseal.cli_common import default_folder

    monkeypatch.chdir(tmp_path)
    assert default_folder(None, None) == Path("apexseal-out/default")
    assert default_folder(None, None, "preload") == Path("apexseal-out/default-preload")
    assert CliRunner().invoke(main, ["scene", "--default", "-o", str(tmp_path / "mine")]).exit_code == 0
    scene = Path("mine/default.toml")
    assert default_folder(scene, None, "calibration") == Path("apexseal-out/default-calibration")
    for name, folder in (("optimise-preload", "<scene name>-preload"), ("calibrate", "<scene name>-calibration")):
        assert folder in " ".join(CliRunner().invoke(main, [name, "--help"]).output.split())  # unwrapped


@pytest.mark.parametrize("module, name", [("apexseal.generated.load", "load_functions"),
                                          ("apexseal.runtime.solving.engine_pool", "lease")],
                         ids=["model", "integrator"])
def test_ctrl_c_while_the_model_or_integrator_builds_writes_nothing(tmp_path, monkeypatch, module, name):
    """A signal while the model is derived, generated or compiled, or its integrator compiled (inside the run,
    before its first step), abandons that work where it is (its caches are written atomically:
    tests/generated/test_cache_heals.py): the command stops before the run with exit code 130 and writes nothing.
    Before, the derivation (20 s for the gas model) and the compilation went on to their ends first, a signal
    during the integrator's compilation wrote a 0-revolution result, and earlier still the run started and wrote
    a 0-revolution "result" over any result at --out."""
    import importlib
    import os
    import signal

    where = importlib.import_module(module)
    real, went_on = getattr(where, name), []

    def building(*args, **kwargs):
        os.kill(os.getpid(), signal.SIGINT)  # Ctrl-C while it builds
        went_on.append(True)
        return real(*args, **kwargs)

    monkeypatch.setattr(where, name, building)
    r = CliRunner().invoke(main, ["simulate", "-n", "1", "--no-figures", "--out", str(tmp_path / "o")])
    assert r.exit_code == 130, r.output
    assert "interrupted by the user (Ctrl-C, SIGINT) before the run started: nothing written" in r.output
    assert went_on == [] and list(tmp_path.iterdir()) == []


def test_a_run_logged_to_a_file_shows_its_progress(tmp_path):
    """stderr not a terminal (a log, a batch job): the revolutions' progress is printed there too (it was shown on a
    terminal only), at most a line every LOG_INTERVAL s and the last one kept; -q prints none."""
    import subprocess

    from apexseal.cli import command

    runs = {}
    for name, extra in (("shown", []), ("quiet", ["-q"])):
        runs[name] = subprocess.run(command("simulate", "-n", "2", "--no-figures", "-o", str(tmp_path / name), *extra),
                                    capture_output=True, text=True, timeout=300)
        assert runs[name].returncode == 0, runs[name].stderr
    assert "100%" in runs["shown"].stderr and "rev/s" in runs["shown"].stderr, runs["shown"].stderr
    assert "rev/s" not in runs["quiet"].stderr
    # each redraw a line of its own: tqdm's carriage returns made the log one line of every redraw
    assert "\r" not in runs["shown"].stderr
    bars = [line for line in runs["shown"].stderr.splitlines() if "rev/s" in line]
    assert bars[-1].startswith("100%") and all(line.rstrip() == line for line in bars), bars


def test_a_signal_while_a_completed_run_is_saved_is_said_and_ends_the_process_as_asked(tmp_path, signalled_in):
    """SIGTERM while a completed run's summary is written: the result is saved whole, the run says the signal came
    after it completed, and the exit code is 128 + SIGTERM (it was 0, and nothing was said)."""
    import signal

    import apexseal.runtime.results.summary as summary

    signalled_in(summary, "summarise")
    out = tmp_path / "o"
    r = CliRunner().invoke(main, ["simulate", "-n", "1", "--out", str(out), "-q", "--no-figures"])
    assert r.exit_code == 128 + signal.SIGTERM, r.output
    assert "after the run completed: its result is whole" in r.output
    assert SimulationResult.load(out).status == "completed"


def test_a_file_given_with_set_is_taken_from_the_current_folder(tmp_path, monkeypatch):
    """`--set pressure.file=mine.csv` looked for mine.csv beside the scene (inside the package for the embedded
    default) instead of where the user typed it."""
    import shutil

    from apexseal.runtime.scenes.scene import embedded_scene_path

    shutil.copy(embedded_scene_path("expander-pressure.csv"), tmp_path / "mine.csv")
    monkeypatch.chdir(tmp_path)
    r = CliRunner().invoke(main, ["scene", "--resolved", "--set", "pressure.file=mine.csv"])
    assert r.exit_code == 0, r.output
    r = CliRunner().invoke(main, ["scene", "--resolved", "--set", "pressure.file=gone.csv"])
    assert r.exit_code != 0 and f"file not found: {tmp_path / 'gone.csv'}" in r.output


def test_a_write_protected_result_is_not_replaced(tmp_path, monkeypatch):
    """`chmod -R a-w <out>`, then `apexseal simulate --out <out>`: the run renamed the protected folder aside and
    replaced it (a rename needs only the parent's permission), leaving the old result hidden beside it. Now the
    command refuses before any work, and so does the API."""
    import os

    import apexseal
    from apexseal.runtime.results import folder
    from apexseal.runtime.results.folder import ResultFolderError

    out = tmp_path / "prot"
    first = apexseal.simulate(apexseal.load_scene(), revolutions=1, samples_per_revolution=360, out=out)
    real = os.access
    monkeypatch.setattr(folder.os, "access", lambda p, mode: False if Path(p) == out and mode == os.W_OK
                        else real(p, mode))  # what chmod a-w gives a user who is not root
    r = CliRunner().invoke(main, ["simulate", "-n", "1", "--out", str(out), "-q", "--no-figures"])
    assert r.exit_code == 2 and f"{out} is write-protected" in r.output and "make it writable" in r.output, r.output
    with pytest.raises(ResultFolderError, match="write-protected"):
        apexseal.simulate(apexseal.load_scene(), revolutions=1, out=out)
    assert apexseal.SimulationResult.load(out).info["run_id"] == first.info["run_id"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["prot"]


def test_scene_states_what_a_designer_checks_first():
    """``apexseal scene`` said only "valid": the seal's mass, the spring's preload force, the wall deflection at rest
    (Eq. 9) and the protrusion (Eq. 17) were seen only after a run. They follow the scene (preload ks delta_s), and
    the spring's force is not stated when the spring is off."""
    r = CliRunner().invoke(main, ["scene", "--set", "spring.ks=4e3 N/m", "--set", "spring.delta_s=2.5 mm"])
    assert r.exit_code == 0, r.output
    assert "derived: seal mass ms = 17.26 g, spring preload ks delta_s = 10 N" in r.output
    assert "protrusion zeta0 = 0.71 mm (given)" in r.output and "delta_w = " in r.output
    off = CliRunner().invoke(main, ["scene", "--set", "effects.spring=false"])
    assert off.exit_code == 0 and "derived: seal mass" in off.output and "preload" not in off.output



def test_a_scheduled_preload_is_stated_at_the_start_angle():
    """A scene that schedules the preload along the revolution has no one preload: the scene command states the
    start angle's (what delta_w balances at rest), and says so."""
    import apexseal
    from apexseal.commands_scene import derived_values

    scene = apexseal.load_scene().with_overrides(**{
        "spring.delta_s": None, "spring.schedule.angles": ["0 deg", "180 deg"],
        "spring.schedule.delta_s": ["3 mm", "1 mm"]})
    text = derived_values(scene)
    assert "spring preload ks delta_s = 15 N at the start angle (scheduled)" in text
    assert "preload ks delta_s = 10 N," in derived_values(apexseal.load_scene())
