"""The command line end to end: simulate the default scene, derive, bad input."""

from __future__ import annotations

import json

from click.testing import CliRunner

from apexseal.cli import main


def test_simulate_default_scene_end_to_end(tmp_path):
    out = tmp_path / "run"
    r = CliRunner().invoke(main, ["simulate", "--revolutions", "1", "--out", str(out), "--quiet", "--csv"])
    assert r.exit_code == 0, r.output
    for name in ("trajectory.csv", "parts/part-00000.npz", "result.json", "summary.json", "fig12_displacements.png",
                 "fig13_forces.png", "fig14_housing_spectrum.png", "mode_timeline.png"):
        assert (out / name).stat().st_size > 0, name
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]  # written beside it, renamed into place
    summary = json.loads((out / "summary.json").read_text())
    assert summary["run_id"] == json.loads((out / "result.json").read_text())["run_id"]
    assert summary["status"] == "completed"
    assert summary["run"]["method"] == "erk"
    assert summary["events_total"] > 0
    assert set(summary["extremes"]) == {"x", "y", "phi"}
    assert "wrote" in r.output and str(out) in r.output


def test_simulate_rejects_a_bad_scene_with_the_key_named(tmp_path):
    scene = tmp_path / "bad.toml"
    from apexseal.runtime.scenes.scene import default_scene_text

    scene.write_text(default_scene_text().replace('ks = "5e3 N/m"', 'ks = "-5e3 N/m"'))
    r = CliRunner().invoke(main, ["simulate", str(scene), "--out", str(tmp_path / "o")])
    assert r.exit_code != 0
    assert "spring.ks" in r.output and "-5e3" in r.output
    assert not (tmp_path / "o" / "summary.json").exists()


def test_simulate_refuses_an_unwritable_output_folder(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    r = CliRunner().invoke(main, ["simulate", "--out", str(blocker / "sub")])
    assert r.exit_code != 0
    assert "--out" in r.output and "cannot create the output folder" in r.output


def test_derive_reports_cold_and_cached_times():
    r = CliRunner().invoke(main, ["derive"])
    assert r.exit_code == 0, r.output
    assert "contact guards" in r.output and "cached call" in r.output
