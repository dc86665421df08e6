"""Units that can be silently wrong (issue: results a notebook user can trust): each defect has a test."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import pytest

from apexseal.runtime.scenes.errors import SceneError
from apexseal.runtime.scenes.units import PlausibilityWarning, plausible_ranges

#: the repository (the tests run from a checkout; the package itself may be installed elsewhere)
REPO = Path(__file__).resolve().parents[2]


def test_quoted_number_without_unit_is_an_error_naming_key_and_unit(default_scene):
    """delta_s = "2.0" was read as 2 m and the run blew up at 2.2 deg with advice about contact stiffness."""
    with pytest.raises(SceneError) as err:
        default_scene.with_overrides(**{"spring.delta_s": "2.0"})
    assert err.value.keys() == ["spring.delta_s"]
    assert "needs a unit" in str(err.value) and "length in m" in str(err.value)


def test_bare_numbers_keep_meaning_si(default_scene):
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        scene = default_scene.with_overrides(**{"spring.delta_s": 0.002})
    assert scene.spring.delta_s == 0.002


def test_a_bare_length_of_metres_is_reported_against_the_key_written(default_scene):
    """Ws = 3.0 (meant mm) was reported against Wg and ro instead of Ws."""
    with pytest.raises(SceneError) as err:
        default_scene.with_overrides(**{"seal.Ws": 3.0})
    assert err.value.keys()[0] == "seal.Ws"
    assert 'did you mean "3 mm"' in str(err.value)


def test_a_preload_of_metres_warns(default_scene):
    with pytest.warns(PlausibilityWarning, match=r"spring\.delta_s.*far outside engineering practice"):
        default_scene.with_overrides(**{"spring.delta_s": 2.0})


def test_a_pressure_table_in_bar_declared_in_pa_warns(default_scene, tmp_path):
    """A table in bar declared unit = "Pa" completed at 1.5-9 Pa with no warning."""
    table = tmp_path / "bar.csv"
    table.write_text("theta_deg,Pa,Pb\n0,1.5,9\n180,9,1.5\n")
    with pytest.warns(PlausibilityWarning, match=r"pressure\.unit.*1\.5\.\.9 Pa.*bar"):
        default_scene.with_overrides(**{"pressure.file": str(table)})
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        scene = default_scene.with_overrides(**{"pressure.file": str(table), "pressure.unit": "bar"})
    assert scene.pressure.pa.max() == pytest.approx(9e5)


def test_a_pressure_table_in_pa_declared_in_bar_warns(default_scene, tmp_path):
    """A table in Pa declared unit = "bar" (1.5e10 Pa) loaded with no warning and failed at the first step."""
    table = tmp_path / "pa.csv"
    table.write_text("theta_deg,Pa,Pb\n0,150000,900000\n180,900000,150000\n")
    with pytest.warns(PlausibilityWarning, match=r"pressure\.unit.*1\.5e\+10\.\.9e\+10 Pa, above 1e\+08 Pa"):
        default_scene.with_overrides(**{"pressure.file": str(table), "pressure.unit": "bar"})


def test_the_default_and_hard_scenes_are_plausible():
    """Every shipped scene lies inside the documented ranges (no warning on a correct scene)."""
    import apexseal

    hard = REPO / "runtime" / "scenes" / "hard"
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        apexseal.load_scene()
        for f in sorted(hard.glob("*.toml")):
            apexseal.load_scene(f)

def test_the_plausible_ranges_are_documented():
    doc = (REPO / "docs" / "scenes.md").read_text().split("## Plausible ranges")[1]
    rows = [line for line in doc.splitlines() if line.startswith("| `")]
    assert rows[:len(plausible_ranges())] == [f"| `{k}` | {r.describe()} |" for k, r in plausible_ranges().items()]


@pytest.mark.parametrize("density", ["21000 kg/m^3", "1e-30 kg/m^3"])
def test_a_density_beyond_any_seal_material_warns(default_scene, density):
    """seal.density had no plausible range: 1e30 kg/m^3 loaded without a word (its mass 1e30 times too big) and the
    run left the model's domain at 20 deg. Now beyond osmium's it is refused (test_bad_input.py), and a density
    outside the seal materials' but possible, denser than tungsten or a foam's, warns."""
    with pytest.warns(PlausibilityWarning, match=r"seal.density.*500 to 20000 kg/m\^3"):
        default_scene.with_overrides(**{"seal.density": density})


def test_a_value_no_law_reads_is_not_questioned(default_scene):
    """A spring stiffness of 1e9 N/m warns while the spring is in the model, and not once it is switched off (no law
    reads it then; the warning sent the user after a value that changes nothing)."""
    off = {"effects.spring": False, "effects.spring_damping": False, "effects.spring_friction": False}
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        default_scene.with_overrides(**off, **{"spring.ks": "1e9 N/m"})
    with pytest.warns(PlausibilityWarning, match="spring.ks"):  # its preload 0.1 mm: the wall's deflection at rest
        default_scene.with_overrides(**{"spring.ks": "1e9 N/m", "spring.delta_s": "0.1 mm"})  # within 0.1 Ws


def test_a_scene_s_warnings_point_at_the_line_that_made_the_scene(default_scene):
    """From every entry point (a file, a string, an override) a scene's warnings name the caller's own line, as a
    script or notebook shows it: a fixed stack level named the line of the caller's caller from with_overrides and
    from_toml_string (or Python's "sys:1" at a script's top level)."""
    from apexseal import Scene, load_scene
    from apexseal.runtime.scenes.errors import IgnoredValueWarning
    from apexseal.runtime.scenes.scene import default_scene_text

    text = default_scene_text().replace("zeta_w = 0.1 ", "zeta_w = 3   ")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        line = _line_after()
        default_scene.with_overrides(**{"contacts.zeta_w": 3})
        Scene.from_toml_string(text, default_scene.source_path.parent)
        load_scene(overrides={"contacts.zeta_w": 3})
        default_scene.with_overrides(**{"effects.groove_friction": False, "friction.mu2": 1.5})
    assert [(w.category, w.filename, w.lineno) for w in caught] == [
        (PlausibilityWarning, __file__, line), (PlausibilityWarning, __file__, line + 1),
        (PlausibilityWarning, __file__, line + 2), (IgnoredValueWarning, __file__, line + 3)]


def _line_after() -> int:
    """The number of the line after the caller's."""
    import sys

    return sys._getframe(1).f_lineno + 1


@pytest.mark.parametrize("key, value, shown", [
    ("gas.p_supply", 1e9, "1e+06 kPa"), ("gas.p_exhaust", "1e9 Pa", "1e+06 kPa"), ("gas.T_supply", 1e5, "100000 K"),
    ("gas.T_exhaust", "1e-3 K", "0.001 K"), ("gas.R", 8.314, "8.314 J/(kg*K)"), ("gas.gamma", 1.95, "1.95 is")])
def test_a_gas_value_far_outside_practice_warns(default_scene, key, value, shown):
    """The [gas] keys had no plausible range: a supply pressure of 1e9 Pa (a unit slip) loaded without a word, and its
    run spent a minute in two integrator calls (docs/hard-cases.md)."""
    with pytest.warns(PlausibilityWarning, match=rf"{key}.*{re.escape(shown)}.*far outside engineering practice"):
        default_scene.with_overrides(**{"pressure": {"source": "chamber"}, key: value})


def test_the_gas_scene_is_plausible_and_its_keys_unread_elsewhere_are_not_questioned(default_scene):
    """The shipped gas scene warns of nothing, and a [gas] value no law reads (the pressure from a table) neither."""
    import apexseal

    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        apexseal.load_scene(REPO / "runtime" / "scenes" / "expander-gas.toml")
        default_scene.with_overrides(**{"gas.p_supply": 1e9})


def test_a_pressure_table_in_bar_declared_in_kpa_warns(default_scene, tmp_path):
    """A table in bar declared unit = "kPa" (chamber pressures 1.2-8 kPa, far below atmospheric for an expander)
    loaded silently: only unit = "Pa" warned, below 1000 Pa. A table all below 20 kPa warns, and names the unit
    that makes its numbers plausible."""
    table = tmp_path / "bar.csv"
    table.write_text("theta_deg,Pa,Pb\n0,1.2,8\n180,8,1.2\n")
    with pytest.warns(PlausibilityWarning, match=r'pressure\.unit.*1200\.\.8000 Pa \(unit = "kPa"\), all below '
                      r'20000 Pa.*1\.2\.\.8 bar: is the table in bar \(unit = "bar"\)\?'):
        default_scene.with_overrides(**{"pressure.file": str(table), "pressure.unit": "kPa"})
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        default_scene.with_overrides(**{"pressure.file": str(table), "pressure.unit": "bar"})


def test_a_pressure_table_without_its_unit_is_told_the_unit_that_lifts_it(default_scene, tmp_path):
    """A table in bar with its unit left out (read in Pa: 1-4 Pa) was asked whether it is in "Pa", "kPa" or "bar",
    the unit in use first and kPa, still a vacuum; the warning names bar, the unit that lifts it above atmospheric."""
    table = tmp_path / "bar.csv"
    table.write_text("theta_deg,Pa,Pb\n0,1,4\n180,4,1\n")
    with pytest.warns(PlausibilityWarning, match=r'1\.\.4 Pa, below 1000 Pa .*read in bar, its numbers would span '
                      r'1\.\.4 bar: is the table in bar \(unit = "bar"\)\?') as caught:
        default_scene.with_overrides(**{"pressure.file": str(table)})
    assert not any('"kPa"' in str(w.message) for w in caught)
    table.write_text("theta_deg,Pa,Pb\n0,0.005,4\n180,4,1\n")  # one row too low in a table in bar: no unit slip
    with pytest.warns(PlausibilityWarning, match=r'is the table in another unit \(unit = "Pa", "kPa", "bar", "MPa"\)'):
        default_scene.with_overrides(**{"pressure.file": str(table), "pressure.unit": "bar"})
    table.write_text("theta_deg,Pa,Pb\n0,1e5,4e5\n180,4e5,1e5\n")  # in Pa, declared in bar: read in Pa, it fits
    with pytest.warns(PlausibilityWarning, match=r'above 1e\+08 Pa .*: is the table in Pa \(unit = "Pa"\)\?'):
        default_scene.with_overrides(**{"pressure.file": str(table), "pressure.unit": "bar"})


def test_a_pressure_table_in_radians_warns(default_scene, tmp_path):
    """A table whose angles were written in radians (0..6.1 under theta_deg) loaded without a word: the whole cycle
    ran in the first 6 degrees, a linear ramp back over the rest. It warns, naming the file and the factor."""
    table = tmp_path / "rad.csv"
    table.write_text("theta_deg,Pa,Pb\n0,1e5,4e5\n3.1,4e5,1e5\n6.1,2e5,2e5\n")
    with pytest.warns(PlausibilityWarning, match=r"pressure\.file = .*rad\.csv.*angles span 0\.\.6\.1 deg, no more "
                      r"than 2 pi.*radians \(multiply them by 180/pi\)"):
        default_scene.with_overrides(**{"pressure.file": str(table)})
    table.write_text("theta_deg,Pa,Pb\n-3.1416,1e5,4e5\n0,4e5,1e5\n3.1,2e5,2e5\n")  # radians from -pi
    with pytest.warns(PlausibilityWarning, match=r"angles span -3\.142\.\.3\.1 deg"):
        default_scene.with_overrides(**{"pressure.file": str(table)})
    for rows in ("0,1e5,4e5\n180,4e5,1e5\n", "-180,1e5,4e5\n-90,4e5,1e5\n0,2e5,2e5\n"):  # degrees, from -180 too
        table.write_text("theta_deg,Pa,Pb\n" + rows)
        with warnings.catch_warnings():
            warnings.simplefilter("error", PlausibilityWarning)
            default_scene.with_overrides(**{"pressure.file": str(table)})


def test_a_refused_bare_length_is_asked_whether_it_was_meant_in_mm(default_scene):
    """``zeta0 = 0.6`` (mm meant, 0.6 m read) was refused with its range in mm only, 0.4 mm < zeta0 < 8 mm, where
    0.6 reads as inside it: a key both refused and implausible keeps the implausibility's "did you mean" after the
    refusal."""
    with pytest.raises(SceneError) as info:
        default_scene.with_overrides(**{"seal.zeta0": 0.6})
    (problem,) = info.value.errors
    assert problem.key == "seal.zeta0"
    assert "the seal would leave its groove" in problem.message and 'did you mean "0.6 mm"?' in problem.message


def test_a_spring_stiffness_written_in_n_per_mm_warns(default_scene):
    """``ks = 4`` meant as 4 N/mm (4 N/m read: a preload of 0.01 N) loaded without a word."""
    with pytest.warns(PlausibilityWarning, match=r"spring\.ks = 4: 4 N/m is far outside engineering practice"):
        default_scene.with_overrides(**{"spring.ks": 4})
