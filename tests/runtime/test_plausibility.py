"""Damping stated as a ratio of critical damping, and the penetration check after a run."""

import math
import warnings

import numpy as np
import pytest
from hard_helpers import HARD_DIR

import apexseal
from apexseal.derive.numbers import tip_arc_start
from apexseal.runtime.results.plausibility import (
    PENETRATION_FLOOR,
    PENETRATION_FRACTION,
    FlankWarning,
    PenetrationWarning,
    flank_check,
    penetration_check,
)
from apexseal.runtime.results.quantities import collect
from apexseal.runtime.results.summary import summarise
from apexseal.runtime.scenes.scene import Scene, SceneError, default_scene_text, load_scene

SAMPLES = 720


@pytest.fixture(scope="module")
def scene():
    return load_scene()


def test_a_changed_stiffness_keeps_its_damping_ratio(scene):
    stiff = scene.with_overrides(**{"contacts.kw": 4e9, "contacts.kg2": 3e9, "spring.ks": 2e4})
    p, ms = stiff.parameters, stiff.parameters["ms"]
    assert p["cw"] == pytest.approx(2 * 0.1 * math.sqrt(4e9 * ms), rel=1e-12)
    assert p["cr"] == pytest.approx(2 * 0.1 * math.sqrt((3 * 1e9 + 3e9) / 4 * ms), rel=1e-12)  # the mean kg
    assert p["cs"] == pytest.approx(2 * 0.1 * math.sqrt(2e4 * ms), rel=1e-12)
    half = scene.with_overrides(**{"contacts.zeta_w": 0.05})
    assert half.parameters["cw"] == pytest.approx(scene.parameters["cw"] / 2, rel=1e-12)


def test_an_explicit_coefficient_replaces_the_ratio(scene):
    s = scene.with_overrides(**{"contacts.cw": 50.0})
    assert s.parameters["cw"] == 50.0 and s.parameters["cr"] == scene.parameters["cr"]
    assert s.with_overrides(**{"contacts.kw": 2e9}).parameters["cw"] == 50.0  # no ratio left to follow kw
    back = s.with_overrides(**{"contacts.zeta_w": 0.1})
    assert back.parameters["cw"] == pytest.approx(scene.parameters["cw"], rel=1e-12)


@pytest.mark.parametrize("pair", [("cw", "zeta_w"), ("cr", "zeta_g"), ("cs", "zeta_s")])
def test_a_scene_giving_both_is_an_error_naming_both(pair):
    coefficient, ratio = pair
    text = default_scene_text().replace(f"{ratio} = 0.1", f"{ratio} = 0.1\n{coefficient} = \"5 N*s/m\"")
    with pytest.raises(SceneError) as err:
        Scene.from_toml_string(text, load_scene()._base_dir)
    assert len(err.value.errors) == 1
    message = str(err.value)
    assert f"contacts.{coefficient}" in message and f"contacts.{ratio}" in message and "allowed: one of" in message
    with pytest.raises(SceneError, match="contacts.zeta_w"):
        load_scene().with_overrides(**{"contacts.cw": 5.0, "contacts.zeta_w": 0.2})


def test_a_ratio_out_of_range_names_its_range(scene):
    with pytest.raises(SceneError, match=r"contacts.zeta_g = -0.1: .*allowed: 0 <= value <= 5"):
        scene.with_overrides(**{"contacts.zeta_g": -0.1})


def test_hard_scenes_keep_their_explicit_damping():
    s = load_scene(HARD_DIR / "stiff-groove-1e9.toml")
    assert {k: s.parameters[k] for k in ("cw", "cr", "cs")} == {"cw": 207.0, "cr": 27.0, "cs": 1.9}


def test_the_default_scene_is_plausible(scene, default_functions):
    with warnings.catch_warnings():
        warnings.simplefilter("error", PenetrationWarning)
        warnings.simplefilter("error", FlankWarning)
        r = apexseal.simulate(scene, functions=default_functions.sx, samples_per_revolution=SAMPLES)
    flank = summarise(r)["flank"]
    assert flank["ok"] and flank["first_off_deg"] is None and min(flank["least_mm"].values()) > 0
    # l1 + l2 and l3 + l4 are the length of the seal's flat sides, ds0 + ds2 (Eqs. 22-24), whatever the motion
    p = scene.parameters
    side = tip_arc_start(ds1=p["ds1"], ro=p["ro"], beta_o=p["beta_o"]) + p["ds2"]
    for a, b in (("l1", "l2"), ("l3", "l4")):
        assert r.outputs[a] + r.outputs[b] == pytest.approx(side, rel=1e-12), (a, b)
    check = summarise(r)["plausibility"]
    assert check["ok"] and check["beyond_limit"] == []
    assert check["side_clearance_um"] == pytest.approx(30.0)
    assert check["limit_um"] == pytest.approx(PENETRATION_FRACTION * 30.0)
    assert set(check["penetration_um"]) == {"housing", "i1", "c2", "i2", "c4"}
    # metal contacts: the tip sinks by a fraction of a micrometre; the groove contacts by about 2 um at the
    # chamber switches, where the seal crosses its clearance and strikes the far wall with a few kN
    assert 0 < check["penetration_um"]["housing"] < 1.0
    assert 0.5 < max(check["penetration_um"].values()) < check["limit_um"]


def test_a_soft_groove_is_flagged(scene, default_functions):
    soft = scene.with_overrides(**{f"contacts.kg{i}": 1.05e6 for i in range(1, 5)} | {"contacts.cr": 27.0})
    with pytest.warns(PenetrationWarning, match=r"more than 0.25 of the side clearance \(Wg - Ws\)/2 = 30 µm") as w:
        r = apexseal.simulate(soft, functions=default_functions.sx, samples_per_revolution=SAMPLES)
    check = penetration_check(r)
    assert not check["ok"] and set(check["beyond_limit"]) <= {"i1", "c2", "i2", "c4"} and check["beyond_limit"]
    assert all(check["penetration_um"][c] > 7.5 for c in check["beyond_limit"])
    assert str(w[0].message).startswith("implausible penetration: ")
    assert " into the wall at the output samples, more than 0.25" in str(w[0].message)  # not between them
    assert "far below a metal contact's" in str(w[0].message)  # F / depth is about the 1.05e6 N/m given
    assert summarise(r)["plausibility"] == check


def test_a_tiny_clearance_does_not_make_metal_contacts_implausible(scene, default_functions):
    """With the groove 1 µm wider than the seal (side clearance 0.5 µm, allowed: any Wg > Ws) the metal contacts
    (1e9 N/m) sank 0.17 µm under 172 N, ordinary loads, and the check, a quarter of the clearance (0.125 µm), warned
    that the loads were beyond what the seal takes. The limit is now at least the softest metal contact's deflection
    under 300 N (1 µm); a groove softer than metal in the same clearance is still flagged."""
    tight = scene.with_overrides(**{"seal.Wg": "3.001 mm"})
    with warnings.catch_warnings():
        warnings.simplefilter("error", PenetrationWarning)
        r = apexseal.simulate(tight, functions=default_functions.sx, samples_per_revolution=SAMPLES)
    check = penetration_check(r)
    assert check["side_clearance_um"] == pytest.approx(0.5) and check["ok"]
    assert check["limit_um"] == pytest.approx(PENETRATION_FLOOR * 1e6) == pytest.approx(1.0)
    assert PENETRATION_FRACTION * check["side_clearance_um"] < max(check["penetration_um"].values()) < 1.0
    soft = tight.with_overrides(**{f"contacts.kg{i}": 1.05e6 for i in range(1, 5)} | {"contacts.cr": 27.0})
    with pytest.warns(PenetrationWarning, match=r"more than 1 µm, the least limit at any clearance \(a metal "
                      r"contact's deflection under 300 N; 0.25 of the side clearance \(Wg - Ws\)/2 = 0.5 µm is "
                      r"0.125 µm\)"):
        apexseal.simulate(soft, functions=default_functions.sx, samples_per_revolution=SAMPLES)


def test_the_penetration_warning_blames_the_loads_when_the_contacts_are_metal():
    """A seal on metal contacts (1e9 N/m) at 20000 rpm sank 23 um into the housing under 23 kN, and the warning said
    its stiffness was far below a metal contact's: the peak force over the depth tells the two causes apart."""
    from apexseal.runtime.results.plausibility import describe

    check = {"fraction": 0.25, "side_clearance_um": 30.0, "limit_um": 7.5, "beyond_limit": ["housing"],
             "penetration_um": {"housing": 23.4, "i1": 2.0}, "peak_force_N": {"housing": 23.4e3, "i1": 2e3}}
    metal = describe(check)
    assert "under peak forces of housing 23.4 kN (about 1e+09 N/m): the contacts are as stiff as metal, so the " \
        "loads are beyond what the seal takes" in metal and "far below" not in metal
    soft = describe({**check, "peak_force_N": {"housing": 1.5, "i1": 2e3}})
    assert "housing 0.0015 kN (about 6.4e+04 N/m): the contact stiffness is far below a metal contact's" in soft
    older = describe({k: v for k, v in check.items() if k != "peak_force_N"})  # a summary.json written before
    assert "; either the contact stiffness is far below a metal contact's" in older and "or the loads" in older


def test_a_seal_started_inside_its_groove_wall_is_told_to_check_its_initial_state():
    """operation.initial_state.y = 0.2 mm started the seal 170 µm into two groove corners (the start check lets up
    to 0.1 Ws through), and the warning blamed the loads: a contact deepest at the run's first sample is the start's."""
    from types import SimpleNamespace

    from apexseal.runtime.results.plausibility import describe, penetration_check

    depth = np.array([170e-6, 20e-6, 1e-6])  # b3 below zero is penetration (sign -1)
    outputs = {"xs5": np.zeros(3), "b1": np.zeros(3), "b2": np.zeros(3), "b3": -depth, "b4": -depth[::-1]}
    check = penetration_check(SimpleNamespace(outputs=outputs, n=3), clearance=30e-6)
    assert check["beyond_limit"] == ["c4", "i2"] and check["deepest_at_start"] == ["i2"]  # c4 deepest at the end
    assert "initial state" not in describe(check)
    started = penetration_check(SimpleNamespace(outputs={**outputs, "b4": -depth}, n=3), clearance=30e-6)
    assert started["deepest_at_start"] == ["c4", "i2"]
    assert describe(started).endswith("deepest at the run's first sample: the initial state puts the seal into the "
                                      "wall (check operation.initial_state; the start check lets a start this deep "
                                      "through: docs/scenes.md)")


def test_a_seal_driven_into_its_groove_is_flagged(scene, default_functions):
    """Thrown inwards at 2 m/s, the seal sinks about 0.7 mm into its groove, which puts the mouth corners g1 and g3
    on its tip arc, outside the seal-groove contact model (Eqs. 20-23): the run says so, from the first sample."""
    thrown = scene.with_overrides(**{"operation.initial_state.xd": "-2 m/s"})
    with pytest.warns(FlankWarning, match=r"sank into its groove until a mouth corner lay on its tip arc \(least l1 = "
                      r"-0\.\d+ mm, l3 = -0\.\d+ mm; first at [\d.]+ deg\)") as w:
        r = apexseal.simulate(thrown, functions=default_functions.sx, samples_per_revolution=SAMPLES)
    assert "Eqs. 20-23" in str(w[0].message)
    check = flank_check(r)
    assert summarise(r)["flank"] == check and not check["ok"]
    first = int(np.searchsorted(np.degrees(r.theta), check["first_off_deg"]))
    lengths = np.stack([r.outputs[n] for n in ("l1", "l2", "l3", "l4")])
    assert (lengths[:, :first] > 0).all() and (lengths[:, first] <= 0).any()
    assert check["least_mm"]["l1"] == pytest.approx(r.outputs["l1"].min() * 1e3)
    assert collect(r, ("flank.least",))["flank.least"] == min(check["least_mm"].values()) < 0  # a sweep's quantity
    # its repr (a notebook's first view, beside the mean friction power) says where the model stops holding
    assert f"outside the model from {check['first_off_deg']:.4g} deg, friction power" in repr(r)
    assert "outside the model" in r._repr_html_() and "outside the model" not in repr(
        apexseal.simulate(scene, functions=default_functions.sx, samples_per_revolution=SAMPLES))


def test_the_check_needs_a_clearance(scene, default_functions):
    r = apexseal.simulate(scene, functions=default_functions.sx, samples_per_revolution=72)
    r.info.pop("side_clearance_m")
    with pytest.raises(ValueError, match="no side clearance"):
        penetration_check(r)
    assert "plausibility" not in summarise(r)
    # a 1 nm fit: every contact is deeper than half of it, but no deeper than metal sinks under ordinary loads
    assert penetration_check(r, clearance=1e-9, fraction=0.5, floor=0.0)["beyond_limit"]
    assert penetration_check(r, clearance=1e-9, fraction=0.5)["ok"]


@pytest.mark.parametrize("explicit", [False, True])
def test_a_resolved_scene_states_the_damping_once(scene, tmp_path, explicit):
    """A result's scene.toml gives the ratio, or the coefficient the scene gave instead, never both, and reloads."""
    from apexseal.runtime.scenes.resolved import resolved_toml

    sc = scene.with_overrides(**{"contacts.cw": 207.0}) if explicit else scene
    text, files = resolved_toml(sc)
    for name, content in files.items():
        (tmp_path / name).write_text(content)
    (tmp_path / "scene.toml").write_text(text)
    back = load_scene(tmp_path / "scene.toml")
    assert back.content_hash() == sc.content_hash() and back.parameters["cw"] == sc.parameters["cw"]
    assert ("\ncw = " in text) == explicit and ("\nzeta_w = " in text) != explicit and "\nzeta_g = " in text
