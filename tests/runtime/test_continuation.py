"""A stopped run continues after its last whole revolution, to the samples of a run never stopped
(runtime/results/continuation.py, ``apexseal simulate --resume``, :func:`apexseal.resume`)."""

from __future__ import annotations

import json
import types
import warnings

import numpy as np
import pytest
from click.testing import CliRunner
from test_faults import SCENES_DIR, _start, _wait_for_parts, slow_scene  # noqa: F401  (a fixture)

import apexseal
from apexseal.cli import main
from apexseal.runtime.api import same_model
from apexseal.runtime.results.continuation import continuation
from apexseal.runtime.results.folder import ResultFolderError
from apexseal.runtime.results.result import SimulationResult


def _same_samples(a: SimulationResult, b: SimulationResult) -> None:
    assert a.n == b.n
    assert np.array_equal(a.theta, b.theta) and np.array_equal(a.state, b.state)
    assert np.array_equal(a.closed, b.closed) and np.array_equal(a.events, b.events) and a.modes == b.modes
    assert a.outputs.keys() == b.outputs.keys()
    assert all(np.array_equal(a.outputs[k], b.outputs[k]) for k in a.outputs)


@pytest.fixture(scope="module")
def light(tmp_path_factory):
    """The default scene at 1° samples, and a 3-revolution run of it never stopped."""
    scene = apexseal.load_scene().with_overrides(**{"solver.samples_per_revolution": 360})
    return scene, apexseal.simulate(scene, revolutions=3, out=tmp_path_factory.mktemp("whole") / "o")


def test_a_finished_run_given_more_revolutions_on_the_command_line(light, tmp_path):
    scene, whole = light
    out = tmp_path / "b"
    first = apexseal.simulate(scene, revolutions=1, out=out)
    r = CliRunner().invoke(main, ["simulate", "--resume", str(out), "-n", "3", "-q", "--no-figures"])
    assert r.exit_code == 0, r.output
    assert f"continuing {out} after 1 revolution(s), up to 3" in r.output
    continued = SimulationResult.load(out)
    _same_samples(continued, whole)
    assert continued.status == "completed" and continued.revolutions == 3
    assert continued.info["run_id"] == first.info["run_id"]  # one run, written as one unit
    assert continued.info["scene"] == first.info["scene"]
    (before,) = continued.info["continued"]
    assert before["after_revolutions"] == 1 and before["status"] == "completed"
    assert before["solver_stats"]["n_engine_calls"] == 1 and continued.info["solver_stats"]["n_engine_calls"] == 2
    assert continued.scene.operation.revolutions == 3  # its scene.toml re-runs the whole of it
    assert json.loads((out / "summary.json").read_text())["scene"]["source"] == first.info["scene"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["b"]
    # the wall time said is the last run's, and the whole run's beside it (it said only the last part's)
    total = continued.info["wall_time_s"] + before["wall_time_s"]
    assert f"wall {continued.info['wall_time_s']:.2f} s (its last run; {total:.2f} s in all, 2 runs)" in r.output
    shown = CliRunner().invoke(main, ["show", str(out)])
    assert f"(its last run; {total:.2f} s in all, 2 runs)" in shown.output, shown.output


def test_a_resumed_run_writes_the_trajectory_csv_its_run_asked_for(light, tmp_path):
    """A run written with --csv, stopped and continued with the command it printed (`apexseal simulate --resume
    <folder>`, no --csv): the continued folder lost trajectory.csv (the stopped run's was removed as stale and not
    written again). It is written again, whole, for the continued run; a run without --csv still gets none."""
    scene, whole = light
    args = ["--set", "solver.samples_per_revolution=360", "-q", "--no-figures"]
    for name, csv in (("with", ["--csv"]), ("without", [])):
        out = tmp_path / name
        r = CliRunner().invoke(main, ["simulate", "-n", "1", "-o", str(out), *csv, *args])
        assert r.exit_code == 0, r.output
        assert (out / "trajectory.csv").is_file() == bool(csv)
        r = CliRunner().invoke(main, ["simulate", "--resume", str(out), "-n", "3", "-q", "--no-figures"])
        assert r.exit_code == 0, r.output
        assert (out / "trajectory.csv").is_file() == bool(csv), r.output
    continued = SimulationResult.load(tmp_path / "with")  # checks that the csv names its run
    _same_samples(continued, whole)
    lines = (tmp_path / "with" / "trajectory.csv").read_text().splitlines()
    assert lines[0] == f"# apexseal result {continued.info['run_id']}, {whole.n} samples"
    assert len(lines) == 2 + whole.n
    assert np.allclose([float(row.split(",")[2]) for row in lines[2:]], whole.state[0], rtol=1e-9, atol=0)


def test_a_folder_read_once_gives_the_same_continuation(light, tmp_path):
    """`apexseal show` hands continuation() the result it read: the same revolutions, last sample and state as
    continuation() reading the parts itself."""
    scene, _ = light
    folder = tmp_path / "o"
    whole = apexseal.simulate(scene, revolutions=2, out=folder)
    own, given = continuation(folder), continuation(folder, SimulationResult.load(folder))
    assert own.revolutions == given.revolutions == 2
    assert own.last == given.last == (float(whole.theta[-1]), whole.modes[-1])
    assert np.array_equal(own.z, given.z)


def test_a_killed_run_continues_in_its_partial_folder(slow_scene, tmp_path):  # noqa: F811
    """SIGKILL after three revolutions: the OUT.partial-<run id> folder continues (a revolution in progress, or
    one whose part was being written, is computed again) into OUT, with the samples of the run never stopped."""
    out = tmp_path / "o"
    proc = _start(slow_scene, out)
    staging = _wait_for_parts(out, proc, 3)
    with pytest.raises(ResultFolderError, match="being written by a running process"):
        apexseal.resume(staging)  # its parts are not touched while the run writes them
    proc.kill()
    proc.communicate(timeout=30)  # reaps it and closes its pipes
    shown = CliRunner().invoke(main, ["show", str(staging)])
    assert shown.exit_code == 0 and "interrupted" in shown.output, shown.output
    assert f"whole revolution(s): apexseal simulate --resume {staging}" in shown.output
    killed = continuation(staging)
    shown_from = continuation(staging, SimulationResult.load(staging))  # as `apexseal show` asks, parts read once
    assert (shown_from.revolutions, shown_from.last) == (killed.revolutions, killed.last)
    assert np.array_equal(shown_from.z, killed.z)
    # the third part's file may be written without the record that lists it yet: then it is computed again
    assert killed.target == out and killed.revolutions >= 2 and killed.in_place
    continued = apexseal.resume(staging, revolutions=killed.revolutions + 1)
    assert not staging.exists() and SimulationResult.load(out).n == continued.n
    scene = apexseal.load_scene(slow_scene)
    _same_samples(continued, apexseal.simulate(scene, revolutions=killed.revolutions + 1))
    assert continued.info["continued"][0]["status"] == "interrupted"


def test_a_killed_run_resumed_after_another_run_wrote_its_target_keeps_that_result(slow_scene, light, tmp_path):  # noqa: F811
    """A run killed, another run completed at the same --out, then the killed one resumed: the continuation
    replaced the other run's completed result without a word (it took the run at the target when the continuation
    began, not when the run began). Now the other result stays, and the continued run is kept aside in its folder."""
    from apexseal.runtime.results.folder import KeptAsideWarning

    out = tmp_path / "o"
    proc = _start(slow_scene, out)
    staging = _wait_for_parts(out, proc, 2)
    proc.kill()
    proc.communicate(timeout=30)
    other = apexseal.simulate(light[0], revolutions=1, out=out)
    killed = continuation(staging)
    with pytest.warns(KeptAsideWarning, match=rf"another run \({other.info['run_id'][:12]}\) wrote {out}"):
        continued = apexseal.resume(staging, revolutions=killed.revolutions + 1)
    assert SimulationResult.load(out).info["run_id"] == other.info["run_id"]
    assert SimulationResult.load(staging).n == continued.n and continued.status == "completed"


def test_what_cannot_be_continued_is_refused_with_the_reason(light, tmp_path):
    scene, _ = light
    done = tmp_path / "done"
    apexseal.simulate(scene, revolutions=1, out=done)
    with pytest.raises(ResultFolderError, match="holds 1 whole revolution\\(s\\), as many as asked \\(1\\): give "
                                                "at least 2 revolutions to continue it"):
        apexseal.resume(done)
    two = tmp_path / "two"
    apexseal.simulate(scene, revolutions=2, out=two)
    with pytest.raises(ResultFolderError) as info:  # fewer than it holds: it said "as many as asked (1)"
        apexseal.resume(two, revolutions=1)
    assert str(info.value).endswith("holds 2 whole revolution(s), more than the 1 asked: give at least 3 "
                                    "revolutions to continue it")
    saved = tmp_path / "saved"
    apexseal.simulate(scene, revolutions=2).save(saved)  # one part of two revolutions
    with pytest.raises(ResultFolderError, match="do not hold the integrator's state"):
        apexseal.resume(saved, revolutions=3)
    (tmp_path / "empty").mkdir()
    with pytest.raises(ResultFolderError, match="no result.json"):
        apexseal.resume(tmp_path / "empty")
    failed = tmp_path / "failed"
    hard = apexseal.load_scene(SCENES_DIR / "hard" / "stiff-housing-1e10.toml")
    assert apexseal.simulate(hard, method="euler", out=failed).status == "failed"
    with pytest.raises(ResultFolderError, match="no whole revolution"):
        apexseal.resume(failed)
    text = (done / "scene.toml").read_text()
    (done / "scene.toml").write_text(text.replace('ks = "5000.0 N/m"', 'ks = "7000.0 N/m"'))
    from apexseal.runtime.results.reading import SceneChangedWarning

    with pytest.warns(SceneChangedWarning, match="is not the scene the run computed"):  # it loaded without a word
        assert apexseal.SimulationResult.load(done).scene.spring.ks == 7000.0
    with pytest.raises(ResultFolderError, match="is not the scene the run computed") as err:
        apexseal.resume(done, revolutions=2)
    assert "edited since, or written by an earlier apexseal whose hash counted the pressure table's unit?)" in \
        str(err.value)  # no submodels installed: not named
    from apexseal.derive.submodels import registry

    with pytest.MonkeyPatch.context() as mp:  # a package of submodels installed since: a cause too
        mp.setattr(registry, "installed", lambda: {"film": "my-seal-models 0.2"})
        with pytest.raises(ResultFolderError, match="or read with other submodels installed now: film from "
                                                    "my-seal-models 0.2"):
            apexseal.resume(done, revolutions=2)
        from apexseal.generated import manifest

        # a submodel changed since the run (a key added, a default changed): that is the cause to name, not an edit
        mp.setattr(manifest, "input_hash", lambda *a: "f" * 64)
        with pytest.raises(ResultFolderError, match=r"edited since, or the model changed since the run, model hash "
                                                    r"[0-9a-f]{12}, now ffffffffffff: the derivation, a submodel"):
            apexseal.resume(done, revolutions=2)
    # a range narrowed since the run (here: a value the ranges refuse): the samples stay readable, without the scene
    (done / "scene.toml").write_text(text.replace('ks = "5000.0 N/m"', 'ks = "-5 N/m"'))
    with pytest.warns(SceneChangedWarning, match=r"(?s)scene.toml does not load here.*spring.ks = \"-5 N/m\".*"
                                                 r"result.scene is None: the samples are read without their scene"):
        unscened = apexseal.SimulationResult.load(done)
    assert unscened.scene is None and unscened.n > 1 and np.isfinite(unscened.state).all()
    with pytest.raises(ResultFolderError, match="does not load here"):  # a continuation needs its scene
        apexseal.resume(done, revolutions=2)
    (done / "scene.toml").write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("error", SceneChangedWarning)
        apexseal.SimulationResult.load(done)  # the scene that ran: no warning
    other = types.SimpleNamespace(model_hash="0" * 64)
    with pytest.raises(ResultFolderError, match="another model"):
        same_model(continuation(done), other)
    table = done / "pressure.csv"  # an edited table was blamed on scene.toml, whose hash counts its content
    table.write_text(table.read_text().replace("\n", "\n#\n", 1))
    with pytest.raises(ResultFolderError, match=r"pressure.csv is not the file result.json recorded"):
        apexseal.resume(done, revolutions=2)


def test_the_command_line_refuses_to_change_what_ran(tmp_path, light):
    scene, _ = light
    out = tmp_path / "o"
    apexseal.simulate(scene, revolutions=1, out=out)
    r = CliRunner().invoke(main, ["simulate", "--resume", str(out), "-n", "2", "--method", "rk"])
    assert r.exit_code == 2 and "--method cannot change them" in r.output
    r = CliRunner().invoke(main, ["simulate", "--resume", str(out)])
    assert r.exit_code == 2 and "Invalid value for --resume" in r.output and "give at least 2 revolutions" in r.output
    assert SimulationResult.load(out).n == 361  # untouched


@pytest.mark.slow
def test_a_model_with_states_of_its_own_continues_to_the_same_samples(tmp_path):
    """The chamber gas model integrates the chambers' gas with the seal: its states continue as the seal's do. Slow
    (36 s of one test process in a suite run on a loaded machine, --durations: four revolutions of the gas model):
    the default suite keeps its ten-minute budget on two cores; the seal's own continuation is tested above."""
    from apexseal.runtime.scenes.scene import embedded_scene_path

    scene = apexseal.load_scene(embedded_scene_path("expander-gas.toml"))
    scene = scene.with_overrides(**{"solver.samples_per_revolution": 360})
    whole = apexseal.simulate(scene, revolutions=2)
    apexseal.simulate(scene, revolutions=1, out=tmp_path / "o")
    continued = apexseal.resume(tmp_path / "o", revolutions=2)
    assert continued.state.shape[0] > 6  # the gas states
    _same_samples(continued, whole)


def test_a_run_killed_before_its_first_revolution_is_named_as_such(light, tmp_path):
    """A run killed while it wrote its first part leaves scene.toml (written before the first step) and no
    result.json: show and --resume called it "not a result folder", with nothing said of the run."""
    scene, _ = light
    done = tmp_path / "done"
    apexseal.simulate(scene, revolutions=1, out=done)
    killed = tmp_path / "killed.partial-0123"
    killed.mkdir()
    (killed / "scene.toml").write_text((done / "scene.toml").read_text())
    run_id = json.loads((done / "result.json").read_text())["info"]["run_id"]
    for args in (["show", str(killed)], ["simulate", "--resume", str(killed), "-q", "--no-figures"]):
        r = CliRunner().invoke(main, args)
        assert r.exit_code != 0 and f"run {run_id} began here and was killed before it wrote its first " \
            "revolution" in r.output, r.output
    (killed / "scene.toml").write_text("[machine]\n")  # a scene file of a user's: no run named
    r = CliRunner().invoke(main, ["show", str(killed)])
    assert r.exit_code != 0 and "is not a result folder: it has no result.json" in r.output
    # killed before even its scene.toml: an empty parts/ in a run's folder ("not a result folder", no hint)
    empty = tmp_path / "o.partial-0123456789ab"
    (empty / "parts").mkdir(parents=True)
    r = CliRunner().invoke(main, ["show", str(empty)])
    assert r.exit_code != 0 and "a run was killed here before it wrote anything (an empty parts/)" in r.output
    assert "delete this folder" in r.output


@pytest.fixture(scope="module")
def composite_scene():
    """The default scene with the composite method at 10° samples: its quiet phase starts from the crank angle
    since the last contact event, which a call carries over from the call before."""
    return apexseal.load_scene().with_overrides(**{"solver.method": "composite", "solver.samples_per_revolution": 36})


@pytest.mark.parametrize("calls", [1, 4])
def test_a_composite_run_continues_to_the_same_samples(composite_scene, tmp_path, calls):
    """The composite carries the crank angle since the last contact event from call to call: the part stores it
    (``carried``), so the continued run's first call is the uninterrupted run's (a new engine counted from 0, and the
    states differed from the first sample after the resume point); in one call per revolution and in four."""
    scene = composite_scene.with_overrides(**{"solver.calls_per_revolution": calls})
    whole = apexseal.simulate(scene, revolutions=3)
    assert whole.info["calls_per_revolution"] == calls
    apexseal.simulate(scene, revolutions=1, out=tmp_path / "o")
    with np.load(tmp_path / "o" / "parts" / "part-00000.npz") as part:
        assert part["carried"].shape == (1,) and part["carried"][0] >= 0.0
    _same_samples(apexseal.resume(tmp_path / "o", revolutions=3), whole)


def test_a_composite_folder_without_what_it_carried_continues_as_before(composite_scene, tmp_path):
    """A folder written before parts stored ``carried`` loads and continues with nothing carried: the first call
    after the resume point begins in the tight phase, so the samples from there differ from the run never stopped."""
    import hashlib
    import io

    whole = apexseal.simulate(composite_scene, revolutions=2)
    out = tmp_path / "o"
    apexseal.simulate(composite_scene, revolutions=1, out=out)
    record = json.loads((out / "result.json").read_text())
    (entry,) = record["parts"]
    with np.load(out / entry["file"]) as part:
        arrays = {k: part[k] for k in part.files if k != "carried"}
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    (out / entry["file"]).write_bytes(buf.getvalue())
    entry["sha256"] = hashlib.sha256(buf.getvalue()).hexdigest()
    (out / "result.json").write_text(json.dumps(record))
    assert continuation(out).carried is None
    continued = apexseal.resume(out, revolutions=2)
    assert continued.status == "completed" and np.array_equal(continued.theta, whole.theta)
    first = 1 + 36  # the initial sample and the first revolution: read back as written
    assert np.array_equal(continued.state[:, :first], whole.state[:, :first])
    assert not np.array_equal(continued.state[:, first:], whole.state[:, first:])


def test_a_resumed_run_records_the_cost_of_the_revolutions_it_has_left(light, tmp_path):
    """The cost estimate of a resumed run (said as a SlowRunWarning on a slow rotor, recorded in result.json)
    counted every revolution asked for, also those already run: 1 of 3 done, 2 are left."""
    scene, whole = light
    apexseal.simulate(scene, revolutions=1, out=tmp_path / "b")
    continued = apexseal.resume(tmp_path / "b", revolutions=3)
    assert continued.info["cost_estimate"]["seconds"] == pytest.approx(
        whole.info["cost_estimate"]["seconds"] * 2 / 3, rel=1e-12)
