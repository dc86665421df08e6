"""``apexseal show FOLDER``: a result folder checked and described, with how to continue it."""

from __future__ import annotations

import pytest
from click.testing import CliRunner

import apexseal
from apexseal.cli import main


def test_show_describes_a_result_and_how_to_continue_it(tmp_path):
    scene = apexseal.load_scene().with_overrides(**{"solver.samples_per_revolution": 360})
    done, saved = tmp_path / "done", tmp_path / "saved"
    result = apexseal.simulate(scene, revolutions=1, out=done)
    r = CliRunner().invoke(main, ["show", str(done), "--figures"])
    assert r.exit_code == 0, r.output
    assert f"run {result.info['run_id'][:12]} of scene default; method erk" in r.output
    assert "completed: 1.00 revolutions" in r.output and "friction power" in r.output
    assert "  tip off the housing: " in r.output and "warning: the seal tip" not in r.output  # brief lift-offs
    assert f"more revolutions: apexseal simulate --resume {done} -n <total>" in r.output
    assert sorted(p.name for p in done.glob("*.png")) == ["fig12_displacements.png", "fig13_forces.png",
                                                          "fig14_housing_spectrum.png", "mode_timeline.png"]
    assert apexseal.SimulationResult.load(done).n == result.n  # the figures are files a result folder may hold
    result.save(saved)
    r = CliRunner().invoke(main, ["show", str(saved)])
    assert r.exit_code == 0 and "cannot be continued: the parts of" in r.output, r.output


def test_a_seal_outside_its_groove_contacts_is_said_once_by_simulate_and_again_by_show(tmp_path):
    """Thrown inwards at 2 m/s, the seal's mouth corners reach its tip arc (Eqs. 20-23): simulate prints the margins
    and one warning (the FlankWarning of the run is not printed twice), show the same from the folder."""
    out = tmp_path / "thrown"
    args = ["simulate", "-n", "1", "--no-figures", "-q", "--out", str(out), "--set",
            "operation.initial_state.xd=-2 m/s", "--set", "solver.samples_per_revolution=360"]
    r = CliRunner().invoke(main, args)
    assert r.exit_code == 0, r.output
    said = "warning: the seal sank into its groove until a mouth corner lay on its tip arc (least l1 = -0."
    assert r.output.count(said) == 1 and "FlankWarning" not in r.output, r.output
    assert "groove mouth corners (mm): -0." in r.output
    r = CliRunner().invoke(main, ["show", str(out)])
    assert r.exit_code == 0 and r.output.count(said) == 1, r.output


def test_a_tip_off_the_housing_for_the_whole_revolution_is_said_once_by_simulate_and_again_by_show(tmp_path):
    """A constant 100 bar on one side held the seal in its groove, off the housing for the whole revolution, and
    the run's end said nothing of it: simulate prints the part of the run with the tip off and one warning (the
    LiftOffWarning of the run is not printed twice), show the same from the folder."""
    out = tmp_path / "held-off"
    args = ["simulate", "-n", "1", "--no-figures", "-q", "--out", str(out), "--set", "solver.samples_per_revolution=360"]
    for key, value in (("pressure.source", "constant"), ("pressure.Pa", "100 bar"), ("pressure.Pb", "1 bar"),
                       ("operation.initial_state.x", "-20 um")):
        args += ["--set", f"{key}={value}"]
    r = CliRunner().invoke(main, args)
    assert r.exit_code == 0, r.output
    said = "warning: the seal tip is off the housing for 100.0% of the samples of 1 revolution (longest 360°"
    assert r.output.count(said) == 1 and r.output.count("LiftOffWarning") == 1, r.output  # its tag, once
    assert "tip off the housing: 100.00% of the samples, longest 360° from 0°" in r.output
    r = CliRunner().invoke(main, ["show", str(out)])
    assert r.exit_code == 0 and r.output.count(said) == 1, r.output


def test_show_refuses_a_folder_that_is_not_a_result(tmp_path):
    r = CliRunner().invoke(main, ["show", str(tmp_path)])
    assert r.exit_code == 1 and "is not a result folder: it has no result.json" in r.output
    assert "; it is" not in r.output
    (tmp_path / "preload.md").write_text("# preload study\n")  # a study's folder says what it is, and what to read
    r = CliRunner().invoke(main, ["show", str(tmp_path)])
    assert "no result.json; it is a preload study's report (`apexseal optimise-preload`): read preload.md" in r.output


def test_show_says_a_complete_result_was_not_moved_into_place(tmp_path):
    """A completed result left in its .partial- folder (killed between its final record and the rename, or kept
    aside beside another run's result) loaded as any result, with nothing saying where it belongs."""
    from apexseal.runtime import api
    from apexseal.runtime.results.folder import ResultFolder

    scene = apexseal.load_scene().with_overrides(**{"solver.samples_per_revolution": 360})
    out = tmp_path / "o"
    first, second = ResultFolder(out), ResultFolder(out)  # two runs into one folder at once
    for sink in (first, second):
        api.run_scene(scene, api.settings_of(scene, revolutions=1), sink=sink)
    assert first.commit() == out and second.commit() == second.staging  # the first wrote out while the second ran
    r = CliRunner().invoke(main, ["show", str(second.staging)])
    assert r.exit_code == 0, r.output
    assert f"not moved into place at {out}" in r.output and f"it is complete: rename it to {out}" in r.output


def test_show_does_not_offer_to_continue_a_result_of_another_model(tmp_path):
    """show offered `--resume` for a result computed with another model (a submodel edited since), which --resume
    then refused: show now checks the model as --resume does."""
    import json

    scene = apexseal.load_scene().with_overrides(**{"solver.samples_per_revolution": 360})
    done = tmp_path / "done"
    apexseal.simulate(scene, revolutions=1, out=done)
    record = json.loads((done / "result.json").read_text())
    record["info"]["model_hash"] = "0" * 64  # what a model of other sources would have written
    (done / "result.json").write_text(json.dumps(record))
    r = CliRunner().invoke(main, ["show", str(done)])
    assert r.exit_code == 0, r.output
    assert "cannot be continued:" in r.output and "was computed with another model" in r.output
    assert "--resume" not in r.output
    r = CliRunner().invoke(main, ["simulate", "--resume", str(done), "-n", "2", "-q", "--no-figures"])
    assert r.exit_code != 0 and "was computed with another model" in r.output


def test_show_says_a_folder_still_being_written_is_not_a_killed_run(tmp_path):
    """A run's .partial- folder shown while the run writes it (its process holds the folder's lock) was said to be
    "not moved into place (the run was killed ...)" and offered to be continued."""
    from apexseal.runtime import api
    from apexseal.runtime.results.folder import ResultFolder

    scene = apexseal.load_scene().with_overrides(**{"solver.samples_per_revolution": 360})
    out = tmp_path / "o"
    sink = ResultFolder(out)
    api.run_scene(scene, api.settings_of(scene, revolutions=1), sink=sink)  # written, not yet moved into place
    r = CliRunner().invoke(main, ["show", str(sink.staging)])
    assert r.exit_code == 0, r.output
    assert "still being written by a run that is going on" in r.output
    assert "the run was killed" not in r.output and "--resume" not in r.output
    assert sink.commit() == out  # the run ends: its folder moves into place as ever


def test_a_csv_asked_for_and_not_written_is_named_and_show_writes_it(tmp_path):
    """A run asked for trajectory.csv and stopped (killed while writing it) before writing it: nothing recorded the
    request, so its folder did not say the file was missing and --resume did not write it. The request is in
    result.json from the first progress record on; show names the missing file, and show --csv writes the same
    file the run writes."""
    import json

    out = tmp_path / "o"
    r = CliRunner().invoke(main, ["simulate", "-n", "1", "--set", "solver.samples_per_revolution=360", "--csv",
                                  "--no-figures", "--quiet", "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert json.loads((out / "result.json").read_text())["info"]["files_asked"] == ["trajectory.csv"]
    written = (out / "trajectory.csv").read_bytes()
    (out / "trajectory.csv").unlink()  # as a run killed before writing it leaves its folder
    r = CliRunner().invoke(main, ["show", str(out)])
    assert r.exit_code == 0 and f"trajectory.csv asked for and not written (the run stopped before): `apexseal " \
                                f"show {out} --csv` writes it" in r.output, r.output
    r = CliRunner().invoke(main, ["show", str(out), "--csv"])
    assert r.exit_code == 0 and "wrote trajectory.csv (361 samples)" in r.output, r.output
    assert (out / "trajectory.csv").read_bytes() == written
    assert "asked for and not written" not in CliRunner().invoke(main, ["show", str(out)]).output
    (out / "trajectory.csv").unlink()  # and --resume writes it, as the run it continues was asked
    r = CliRunner().invoke(main, ["simulate", "--resume", str(out), "-n", "2", "--no-figures", "--quiet"])
    assert r.exit_code == 0 and (out / "trajectory.csv").is_file(), r.output


def test_a_run_without_figures_is_resumed_without_figures(tmp_path):
    """`simulate --no-figures`, then `--resume` with more revolutions: the continuation drew four figures, as the
    --csv request was remembered and --no-figures was not. It is recorded in result.json now."""
    import json

    out = tmp_path / "nf"
    r = CliRunner().invoke(main, ["simulate", "-n", "1", "--set", "solver.samples_per_revolution=360",
                                  "--no-figures", "--quiet", "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert json.loads((out / "result.json").read_text())["info"]["figures"] is False
    r = CliRunner().invoke(main, ["simulate", "--resume", str(out), "-n", "2", "--quiet"])
    assert r.exit_code == 0, r.output
    assert not list(out.glob("*.png")) and json.loads((out / "result.json").read_text())["info"]["figures"] is False


def test_show_into_a_folder_it_cannot_write_says_so(tmp_path, monkeypatch):
    """`apexseal show <read-only folder> --figures` (or --csv) ended in an OSError traceback."""
    import errno

    from apexseal import files

    out = tmp_path / "ro"
    r = CliRunner().invoke(main, ["simulate", "-n", "1", "--set", "solver.samples_per_revolution=360",
                                  "--no-figures", "--quiet", "--out", str(out)])
    assert r.exit_code == 0, r.output

    def read_only(*args, **kwargs):
        raise OSError(errno.EROFS, "Read-only file system")

    monkeypatch.setattr(files, "atomic_open", read_only)
    r = CliRunner().invoke(main, ["show", str(out), "--csv"])
    assert r.exit_code == 1 and "Traceback" not in r.output, r.output
    assert f"cannot write into {out}: Read-only file system" in r.output
    assert not (out / "trajectory.csv").exists()


def test_show_of_a_run_stopped_as_periodic_says_so_and_offers_no_resume(tmp_path):
    """show suggested ``--resume`` for a run that stopped because it was periodic, where more revolutions add
    nothing: it says the run stopped periodic instead."""
    out = tmp_path / "periodic"
    scene = apexseal.load_scene().with_overrides(**{
        "solver.samples_per_revolution": 72, "solver.rtol": 1e-8, "pressure.source": "none", "pressure.file": None,
        "pressure.unit": None, "effects.chamber_pressure": False, "operation.until_periodic": True,
        "operation.periodic_tol": 1e-4})
    result = apexseal.simulate(scene, revolutions=12, out=out)
    revs = result.info["periodic"]["revolution"]
    assert result.info["periodic"]["periodic"] and revs < 12
    r = CliRunner().invoke(main, ["show", str(out)])
    assert r.exit_code == 0, r.output
    assert (f"stopped because it is periodic (operation.until_periodic) after {revs} of the 12 revolution(s) asked: "
            "more revolutions add nothing") in r.output
    assert "--resume" not in r.output


def test_a_folder_a_killed_run_never_made_points_to_its_partial_folder(tmp_path):
    """apexseal.resume("killed") after a kernel was killed said "killed is not a result folder: it has no
    result.json": the run's revolutions were in killed.partial-<id>, which nothing named. A folder that does not
    exist says so, and one a killed run left beside names it, with the call that continues it."""
    from apexseal.runtime.results.folder import ResultFolderError
    from apexseal.runtime.results.result import SimulationResult

    with pytest.raises(ResultFolderError, match="does not exist"):
        SimulationResult.load(tmp_path / "nope")
    (tmp_path / "killed.partial-aa88666ba130").mkdir()
    with pytest.raises(ResultFolderError, match=r"killed does not exist: a run into it was killed and left what it "
                                                r"computed in .*killed\.partial-aa88666ba130: load or resume"):
        SimulationResult.load(tmp_path / "killed")
    with pytest.raises(ResultFolderError, match=r"apexseal\.resume\("):
        apexseal.resume(tmp_path / "killed")
    for args in (["show", str(tmp_path / "killed")], ["simulate", "--resume", str(tmp_path / "killed"), "-q"]):
        r = CliRunner().invoke(main, args)  # the command line says it too (click refused a missing folder first)
        assert r.exit_code in (1, 2) and "killed.partial-aa88666ba130: load or resume" in r.output, r.output
