"""Results side by side (runtime/results/compare.py, ``apexseal compare``): the scene keys that differ, each run's
numbers as a sweep names them, their change against the first."""

from __future__ import annotations

import math

import pandas as pd
import pytest
from click.testing import CliRunner

import apexseal
from apexseal.cli import main
from apexseal.runtime.results.compare import compare, compared, scene_keys
from apexseal.runtime.results.plausibility import penetrations
from apexseal.runtime.results.quantities import collect, quantity_help


@pytest.fixture(scope="module")
def folders(tmp_path_factory):
    """The default scene, the same with a stiffer spring, and with groove friction off (one revolution each), and
    the default scene at a tenth of its rtol ("tight")."""
    root = tmp_path_factory.mktemp("compare")
    scene = apexseal.load_scene()
    scenes = {"default": scene, "stiff": scene.with_overrides(**{"spring.ks": "2e4 N/m"}),
              "smooth": scene.with_overrides(**{"effects.groove_friction": False})}
    for name, s in scenes.items():
        apexseal.simulate(s, out=root / name, samples_per_revolution=360)
    apexseal.simulate(scene, out=root / "tight", samples_per_revolution=360, rtol=scene.solver.rtol / 10)
    return {name: root / name for name in (*scenes, "tight")}


def test_the_changed_key_and_each_runs_numbers(folders):
    c = compare([folders["default"], folders["stiff"]])
    assert c.labels == ["default", "stiff"]
    # the spring's damper is given as a ratio (zeta_s): its coefficient, derived from ks, is shown changing with it
    assert list(c.scenes.index) == ["contacts.cs", "spring.ks"]
    assert list(c.scenes.loc["spring.ks"]) == ["5000.0 N/m", "20000.0 N/m"]
    low, high = (float(v.split()[0]) for v in c.scenes.loc["contacts.cs"])
    assert c.scenes.loc["contacts.cs"].str.endswith("N*s/m (derived)").all() and high == pytest.approx(2 * low, 1e-3)
    assert c.numbers.loc["status"].tolist() == ["completed", "completed"]
    for label, folder in zip(c.labels, (folders["default"], folders["stiff"]), strict=True):
        expected = collect(apexseal.SimulationResult.load(folder), compared())
        for q, value in expected.items():
            row = f"{q} ({quantity_help()[q][0]})"
            if math.isnan(value):  # no run has it (the gas model's): left out of the table
                assert row not in c.numbers.index and q.startswith("gas."), row
                continue
            assert c.numbers.loc[row, label] == value, row
    text = c.text()
    assert "spring.ks" in text and "change against default" in text
    base = c.numbers.loc["friction_power.total (W)", "default"]
    stiff = c.numbers.loc["friction_power.total (W)", "stiff"]
    assert f"{stiff:.4g} ({100 * (stiff - base) / base:+.1f} %)" in text


def test_an_effect_off_shows_as_a_key_and_its_quantities_as_missing(folders):
    c = compare([folders["default"], folders["smooth"]])
    assert list(c.scenes.index) == ["effects.groove_friction"]
    row = c.numbers.loc["friction_power.i1 (W)"]
    assert row["default"] > 0 and math.isnan(row["smooth"])
    line = next(ln for ln in c.text().splitlines() if ln.startswith("friction_power.i1"))
    assert line.split()[-1] == "–"


def test_a_value_given_explicitly_equals_its_default():
    scene = apexseal.load_scene()
    same = scene.with_overrides(**{"spring.ks": "5 kN/m", "friction.v_eps": scene.friction.v_eps})
    assert scene_keys(scene) == scene_keys(same)
    assert scene_keys(scene)["pressure.file"].startswith("table sha256 ")  # the default's table, by its rows


def test_the_penetrations_are_the_plausibility_checks(folders):
    assert penetrations() == {"housing": (("xs5", 1.0),), "i1": (("b1", -1.0),), "c2": (("b2", -1.0),),
                              "i2": (("b3", -1.0),), "c4": (("b4", -1.0),)}  # the spring, closed at rest, left out
    result = apexseal.SimulationResult.load(folders["default"])
    depths = result.summary()["plausibility"]["penetration_um"]
    assert collect(result, tuple(f"penetration.{c}" for c in penetrations())) == \
        {f"penetration.{c}": depths[c] for c in penetrations()}
    assert all(d > 0 for d in depths.values())  # every contact touched in the revolution


def test_the_command_prints_both_tables_and_writes_them(folders, tmp_path):
    out = tmp_path / "cmp"
    r = CliRunner().invoke(main, ["compare", str(folders["default"]), str(folders["stiff"]), "-o", str(out)])
    assert r.exit_code == 0, r.output
    assert "spring.ks" in r.output and "friction_power.total (W)" in r.output
    numbers = pd.read_csv(out / "comparison.csv", index_col=0)
    expected = compare([folders["default"], folders["stiff"]]).numbers
    assert numbers.loc["friction_power.total (W)"].astype(float).tolist() == \
        expected.loc["friction_power.total (W)"].tolist()
    assert pd.read_csv(out / "scene-differences.csv", index_col=0).index.tolist() == ["contacts.cs", "spring.ks"]
    assert (out / "comparison.png").read_bytes().startswith(b"\x89PNG")


def test_the_command_refuses_one_folder_and_a_folder_without_a_result(folders, tmp_path):
    one = CliRunner().invoke(main, ["compare", str(folders["default"])])
    assert one.exit_code == 2 and "two or more result folders, got 1" in one.output
    bad = CliRunner().invoke(main, ["compare", str(folders["default"]), str(tmp_path)])
    assert bad.exit_code == 1 and str(tmp_path) in bad.output and "result.json" in bad.output
    twice = CliRunner().invoke(main, ["compare", str(folders["default"]), str(folders["default"])])
    assert twice.exit_code == 0 and "the scenes are the same" in twice.output
    assert f"{folders['default']} (1)" in twice.output and f"{folders['default']} (2)" in twice.output


def test_the_command_does_not_write_into_a_result_folder(folders):
    """--out of a result folder wrote comparison.csv into it, and --resume then refused the folder for files that
    are not a result's."""
    into = folders["stiff"]
    before = sorted(p.name for p in into.iterdir())
    r = CliRunner().invoke(main, ["compare", str(folders["default"]), str(into), "-o", str(into)])
    assert r.exit_code == 2 and "holds a simulation's result (result.json): the comparison's files would mix" in \
        " ".join(r.output.split()), r.output
    assert sorted(p.name for p in into.iterdir()) == before


def test_results_of_the_same_scene_and_other_models_say_so(folders, tmp_path):
    """Two runs of one scene with models of other sources read as "the scenes are the same" and nothing else."""
    import json
    import shutil

    other = tmp_path / "other"
    shutil.copytree(folders["default"], other)
    record = json.loads((other / "result.json").read_text())
    record["info"]["model_hash"] = "f" * 64
    (other / "result.json").write_text(json.dumps(record))
    text = compare([folders["default"], other]).text()
    assert "the scenes are the same" in text and "the models differ (model hash default " in text
    assert "other ffffffffffff" in text
    assert "the models differ" not in compare([folders["default"], folders["stiff"]]).text()


def test_results_of_other_effects_are_not_said_to_differ_in_their_models(folders):
    """Their model hashes differ because their effects do (the scene keys say so): "the derivation, a submodel or
    the generator changed" was false there."""
    text = compare([folders["default"], folders["smooth"]]).text()
    assert "effects.groove_friction" in text and "the models differ" not in text


def test_a_key_only_a_later_scene_has_is_a_difference():
    """The differing keys are those of every scene, not the first's alone: a table-pressure scene after a constant one
    shows its table, with "–" for the first (keys taken from the first scene only went unnoticed)."""
    import apexseal
    from apexseal.runtime.results.compare import scene_differences

    table = apexseal.load_scene()
    constant = table.with_overrides(pressure={"source": "constant", "Pa": "6 bar", "Pb": "1 bar"})
    diff = scene_differences([constant, table], ["constant", "table"])
    assert diff.loc["pressure.file", "constant"] == "–" and diff.loc["pressure.file", "table"].startswith("table sha256")
    assert diff.loc["pressure.Pa", "table"] == "–"


def test_scene_values_are_compared_at_the_digits_that_tell_them_apart(folders):
    """compare's text shows a differing scene value with its unit to the fewest digits (from 4) that keep the row's
    values apart, not scene.toml's seventeen; integers, words, a missing value and a number with no more digits
    stay as written, and the table and its CSV keep every value whole."""
    from apexseal.runtime.results.compare import _shortest

    assert _shortest(["-0.436332312998582 rad", "-0.698131700797732 rad"]) == ["-0.4363 rad", "-0.6981 rad"]
    assert _shortest(["1.0000001 m", "1.0000002 m"]) == ["1.0000001 m", "1.0000002 m"]
    assert _shortest(["0.001 m", "0.0010004 m"]) == ["0.001 m", "0.0010004 m"]
    assert _shortest(["36", "360"]) == ["36", "360"]
    assert _shortest(['"erk"', '"rosenbrock"']) == ['"erk"', '"rosenbrock"']
    assert _shortest(["5 m", "–"]) == ["5 m", "–"]
    # a key one result lacks (the ports of a scene without them): the other's number is shortened all the same
    assert _shortest(["-0.436332312998582 rad", "–"]) == ["-0.4363 rad", "–"]
    assert _shortest(['"limacon-to-limacon"', "0.0001 m"]) == ['"limacon-to-limacon"', "0.0001 m"]
    c = compare([folders["default"], folders["stiff"]])
    assert list(c.scenes.loc["spring.ks"]) == ["5000.0 N/m", "20000.0 N/m"]  # whole in the table (and its CSV)
    assert "5000 N/m" in c.text() and "20000 N/m" in c.text() and "20000.0" not in c.text()


def test_a_change_against_a_run_without_the_quantity_is_not_a_percentage():
    """A run without the quantity (NaN: an effect off) printed `0 (+nan %)` beside it."""
    from apexseal.runtime.results.compare import _cell

    assert _cell(0.0, math.nan, True) == "0" and _cell(2.0, math.inf, True) == "2"
    assert _cell(1.5, 1.0, True) == "1.5 (+50.0 %)"


def _marked(c, label: str) -> list[str]:
    """The quantities whose change against the first result ``compare`` marks as within the noise."""
    return [q for q, m in c.within_noise()[label].items() if m]


def _changed(c, label: str) -> list[str]:
    base = c.numbers[c.labels[0]]
    return [q for q in c.noise.index if c.numbers.loc[q, label] != base[q] and not math.isnan(base[q])]


def test_runs_that_differ_only_in_rtol_are_within_the_noise(folders):
    """compare stated no noise floor: the default scene at rtol 1e-6 and at 1e-7 (nothing physical changed) showed
    changes of up to a few per cent (the impacts amplify integration error) as if they were effects. Each number
    now carries a noise estimate from its run's rtol, and every one of those changes is marked within it."""
    c = compare([folders["default"], folders["tight"]])
    changed = _changed(c, "tight")
    assert changed and _marked(c, "tight") == changed
    text = c.text()
    assert "runs: default erk, rtol 1e-06; tight erk, rtol 1e-07" in text
    assert "estimated from each run's rtol" in text and "--noise (noise=True) measures it" in text
    assert "~: a change within the numerical noise" in text and "a tighter rtol for every run (--rtol, rtol=)" in text
    row = next(ln for ln in text.splitlines() if ln.startswith(changed[0]))
    assert row.endswith("%)~") and row.split()[3].startswith("±")  # the noise column beside the first, a share


def test_a_real_change_is_not_within_the_noise(folders):
    """A four times stiffer spring moves the means and the switches far beyond any noise: not marked."""
    for noise in (None, folders["tight"]):  # by the rule, and measured from the re-run at a tenth of the rtol
        c = compare([folders["default"], folders["stiff"]], noise=noise)
        marked = _marked(c, "stiff")
        for q in ("friction_power.total (W)", "friction_power.spring (W)", "housing_force.mean (N)",
                  "events.total (1)"):
            assert q in _changed(c, "stiff") and q not in marked, (noise, q)


def test_the_measured_noise_is_the_first_run_s_change_at_a_tighter_rtol(folders):
    """noise=<a re-run of the first at a tighter rtol>: each number's noise is its change in that re-run (the
    first's integration error); a run at the same rtol carries the same, so the tight run's changes are all
    within it, and a result that is not such a re-run is refused, naming what differs."""
    c = compare([folders["default"], folders["tight"]], noise=folders["tight"])
    assert c.noise_source.startswith("measured: the first run re-run at rtol 1e-07")
    tight = c.numbers["tight"]
    for q in c.noise.index:
        assert c.noise.loc[q, "default"] == abs(c.numbers.loc[q, "default"] - tight[q])
        assert c.noise.loc[q, "tight"] == pytest.approx(c.noise.loc[q, "default"] / 10)
    assert _marked(c, "tight") == _changed(c, "tight")
    with pytest.raises(ValueError, match=r"not a re-run of the first result's scene \(differs in .*spring\.ks"):
        compare([folders["default"], folders["stiff"]], noise=folders["stiff"])
    with pytest.raises(ValueError, match=r"solver\.rtol = 1e-06 is not tighter than the first result's 1e-07"):
        compare([folders["tight"], folders["default"]], noise=folders["default"])
    with pytest.raises(TypeError, match="noise = 3: expected None"):
        compare([folders["default"], folders["tight"]], noise=3)


def test_noise_true_reruns_the_first_and_save_keeps_the_rerun(folders, tmp_path):
    c = compare([folders["default"], folders["stiff"]], noise=True)
    assert c.noise_run.info["rtol"] == pytest.approx(1e-7) and not c.noise_run_kept
    assert c.noise_run.scene.solver.samples_per_revolution == 360  # the first's settings, but its rtol
    written = c.save(tmp_path / "cmp")
    assert (tmp_path / "cmp" / "noise-rerun" / "result.json").exists() and len(written) == 5
    noise = pd.read_csv(tmp_path / "cmp" / "noise.csv", comment="#", index_col=0)
    assert noise.loc["friction_power.total (W)", "default"] == pytest.approx(c.noise.loc["friction_power.total (W)",
                                                                                           "default"])
    assert (tmp_path / "cmp" / "noise.csv").read_text().startswith("# numerical noise of each number, measured")


def test_the_command_measures_the_noise_on_request(folders, tmp_path):
    out = tmp_path / "cmp"
    r = CliRunner().invoke(main, ["compare", str(folders["default"]), str(folders["tight"]), "--noise", "-o",
                                  str(out)])
    assert r.exit_code == 0, r.output
    assert "measured: the first run re-run at rtol 1e-07" in r.output and (out / "noise-rerun" / "scene.toml").exists()
    again = CliRunner().invoke(main, ["compare", str(folders["default"]), str(folders["tight"]), "--noise-from",
                                      str(out / "noise-rerun")])
    assert again.exit_code == 0 and "measured: the first run re-run at rtol 1e-07" in again.output
    bad = CliRunner().invoke(main, ["compare", str(folders["default"]), str(folders["tight"]), "--noise-from",
                                    str(folders["stiff"])])
    assert bad.exit_code == 1 and "spring.ks" in bad.output and "tighter solver.rtol" in bad.output
    both = CliRunner().invoke(main, ["compare", str(folders["default"]), str(folders["tight"]), "--noise",
                                     "--noise-from", str(folders["tight"])])
    assert both.exit_code == 2 and "give one" in both.output


def test_the_rule_scales_with_rtol_and_leaves_a_fixed_step_run_unestimated():
    from apexseal.runtime.results.noise import SPREAD_AT_1E6, kind, rule_noise

    assert [kind(q) for q in ("revolutions", "events.total", "friction_power.c2", "friction_power.total",
                              "housing_force.max", "penetration.i2", "liftoff_fraction")] == \
        [None, "count", "groove friction", "mean", "peak", "peak", "count"]
    values = {"housing_force.max": 200.0, "revolutions": 1.0}
    assert rule_noise(values, 1e-7) == {"housing_force.max": pytest.approx(SPREAD_AT_1E6["peak"] * 20.0),
                                        "revolutions": 0.0}
    assert math.isnan(rule_noise(values, None)["housing_force.max"])


def test_runs_sampled_or_run_differently_are_said_not_alike(folders, tmp_path):
    """Runs at 720 and 360 samples per revolution showed housing_force.max 85.6 -> 37.3 N (-56 %) side by side,
    although peaks at different samplings are not comparable (the README says so): compare says it now, as it
    does for runs of different lengths; runs alike say nothing."""
    dense = tmp_path / "dense"
    apexseal.simulate(apexseal.load_scene(), out=dense, samples_per_revolution=720, revolutions=2)
    text = compare([folders["default"], dense]).text()
    assert "not alike: samples per revolution (default 360, dense 720): peaks" in text
    assert "not alike: revolutions (default 1, dense 2)" in text
    assert "not alike" not in compare([folders["default"], folders["stiff"]]).text()


def test_numbers_the_samples_do_not_resolve_are_said_to_be_so(folders):
    """compare marked a groove contact's friction power as changed by +84 % beside a noise of 4 % (the rtol's), where
    the run's own samples miss a share of the contacts' work that size (its energy balance does not close at 360
    samples): the comparison names the runs whose balance does not close and what they miss, as simulate's note does."""
    c = compare([folders["default"], folders["stiff"]])
    unresolved = c.unresolved_by_samples()
    fractions = c.numbers.loc["energy.residual_fraction (1)"]
    assert set(unresolved) == {label for label in c.labels if fractions[label] > 0.05} and unresolved
    for label, missed in unresolved.items():
        assert missed == pytest.approx(c.numbers.loc["energy.residual (J)", label])
    text = c.text()
    assert "sampling: the seal's energy balance over the samples does not close for default (misses " in text
