"""``apexseal calibrate``'s report folder: what it identifies, that its scene.toml reruns the study and simulates the
fit, and that a calibration stopped by a signal never replaces a completed one (each study a 1-point grid: one
simulation)."""

from __future__ import annotations

import json
import os
import shlex
import signal

import pytest
from click.testing import CliRunner

import apexseal
from apexseal.cli import main
from apexseal.runtime.results.result import SimulationResult
from apexseal.runtime.studies import calibration
from apexseal.runtime.studies.calibration import features

TINY = ["--grid", "1", "--polish", "0", "-q"]
#: a scene key replaced on the command line: recorded in calibration.json, written into scene.toml
SPRING = "spring.ks=6000 N/m"


def _lines(output: str, head: str) -> str:
    (line,) = [x.strip() for x in output.splitlines() if x.strip().startswith(head)]
    return line[len(head):].strip()


@pytest.fixture(scope="module")
def completed(tmp_path_factory):
    """A completed calibration with a --set key: its folder, calibration.json and the command's output."""
    out = tmp_path_factory.mktemp("cal") / "c"
    r = CliRunner().invoke(main, ["calibrate", "--set", SPRING, *TINY, "-o", str(out)])
    assert r.exit_code == 0, r.output
    return out, json.loads((out / "calibration.json").read_text()), r.output


def test_the_report_says_what_it_calibrated_and_its_scene_simulates_the_fit(completed, tmp_path):
    """calibration.json named neither the scene nor the model nor the --set keys: two calibration folders could not
    be told apart. It records them now as a result's info does (scene, content hash, model hash, versions), with the
    run id, the status, the --set keys and the options; scene.toml beside it holds the scene with the keys
    replaced, and the simulate line printed and recorded for the best set reproduces the features fitted."""
    out, data, output = completed
    sc = apexseal.load_scene(overrides={"spring.ks": "6000 N/m"})
    assert data["status"] == "completed" and len(data["run_id"]) == 32
    assert data["scene"] == "default" and data["scene_hash"] == sc.content_hash()
    assert data["overrides"] == {"spring.ks": "6000 N/m"}
    assert data["options"] == {"grid": 1, "polish": 0, "revolutions": 2}
    assert sorted(p.name for p in out.iterdir()) == ["calibration.json", "pressure.csv", "scene.toml"]
    assert sorted(p.name for p in out.parent.iterdir()) == ["c"]  # written beside it, renamed into place
    assert data["scene_file"] == "scene.toml"
    header = (out / "scene.toml").read_text().splitlines()[0]
    assert header == f"# apexseal calibration {data['run_id']}, scene default, content hash {data['scene_hash']}"
    written = apexseal.load_scene(out / "scene.toml")
    assert written.parameters["ks"] == sc.parameters["ks"] == 6000.0
    assert written.solver.samples_per_revolution == data["samples_per_revolution"]
    assert f"wrote calibration.json and scene.toml to {out}/ (run {data['run_id'][:12]})" in output
    # the best set simulated from the folder, as printed: the very features the study fitted, and the same model
    line = _lines(output, "simulate the best set:")
    assert line.replace(shlex.quote(str(out / "scene.toml")), "scene.toml") == data["simulate_best"]
    args = shlex.split(line)[1:]
    assert args[:2] == ["simulate", str(out / "scene.toml")]
    sim = tmp_path / "sim"
    r = CliRunner().invoke(main, [*args, "-o", str(sim), "-q", "--no-figures"])
    assert r.exit_code == 0, r.output
    run = SimulationResult.load(sim)
    assert features(run, run.scene.omega).to_dict() == {
        k: tuple(v) if isinstance(v, list) else v for k, v in data["best"]["features"].items()}
    assert run.info["model_hash"] == data["model_hash"] and run.info["versions"] == data["versions"]
    # the values printed read back as the very numbers of the best set (kg: kg1..kg4)
    sets = dict(args[i + 1].split("=", 1) for i, a in enumerate(args) if a == "--set")
    assert {k: float(v) for k, v in sets.items()} == data["best_overrides"]
    # at most the 12 significant digits scenes keep (the grid's 4e9 was printed 3999999999.999998)
    assert all(float(v) == float(f"{float(v):.12g}") for v in sets.values()), sets
    assert sorted(sets) == sorted(f"contacts.{k}" for k in ("kw", "kg1", "kg2", "kg3", "kg4", "zeta_w", "zeta_g"))


def test_the_scene_file_reruns_the_same_study(completed, tmp_path):
    """``apexseal calibrate <out>/scene.toml`` with the options printed: the same samples, the same best set and
    features, and the scene's content hash the one scene.toml's header gives as written."""
    out, data, output = completed
    line = _lines(output, "re-run:")
    assert line.replace(shlex.quote(str(out / "scene.toml")), "scene.toml") == data["rerun"]
    again = tmp_path / "again"
    r = CliRunner().invoke(main, [*shlex.split(line)[1:], "-q", "-o", str(again)])
    assert r.exit_code == 0, r.output
    second = json.loads((again / "calibration.json").read_text())
    assert second["samples_per_revolution"] == data["samples_per_revolution"]
    assert second["best"] == data["best"] and second["options"] == data["options"]
    assert f"content hash as written {second['scene_hash']}" in (out / "scene.toml").read_text()
    assert second["run_id"] != data["run_id"] and second["model_hash"] == data["model_hash"]


def test_the_unknowns_and_ranges_of_a_study_rerun_from_its_report(tmp_path):
    """``calibrate(ranges=...)`` had no counterpart on the command line, and the re-run line printed for such a
    study ran the default unknowns over their plausible ranges: another study. ``--unknown NAME=LOW:HIGH`` gives
    them; the re-run line writes them back (exactly) where they are not the scene's default ones, and reruns the
    same study."""
    out = tmp_path / "c"
    r = CliRunner().invoke(main, ["calibrate", "--unknown", "kw=1.5e9:4e9", "--unknown", "zeta_g=0.05:0.3", *TINY,
                                  "-o", str(out)])
    assert r.exit_code == 0, r.output
    assert "unknowns kw 1.5e+09..4e+09, zeta_g 0.05..0.3" in r.output
    data = json.loads((out / "calibration.json").read_text())
    assert data["ranges"] == {"kw": [1.5e9, 4e9], "zeta_g": [0.05, 0.3]}
    assert data["rerun"].endswith("--unknown kw=1.5e+09:4e+09 --unknown zeta_g=0.05:0.3")
    # a 1-point grid sits at the middle of each range (log-spaced); kg and zeta_w keep the scene's values
    best = data["best_overrides"]
    assert best["contacts.kw"] == pytest.approx((1.5e9 * 4e9) ** 0.5)
    assert best["contacts.zeta_g"] == pytest.approx((0.05 * 0.3) ** 0.5)
    again = tmp_path / "again"
    r = CliRunner().invoke(main, [*shlex.split(_lines(r.output, "re-run:"))[1:], "-q", "-o", str(again)])
    assert r.exit_code == 0, r.output
    second = json.loads((again / "calibration.json").read_text())
    assert second["ranges"] == data["ranges"] and second["best"] == data["best"]
    assert second["rerun"].replace(str(again), str(out)) == data["rerun"]


@pytest.mark.parametrize("given, words", [
    ("kw=1e5:1e9", "kw = 100000..1e+09: allowed: a range inside the plausible 3e+08..1e+10"),
    ("kw=2e9:1e9", "kw = 2e+09..1e+09: the low end is not below the high end; allowed: LOW..HIGH with LOW < HIGH"),
    ("k=1e9:2e9", "unknown = 'k': not an unknown of the study; allowed: kw, kg, zeta_w, zeta_g"),
    ("kw=1e9", "'kw=1e9': allowed: NAME=LOW:HIGH with finite numbers in SI units"),
    ("kw=1e9 N/m:2e9", "'kw=1e9 N/m:2e9': allowed: NAME=LOW:HIGH"),
    ("kw=nan:2e9", "'kw=nan:2e9': allowed: NAME=LOW:HIGH with finite numbers"),  # was "not below the high end"
])
def test_a_bad_unknown_is_refused_naming_it_before_any_simulation(tmp_path, given, words):
    """Each refusal names the option (those the study refused said "Invalid value:" without it)."""
    out = tmp_path / "c"
    r = CliRunner().invoke(main, ["calibrate", "--unknown", given, *TINY, "-o", str(out)])
    assert r.exit_code == 2 and words in " ".join(r.output.split()), r.output
    assert "Invalid value for" in r.output and "--unknown" in r.output.split("Invalid value for")[1][:20], r.output
    assert not out.exists() and not list(tmp_path.iterdir())


def test_an_unknown_given_twice_is_refused():
    r = CliRunner().invoke(main, ["calibrate", "--unknown", "kw=1e9:2e9", "--unknown", "kw=1e9:3e9", *TINY])
    assert r.exit_code == 2 and "kw given twice: allowed: each unknown once" in r.output, r.output


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_an_interrupted_calibration_does_not_replace_a_completed_one(completed, tmp_path, monkeypatch, signum):
    """A second calibration into the folder of a completed one, stopped by a signal after its first simulation:
    calibration.json was replaced by the interrupted study's. Now the completed report stays as it was and the
    interrupted one is kept beside it, whole, in <out>.partial-<run id>; the command says so and exits with
    128 + the signal."""
    import shutil

    source, data, _ = completed
    out = tmp_path / "c"
    shutil.copytree(source, out)
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    real = calibration.calibrate

    def stopped_after_the_first(sc, **kw):
        kw["progress"] = lambda line: os.kill(os.getpid(), signum)  # noted, acted on before the next simulation
        return real(sc, **kw)

    monkeypatch.setattr(calibration, "calibrate", stopped_after_the_first)
    r = CliRunner().invoke(main, ["calibrate", "--set", SPRING, "--grid", "1", "--polish", "3", "-o", str(out)])
    assert r.exit_code == 128 + signum, r.output
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before  # the completed report, untouched
    (beside,) = [p for p in tmp_path.iterdir() if p.name != "c"]
    second = json.loads((beside / "calibration.json").read_text())
    assert beside.name == f"c.partial-{second['run_id'][:12]}" and second["run_id"] != data["run_id"]
    assert second["status"] == "interrupted" and second["stopped"].startswith("interrupted by ")
    assert len(second["evaluations"]) == 1 and second["options"]["polish"] == 3
    assert sorted(p.name for p in beside.iterdir()) == sorted(before)
    assert f"so the completed report at {out} was kept; this calibration's report is in {beside}/" in r.output


def test_an_interrupted_calibration_into_a_new_folder_is_its_report(tmp_path, monkeypatch):
    """Where no completed report is in the way, the interrupted study's report is moved to <out> (status
    "interrupted"), nothing left beside it."""
    real = calibration.calibrate

    def stopped_after_the_first(sc, **kw):
        kw["progress"] = lambda line: os.kill(os.getpid(), signal.SIGINT)
        return real(sc, **kw)

    monkeypatch.setattr(calibration, "calibrate", stopped_after_the_first)
    out = tmp_path / "new" / "c"
    r = CliRunner().invoke(main, ["calibrate", "--grid", "1", "--polish", "3", "-o", str(out)])
    assert r.exit_code == 130, r.output
    assert json.loads((out / "calibration.json").read_text())["status"] == "interrupted"
    assert [p.name for p in out.parent.iterdir()] == ["c"]
