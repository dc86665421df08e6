"""Bad input of every kind gets a clear error, and no partial file is presented as a result (docs/bad-input.md).

Each row of the table in docs/bad-input.md is one test here (or names the test elsewhere that covers it). Scene
files are written to a temporary folder from the default scene's text with one edit, and read with load_scene.
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import apexseal
from apexseal.cli import main
from apexseal.generated.manifest import StaleArtefactError, verify
from apexseal.runtime.scenes.errors import IgnoredValueWarning, SceneError
from apexseal.runtime.scenes.scene import default_scene_text, load_scene
from apexseal.runtime.solving import run as sim
from apexseal.runtime.solving.settings import SettingsError

TEXT = default_scene_text()
SCENES_DIR = Path(__file__).resolve().parents[2] / "runtime" / "scenes"
TABLE = "theta_deg,Pa,Pb\n0,1e5,2e5\n90,3e5,2e5\n180,1e5,2e5\n270,3e5,2e5\n"

# id, (old, new) edit of the default scene's text, fragments of the error
SCENE_FILES = [
    ("toml-unquoted-unit", ('r = "10 mm"', "r = 10 mm"), ["malformed TOML at line", "must be a quoted string"]),
    ("toml-unclosed-string", ('L = "50 mm"', 'L = "50 mm'), ["malformed TOML at line"]),
    ("toml-duplicate-key", ('L = "50 mm"', 'L = "50 mm"\nL = "60 mm"'), ["malformed TOML"]),
    ("toml-unclosed-table", ("[spring]", "[spring"), ["malformed TOML"]),
    ("empty-file", (TEXT, ""), ["required section [machine] is missing",
                                "contacts.kw = (missing): required while effects.housing_contact is on"]),
    ("unknown-key", ('kw = "1e9 N/m"', 'kw = "1e9 N/m"\ncww = 1'), ["contacts.cww", "unknown key", "'cw'"]),
    ("unknown-section", ("[friction]", "[fricton]"), ["unknown section", "'friction'"]),
    ("wrong-unit", ('ks = "5e3 N/m"', 'ks = "5e3 mm"'), ["spring.ks", "wrong unit", "N/m"]),
    ("angle-without-unit", ('start_angle = "0 deg"', "start_angle = 30"), ["operation.start_angle", "give a unit"]),
    ("speed-in-hertz", ('rpm = "1500 rpm"', 'rpm = "25 Hz"'), ["operation.rpm", "Hz carries no angle"]),
    ("unknown-unit", ('Ws = "3.0 mm"', 'Ws = "3.0 mmm"'), ["seal.Ws", "unknown unit 'mmm'"]),
    ("decimal-comma", ('Ws = "3.0 mm"', 'Ws = "3,0 mm"'), ["seal.Ws", "decimal point"]),
    ("nan-value", ('Ws = "3.0 mm"', "Ws = nan"), ["seal.Ws", "must be finite"]),
    ("negative-stiffness", ('kw = "1e9 N/m"', "kw = -5"), ["contacts.kw", "out of range", "> 0 N/m"]),
    ("friction-of-one", ("mu1 = 0.10", "mu1 = 1.0"), ["friction.mu1", "0 <= value < 1"]),
    ("zero-speed", ('rpm = "1500 rpm"', "rpm = 0"), ["operation.rpm", "out of range"]),
    ("too-many-samples", ("samples_per_revolution = 3600", "samples_per_revolution = 200000"),
     ["solver.samples_per_revolution", "36 <= n <= 100000"]),
    ("tolerance-out-of-range", ("rtol = 1e-6", "rtol = 0.1"), ["solver.rtol", "1e-12 <= value <= 0.01"]),
    ("zero-calls-per-revolution", ("rtol = 1e-6", "rtol = 1e-6\ncalls_per_revolution = 0"),
     ["solver.calls_per_revolution", "1 <= n <= 100000"]),
    ("unknown-method", ('method = "erk"', 'method = "cvode"'), ["solver.method", "did you mean 'cvodes'"]),
    ("groove-narrower-than-seal", ('Wg = "3.06 mm"', 'Wg = "2.9 mm"'), ["seal.Wg", "groove must be wider"]),
    ("aspect-ratio-above-limit", ('r = "10 mm"', 'r = "20 mm"'), ["machine.r", "exceeds 0.25"]),
    ("tip-arc-too-small", ('ro = "3.0 mm"', 'ro = "1 mm"'), ["seal.ro", "ro >= Ws/2"]),
    ("seal-longer-than-rotor", ('ds2 = "4.0 mm"', 'ds2 = "47 mm"'), ["seal.ds2", "reaches past the chord centre"]),
    ("seal-leaves-groove", ('zeta0 = "0.71 mm"', 'zeta0 = "9 mm"'), ["seal.zeta0", "would leave its groove"]),
    ("groove-mouth-on-tip-arc", ('zeta0 = "0.71 mm"', 'zeta0 = "0.3 mm"'),
     ["seal.zeta0", "mouth would lie on the seal's tip arc", "zeta0 > ro (1 - cos beta_o) = 0.401924 mm"]),
    ("nul-in-table-name", ('file = "expander-pressure.csv"', 'file = "p\\u0000.csv"'),
     ['pressure.file = "p\\u0000.csv": a file name cannot contain a NUL character', "allowed:"]),
    ("three-problems-at-once", ('ks = "5e3 N/m"', 'ks = "-5 N/m"\nkss = 1\ndelta = "3 Hz"'),
     ["3 problems", "spring.ks", "spring.kss", "spring.delta"]),
]

# id, table text, fragments of the error
TABLES = [
    ("table-wrong-header", "theta,Pa,Pb\n0,1,2\n90,1,2\n", ["expected the header 'theta_deg,Pa,Pb'"]),
    ("table-empty-cell", "theta_deg,Pa,Pb\n0,1,2\n90,,2\n", ["line 3", "is not three numbers"]),
    ("table-missing-column", "theta_deg,Pa,Pb\n0,1,2\n90,1\n", ["line 3", "expected 3 comma-separated numbers"]),
    ("table-non-monotonic", "theta_deg,Pa,Pb\n0,1,2\n90,1,2\n45,1,2\n", ["line 4", "below the previous angle"]),
    ("table-repeated-angle", "theta_deg,Pa,Pb\n0,1,2\n90,1,2\n90,3,2\n", ["line 4", "repeats the previous angle"]),
    ("table-nan", "theta_deg,Pa,Pb\n0,1,2\n90,nan,2\n", ["line 3", "Pa = nan is not a finite number"]),
    ("table-inf", "theta_deg,Pa,Pb\n0,1,inf\n90,1,2\n", ["line 2", "Pb = inf is not a finite number"]),
    ("table-negative-pressure", "theta_deg,Pa,Pb\n0,1,2\n90,-5,2\n", ["negative absolute pressure"]),
    ("table-one-row", "theta_deg,Pa,Pb\n0,1,2\n", ["1 data row", "at least 2 rows"]),
    ("table-more-than-a-revolution", "theta_deg,Pa,Pb\n0,1,2\n180,1,2\n360,1,2\n", ["one revolution"]),
    ("table-binary", b"\xff\xfe\x00\x01", ["p.csv"]),
]


def _write_scene(tmp_path: Path, old: str, new: str, table: str | bytes | None = None) -> Path:
    assert old in TEXT
    text = TEXT.replace(old, new)
    if table is not None:
        text = text.replace('file = "expander-pressure.csv"', 'file = "p.csv"')
        (tmp_path / "p.csv").write_bytes(table if isinstance(table, bytes) else table.encode())
    else:
        shutil.copy(SCENES_DIR / "expander-pressure.csv", tmp_path)
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("edit, fragments", [c[1:] for c in SCENE_FILES], ids=[c[0] for c in SCENE_FILES])
def test_bad_scene_file(tmp_path, edit, fragments):
    path = _write_scene(tmp_path, *edit)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    for f in fragments:
        assert f in str(info.value), (f, str(info.value))


@pytest.mark.parametrize("table, fragments", [c[1:] for c in TABLES], ids=[c[0] for c in TABLES])
def test_bad_pressure_table(tmp_path, table, fragments):
    path = _write_scene(tmp_path, "", "", table)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert "pressure.file" in str(info.value)
    for f in fragments:
        assert f in str(info.value), (f, str(info.value))


def test_missing_scene_file(tmp_path):
    with pytest.raises(SceneError, match="file not found"):
        load_scene(tmp_path / "nope.toml")


def test_scene_file_not_utf8(tmp_path):
    (tmp_path / "s.toml").write_bytes(b"\xff\xfe[machine]\n")
    with pytest.raises(SceneError, match="cannot read"):
        load_scene(tmp_path / "s.toml")


def test_a_scene_or_study_saved_with_a_byte_order_mark_loads(tmp_path):
    """An editor's UTF-8 byte-order mark was "malformed TOML at line 1, column 1: Invalid statement" (its pressure
    tables were read with or without one already)."""
    from apexseal.runtime.studies.sweep import load_study

    path = _write_scene(tmp_path, "", "")
    plain = load_scene(path)
    path.write_bytes(b"\xef\xbb\xbf" + path.read_bytes())
    assert load_scene(path).content_hash() == plain.content_hash()
    study = tmp_path / "study.toml"
    study.write_bytes(b"\xef\xbb\xbf" + f'[study]\nname = "bom"\nscene = "{path.name}"\n\n'
                      '[parameters."spring.ks"]\nvalues = ["3e3 N/m"]\n\n[collect]\nquantities = ["revolutions"]\n'
                      .encode())
    assert load_study(study).name == "bom"


def test_missing_pressure_table(tmp_path, monkeypatch):
    """A relative name is taken from the scene file's folder, and the message says so; a path given on the command
    line is the current folder's (made absolute there), and the message said the scene file's folder too."""
    from click.testing import CliRunner

    from apexseal.cli import main

    path = _write_scene(tmp_path, 'file = "expander-pressure.csv"', 'file = "missing.csv"')
    with pytest.raises(SceneError, match="file not found: .*missing.csv \\(a relative path is taken from the scene"):
        load_scene(path)
    monkeypatch.chdir(tmp_path)
    r = CliRunner().invoke(main, ["scene", "--set", "pressure.file=absent.csv"])
    assert r.exit_code != 0 and f"file not found: {tmp_path / 'absent.csv'}" in r.output, r.output
    assert "scene file's folder" not in r.output


#: the one warning of the groove friction's coefficient out of range while that friction is off
IGNORED_MU2 = ("ignored, out of range but read by no law of the scene's model: friction.mu2 = 1.5 (not read while "
               "effects.groove_friction is off; allowed: 0 <= value < 1); switching the effect on makes it an error")


def _groove_friction_off(tmp_path: Path, mu2: str) -> Path:
    path = _write_scene(tmp_path, "mu2 = 0.12", f"mu2 = {mu2}")
    path.write_text(path.read_text().replace("groove_friction = true", "groove_friction = false"))
    return path


def test_an_out_of_range_value_of_an_effect_that_is_off_loads_with_one_warning(tmp_path):
    """A value that no law of the scene's model reads (its effect off) is not range-checked as an error: the file
    loads, with one warning naming the key, its value, the effect that is off and the range. It stopped the scene."""
    path = _groove_friction_off(tmp_path, "1.5")
    with pytest.warns(IgnoredValueWarning) as caught:
        scene = load_scene(path)
    assert [str(w.message) for w in caught if w.category is IgnoredValueWarning] == [f"scene scene.toml: {IGNORED_MU2}"]
    assert scene.friction.mu2 == 1.5 and "mu2" not in scene.parameters
    with pytest.raises(SceneError) as info:  # the same value read: the error it always was
        load_scene(path, overrides={"effects.groove_friction": True})
    assert [str(p) for p in info.value.errors] == ["friction.mu2 = 1.5: 1.5 is out of range; allowed: 0 <= value < 1"]


def test_a_whole_table_of_a_users_submodel_that_is_off_loads_with_one_warning(tmp_path):
    """An in-range [damper] table while effects.damper is off was ignored without a word (only out-of-range values
    warned): one warning names the table, its keys and the switch. Keys left at their defaults, or the effect on,
    say nothing; nor do the built-in tables of the default scene when an override switches their effect off."""
    from apexseal.derive.parameters import Parameter

    damper = _switched_submodel("damper", "a radial damper",
                                Parameter("c_d", "N*s/m", "damping", key="damper.c", default=10.0, ge=0))
    path = _write_scene(tmp_path, "[effects]", '[damper]\nc = "30 N*s/m"\n\n[effects]')
    _warns_once_while_off(damper, path, "scene scene.toml: [damper] is not read: no law reads damper.c while "
                          "effects.damper is off (switch it on to use them, or leave the table out)",
                          silent=({"damper.c": "10 N*s/m"},  # its default
                                  {"effects.spring": False, "effects.spring_damping": False,
                                   "effects.spring_friction": False}))  # a built-in effect off: its keys are read


def test_a_key_of_a_packages_submodel_that_is_off_in_a_built_in_table_warns(tmp_path):
    """A package's key in a built-in table (``contacts.kwp`` while effects.wiper is off), in range, loaded without a
    word: the table's check skipped every table another law reads. Scene loading (the one check both ``apexseal
    scene`` and ``apexseal simulate`` run) now names the key, its value and the switch; at its default it says
    nothing."""
    from apexseal.derive.parameters import Parameter

    wiper = _switched_submodel("wiper", "a wiper ahead of the seal",
                               Parameter("kwp", "N/m", "wiper stiffness", key="contacts.kwp", default=1e4, gt=0))
    path = _write_scene(tmp_path, "[contacts]", '[contacts]\nkwp = "3 kN/m"')
    _warns_once_while_off(wiper, path, 'scene scene.toml: contacts.kwp = "3 kN/m" is not read: no law reads it '
                          "while effects.wiper is off (switch it on to use it, or leave the key out)",
                          silent=({"contacts.kwp": "10 kN/m"},))  # its default


def test_a_key_read_only_under_a_modelling_choice_asks_for_the_choice(tmp_path):
    """A package's key read only under a modelling choice of its own (``needs="wiper_law=cubic"``) warned "switch it
    on to use it" while its submodel was on and the choice not made: the advice of an effect, not of a choice."""
    from apexseal.derive.options import NONE, ON, Option
    from apexseal.derive.parameters import Parameter
    from apexseal.derive.submodels import registry
    from apexseal.derive.submodels.base import Submodel

    wiper = type("Wiper", (Submodel,), {
        "name": "wiper", "__module__": "elsewhere", "switch": "wiper",
        "options": (Option("wiper", (NONE, ON), "a wiper ahead of the seal"),
                    Option("wiper_law", ("linear", "cubic"), "the wiper's law", table="assumptions")),
        "parameters": (Parameter("kwp3", "N/m**3", "cubic stiffness", key="contacts.kwp3", default=1e12, ge=0,
                                 needs="wiper_law=cubic"),)})
    path = _write_scene(tmp_path, "[contacts]", '[contacts]\nkwp3 = "2e12 N/m**3"')
    with registry.registered(wiper):
        with pytest.warns(IgnoredValueWarning) as caught:
            load_scene(path, overrides={"effects.wiper": True})
    assert [str(w.message) for w in caught if w.category is IgnoredValueWarning] == [
        'scene scene.toml: contacts.kwp3 = "2e12 N/m**3" is not read: no law reads it while assumptions.wiper_law '
        "is not 'cubic' (make that choice to use it, or leave the key out)"]


def _switched_submodel(name: str, meaning: str, parameter):
    """A user's submodel (defined elsewhere than apexseal) with one parameter and the option ``name`` that switches
    it on, off by default."""
    from apexseal.derive.options import NONE, ON, Option
    from apexseal.derive.submodels.base import Submodel

    return type(name.title(), (Submodel,), {"name": name, "__module__": "elsewhere", "switch": name,
                                            "options": (Option(name, (NONE, ON), meaning),),
                                            "parameters": (parameter,)})


def _warns_once_while_off(submodel, path, expected: str, silent) -> None:
    """With ``submodel`` registered, loading ``path`` gives exactly the IgnoredValueWarning ``expected``; loading it
    with the submodel switched on, or with each override of ``silent`` (applied to ``path``, or to the default
    scene where it switches a built-in effect off), gives none."""
    import warnings

    from apexseal.derive.submodels import registry

    with registry.registered(submodel):
        with pytest.warns(IgnoredValueWarning) as caught:
            load_scene(path)
        assert [str(w.message) for w in caught if w.category is IgnoredValueWarning] == [expected]
        with warnings.catch_warnings():
            warnings.simplefilter("error", IgnoredValueWarning)
            load_scene(path, overrides={f"effects.{submodel.name}": True})
            for overrides in silent:
                builtin = any(k.startswith("effects.") for k in overrides)
                load_scene(None if builtin else path, overrides=overrides)


def test_the_command_line_loads_it_with_the_same_warning(tmp_path):
    from apexseal.cli import command

    path = _groove_friction_off(tmp_path, "1.5")
    proc = subprocess.run(command("scene", str(path)), capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("scene.toml: valid; content hash ")
    assert proc.stderr == f"warning: scene scene.toml: {IGNORED_MU2} (IgnoredValueWarning)\n"
    proc = subprocess.run(command("scene", str(path), "--set", "effects.groove_friction=true"), capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode != 0 and "friction.mu2 = 1.5: 1.5 is out of range; allowed: 0 <= value < 1" in proc.stderr


@pytest.mark.parametrize("mu2, fragment", [('"0.1 mm"', "wrong unit: expected a plain number, got mm"),
                                            ('"high"', "is not a number"), ("true", "expected a plain number, got bool")],
                         ids=["wrong-dimension", "no-number", "wrong-type"])
def test_a_malformed_value_of_an_effect_that_is_off_is_still_an_error(tmp_path, mu2, fragment):
    """Only the range is left unchecked: a value that is no quantity of its kind is refused, read or not."""
    with pytest.raises(SceneError) as info:
        load_scene(_groove_friction_off(tmp_path, mu2))
    assert info.value.keys() == ["friction.mu2"] and fragment in str(info.value)


def test_missing_pressure_table_while_chamber_pressure_is_off(tmp_path):
    """With effects.chamber_pressure = false no law reads the table: the file is neither needed nor read (a missing
    file stopped the scene); once the effect is on, it is read."""
    path = _write_scene(tmp_path, 'file = "expander-pressure.csv"', 'file = "missing.csv"')
    path.write_text(path.read_text().replace("chamber_pressure = true", "chamber_pressure = false"))
    scene = load_scene(path)
    assert not scene.effects.chamber_pressure
    assert scene.pressure.to_dict() == {"source": "table", "file": "missing.csv", "unit": "Pa"}
    (tmp_path / "missing.csv").write_text("not a table\n")  # there, but not read either
    assert load_scene(path).content_hash() == scene.content_hash()
    with pytest.raises(SceneError, match="missing.csv line 1: expected the header"):  # read once the effect is on
        load_scene(path, overrides={"effects.chamber_pressure": True})


@pytest.mark.slow  # 11 s of a 2-core test process: in the second step, to keep the default suite under 10 min
def test_a_scene_whose_missing_table_no_law_reads_runs_and_its_result_names_the_table(tmp_path):
    """The run of such a scene completes, and its result's scene names the table without it and loads as the scene
    that ran."""
    path = _write_scene(tmp_path, 'file = "expander-pressure.csv"', 'file = "missing.csv"')
    path.write_text(path.read_text().replace("chamber_pressure = true", "chamber_pressure = false"))
    scene = load_scene(path)
    r = apexseal.simulate(scene, revolutions=1, samples_per_revolution=360, out=tmp_path / "run")
    assert r.status == "completed"
    assert not (tmp_path / "run" / "pressure.csv").exists()
    saved = (tmp_path / "run" / "scene.toml").read_text()
    assert "# missing.csv was not found or not valid beside the scene that ran" in saved
    assert load_scene(tmp_path / "run" / "scene.toml").content_hash() == r.scene.content_hash()


def test_a_table_no_law_read_is_kept_beside_the_result_when_it_is_there(tmp_path):
    """With the chamber pressure off the table is not read for the run, but a result's scene.toml re-runs the scene
    with the effect switched back on: the table, when its file is there, is written beside it as a read table's is
    (it was named relative to the scene that ran, where the result's folder does not find it)."""
    path = _write_scene(tmp_path, "", "")  # the table beside it
    path.write_text(path.read_text().replace("chamber_pressure = true", "chamber_pressure = false"))
    scene = load_scene(path)
    r = apexseal.simulate(scene, revolutions=1, samples_per_revolution=90, out=tmp_path / "run")
    assert r.status == "completed" and (tmp_path / "run" / "pressure.csv").exists()
    saved = load_scene(tmp_path / "run" / "scene.toml")
    assert saved.content_hash() == r.scene.content_hash()
    on = {"effects.chamber_pressure": True}
    assert load_scene(tmp_path / "run" / "scene.toml", overrides=on) == r.scene.with_overrides(**on)


def test_table_with_a_wide_angular_gap_is_accepted_and_interpolated_across(tmp_path):
    """Not an error: rows need not be dense; the table is linear (and periodic) across any gap."""
    path = _write_scene(tmp_path, "", "", "theta_deg,Pa,Pb\n0,1e5,1e5\n10,2e5,1e5\n")
    scene = load_scene(path)
    Pa = np.asarray(scene.pressure(np.radians([5.0, 185.0])), float)[0]
    assert Pa == pytest.approx([1.5e5, 1.5e5])


# ---------------------------------------------------------------- the run API
@pytest.mark.parametrize("key, fragments, inside", [
    ("seal.ms", ["seal.ms = 1e+300: 1e+303 g is heavier than the seal's outline", "osmium",
                 "allowed: ms <= 54.1618 g"], {"seal.ms": "54 g"}),
    ("seal.density", ["seal.density = 1e+300: 1e+300 kg/m^3 is out of range; allowed: 0 < value <= 22590 kg/m^3"],
     {"seal.density": "22000 kg/m^3"}),
    ("seal.Icg", ["seal.Icg = 1e+300: 1e+300 kg*m^2 would put mass farther from the centre of gravity than the "
                  "seal's farthest corner", "allowed: Icg <= ms (max(ds1, ds2)^2 + Ws^2/4) = 3.15045e-07 kg*m^2"],
     {"seal.Icg": 3.1e-7}),
    ("friction.v_eps", ["friction.v_eps = 1e+300: 1e+300 m/s is not below the tip's fastest sliding speed",
                        "allowed: 0 < v_eps < 10.9956 m/s"], {"friction.v_eps": "10 m/s"}),
    ("operation.periodic_tol", ["operation.periodic_tol = 1e+300: 1e+300 is out of range; allowed: 0 < value < 1"],
     {"operation.periodic_tol": 0.5}),
], ids=lambda v: v if isinstance(v, str) else "")
@pytest.mark.filterwarnings("ignore::apexseal.runtime.scenes.units.PlausibilityWarning")
def test_a_value_no_seal_or_run_can_have_is_refused_naming_key_value_and_range(key, fragments, inside):
    """1e300 for these loaded, and the run failed naming no key (ms, density) or completed silently (Icg: a seal
    that cannot turn; v_eps: friction that is a viscous damper; periodic_tol: any revolution is "periodic"). An
    unusual value inside the bound still loads."""
    with pytest.raises(SceneError) as caught:
        load_scene(None, overrides={key: 1e300})
    assert all(f in str(caught.value) for f in fragments), str(caught.value)
    load_scene(None, overrides=inside)


def test_a_cross_key_bound_on_a_value_no_law_reads_is_ignored_as_its_range_is():
    """friction.v_eps above the tip's fastest sliding speed stopped a scene with every friction law off, which reads
    no v_eps: its bound against machine.L, machine.r and operation.rpm was checked whatever the effects, unlike
    the key's own range. Now it is an ignored value, named with the bound; with a friction law on, the error."""
    off = {f"effects.{name}_friction": False for name in ("housing", "spring", "groove")}
    with pytest.warns(IgnoredValueWarning) as caught:
        scene = load_scene(None, overrides={**off, "friction.v_eps": "20 m/s"})
    (warning,) = [str(w.message) for w in caught if w.category is IgnoredValueWarning]
    assert "friction.v_eps = \"20 m/s\" (not read while" in warning and "allowed: 0 < v_eps < 10.9956 m/s" in warning
    assert scene.friction.v_eps == 20 and "v_eps" not in scene.parameters
    with pytest.raises(SceneError, match="friction.v_eps = \"20 m/s\": 20 m/s is not below the tip's fastest"):
        load_scene(None, overrides={**off, "effects.groove_friction": True, "friction.v_eps": "20 m/s"})


def test_unknown_method_in_the_api(default_scene, default_functions):
    with pytest.raises(SettingsError, match="method = \"cvode\": not a method \\(did you mean 'cvodes'\\?\\); allowed: erk"):
        apexseal.simulate(default_scene, method="cvode", functions=default_functions.sx)


def test_engine_that_does_not_divide_the_revolution(default_scene, default_functions):
    fns = default_functions.sx
    st = sim.RunSettings(samples_per_revolution=72, compile_c=False)
    engine = sim.make_engine(fns, st, n_samples=7, span=7 * 2 * np.pi / 72)
    with pytest.raises(ValueError, match="do not divide samples_per_revolution = 72"):
        sim.run(fns, default_scene.parameter_vector(), st, theta_start=0.0, state0=np.zeros(6), revolutions=1,
                engine=engine)


def test_nan_parameter_through_the_api(default_scene, default_functions):
    """Scenes refuse NaN; the lower-level run refuses it too, before the first step, with the reason."""
    p = default_scene.parameter_vector()
    p[3] = np.nan
    r = sim.run(default_functions.sx, p, sim.RunSettings(compile_c=False), theta_start=0.0, state0=np.zeros(6),
                revolutions=1, pressure=default_scene.pressure)
    assert r.status == "failed" and r.n == 1 and "not finite" in r.stop.reason


# ---------------------------------------------------------------- the command line and the output folder
def test_cli_output_folder_is_a_file(tmp_path):
    blocker = tmp_path / "out"
    blocker.write_text("a file")
    r = CliRunner().invoke(main, ["simulate", "--out", str(blocker), "-q"])
    assert r.exit_code != 0 and "--out" in r.output
    assert blocker.read_text() == "a file"


def test_cli_output_folder_cannot_be_created(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    r = CliRunner().invoke(main, ["simulate", "--out", str(blocker / "sub"), "-q"])
    assert r.exit_code != 0 and "cannot create the output folder" in r.output
    assert list(tmp_path.iterdir()) == [blocker]


def test_cli_bad_scene_writes_nothing(tmp_path):
    path = _write_scene(tmp_path, 'kw = "1e9 N/m"', "kw = -5")
    r = CliRunner().invoke(main, ["simulate", str(path), "--out", str(tmp_path / "o"), "-q"])
    assert r.exit_code != 0 and "contacts.kw" in r.output
    assert not (tmp_path / "o").exists()


def test_cli_option_out_of_range(tmp_path):
    r = CliRunner().invoke(main, ["simulate", "--rtol", "0.5", "--out", str(tmp_path / "o")])
    assert r.exit_code != 0 and "--rtol" in r.output
    assert not (tmp_path / "o").exists()


def test_cli_run_that_cannot_start_is_labelled_failed(tmp_path):
    """A run refused before its first step (explicit Euler on a 1e10 N/m contact it would amplify): exit code 2,
    the reason on stderr, and the files say status 'failed' (nothing presented as a completed result)."""
    hard = SCENES_DIR / "hard" / "stiff-housing-1e10.toml"
    out = tmp_path / "o"
    r = CliRunner().invoke(main, ["simulate", str(hard), "--method", "euler", "--out", str(out), "-q"])
    assert r.exit_code == 2
    assert "explicit Euler amplifies" in r.output
    assert json.loads((out / "result.json").read_text())["status"] == "failed"
    assert json.loads((out / "summary.json").read_text())["status"] == "failed"


@pytest.mark.filterwarnings("ignore::apexseal.runtime.results.plausibility.PenetrationWarning")
def test_cli_run_that_stops_midway_exits_2_and_keeps_what_it_computed(tmp_path):
    """A run that stops after its first step (tip-chatter: the tip chatters on the housing within a revolution):
    exit code 2, the stop reason on stderr, and a result of status 'chattering' holding the samples computed before
    (only a run refused before its first step was checked for its exit code)."""
    out = tmp_path / "o"
    r = CliRunner().invoke(main, ["simulate", str(SCENES_DIR / "hard" / "tip-chatter.toml"), "-n", "1", "--no-figures",
                                  "--out", str(out), "-q"])
    assert r.exit_code == 2 and "chattering on guard xs5" in r.output
    record = json.loads((out / "result.json").read_text())
    assert record["status"] == "chattering" and record["samples"] > 1
    assert json.loads((out / "summary.json").read_text())["status"] == "chattering"


# ---------------------------------------------------------------- generated artefacts
def test_corrupted_generated_c_file(artefacts):
    """One flipped bit in a generated C file: detected by its sha256 (regeneration and library rebuild:
    tests/generated/test_gen_artefacts.py::test_stale_default_is_regenerated_into_the_cache,
    tests/generated/test_gen_compile.py::test_modified_library_is_rebuilt)."""
    path = artefacts / "casadi_model.c"
    data = bytearray(path.read_bytes())
    data[len(data) // 3] ^= 0x04
    path.write_bytes(bytes(data))
    with pytest.raises(StaleArtefactError, match="casadi_model.c differs from the manifest"):
        verify(artefacts)


def test_truncated_manifest(artefacts):
    path = artefacts / "manifest.json"
    path.write_text(path.read_text()[:100])
    with pytest.raises(StaleArtefactError, match="unreadable manifest.json"):
        verify(artefacts)
