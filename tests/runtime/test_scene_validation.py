"""Every validation error a scene can raise names the key, the value given and what is allowed.

Each case changes the default scene (``with_overrides``) and checks the one
problem it provokes: its line ``key = value: message`` in the SceneError, and
fragments of the message that state the allowed range (or the allowed values).
"""

import re
from pathlib import Path

import pytest

from apexseal.runtime.scenes.errors import MISSING, Problem, SceneError
from apexseal.runtime.scenes.scene import Scene, load_scene
from apexseal.runtime.scenes.schema import SECTIONS

#: the pressure section switched to constant pressures (the table keys removed)
CONSTANT = {
    "pressure.source": "constant",
    "pressure.file": None,
    "pressure.unit": None,
    "pressure.Pa": "6 bar",
    "pressure.Pb": "1 bar",
}

#: the pressure section switched to the chamber gas model (which needs positive chamber volumes)
GAS = {"pressure.source": "chamber", "pressure.file": None, "pressure.unit": None}

# id, overrides, key, value as shown, fragments of the message (the last ones state what is allowed)
CASES = [
    # units and types
    (
        "wrong-dimension",
        {"spring.ks": "3 mm"},
        "spring.ks",
        '"3 mm"',
        ["wrong unit", "expected a stiffness in N/m", "got mm"],
    ),
    (  # a unit that had no word: "expected a quantity in K (e.g. K)"
        "wrong-dimension-of-a-temperature",
        {**GAS, "gas.T_supply": "300 m"},
        "gas.T_supply",
        '"300 m"',
        ['expected a temperature in K (e.g. "300 K"), got m'],
    ),
    (
        "angle-without-unit",
        {"operation.start_angle": 30},
        "operation.start_angle",
        "30",
        ["give a unit: deg or rad"],
    ),
    (
        "angle-string-without-unit",
        {"machine.ports.inlet.angle": "-25"},
        "machine.ports.inlet.angle",
        '"-25"',
        ["give a unit: deg or rad"],
    ),
    (
        "angular-speed-without-unit",
        {"operation.initial_state.phid": 0},
        "operation.initial_state.phid",
        "0",
        ["give a unit: deg or rad"],
    ),
    (
        "speed-without-angle",
        {"operation.rpm": "25 Hz"},
        "operation.rpm",
        '"25 Hz"',
        ["ambiguous", "rotational speed in rpm", "use rpm, rev/s, rad/s or deg/s"],
    ),
    ("unknown-unit", {"seal.Ws": "3 mmm"}, "seal.Ws", '"3 mmm"', ["unknown unit 'mmm'", "length in m"]),
    ("unreadable-quantity", {"seal.Ws": "3 (mm"}, "seal.Ws", '"3 (mm"', ["cannot read", "length in m"]),
    ("two-numbers", {"seal.Ws": "3 mm 4"}, "seal.Ws", '"3 mm 4"', ["one number, then its unit", "length in m"]),
    ("unit-without-number", {"seal.Ws": "mm"}, "seal.Ws", '"mm"', ["needs a number first", "length in m"]),
    ("decimal-comma", {"seal.Ws": "3,0 mm"}, "seal.Ws", '"3,0 mm"', ["decimal point", "length in m"]),
    ("not-finite", {"seal.Ws": float("inf")}, "seal.Ws", "inf", ["finite", "length in m"]),
    ("bool-for-quantity", {"seal.Ws": True}, "seal.Ws", "true", ["got bool", "length in m"]),
    (
        "float-for-integer",
        {"solver.samples_per_revolution": 720.0},
        "solver.samples_per_revolution",
        "720.0",
        ["expected an integer", "36 <= n <= 100000"],
    ),
    (
        "bool-for-integer",
        {"operation.revolutions": True},
        "operation.revolutions",
        "true",
        ["expected an integer", "1 <= n <= 100000"],
    ),
    (
        "integer-too-small",
        {"operation.revolutions": 0},
        "operation.revolutions",
        "0",
        ["out of range", "allowed: 1 <= n <= 100000"],
    ),
    (
        "integer-too-large",
        {"solver.samples_per_revolution": 200000},
        "solver.samples_per_revolution",
        "200000",
        ["out of range", "allowed: 36 <= n <= 100000"],
    ),
    ("chatter-events", {"solver.chatter_events": 1}, "solver.chatter_events", "1", ["allowed: 2 <= n <= 1e+08"]),
    (
        "unknown-choice",
        {"solver.method": "cvode"},
        "solver.method",
        '"cvode"',
        ["not allowed (did you mean 'cvodes'?); allowed: \"erk\"", '"euler"'],
    ),
    (
        "unknown-embodiment",
        {"machine.embodiment": "limacon"},
        "machine.embodiment",
        '"limacon"',
        ['allowed: "limacon-to-limacon", "circolimacon", "limacon-to-circular"'],
    ),
    (
        "unknown-compile",
        {"solver.compile": "optimized"},
        "solver.compile",
        '"optimized"',
        ["did you mean 'optimised'?", 'allowed: "quick", "optimised"'],
    ),
    (
        "string-for-flag",
        {"solver.interpreted": "no"},
        "solver.interpreted",
        '"no"',
        ["expected true or false"],
    ),
    (
        "number-for-flag",
        {"operation.until_periodic": 0},
        "operation.until_periodic",
        "0",
        ["expected true or false"],
    ),
    ("number-for-effect", {"effects.spring": 1}, "effects.spring", "1", ["expected true or false"]),
    (
        "unknown-assumption-value",
        {"assumptions.damping": "alway"},
        "assumptions.damping",
        '"alway"',
        ["did you mean 'always'?", 'allowed: "in-contact", "always"'],
    ),
    ("empty-file-name", {"pressure.file": ""}, "pressure.file", '""', ["expected a non-empty string"]),
    (
        "pressure-unit",
        {"pressure.unit": "m"},
        "pressure.unit",
        '"m"',
        ["wrong unit", "pressure unit", '"bar"'],
    ),
    # ranges
    (
        "negative-length",
        {"seal.Ws": "-3 mm"},
        "seal.Ws",
        '"-3 mm"',
        ["-0.003 m is out of range", "allowed: > 0 m"],
    ),
    ("zero-length", {"machine.L": 0}, "machine.L", "0", ["out of range", "allowed: > 0 m"]),
    (
        "negative-stiffness",
        {"contacts.kw": -5},
        "contacts.kw",
        "-5",
        ["-5 N/m is out of range", "allowed: > 0 N/m"],
    ),
    ("negative-spring", {"spring.ks": "-5e3 N/m"}, "spring.ks", '"-5e3 N/m"', ["allowed: > 0 N/m"]),
    ("zero-groove-stiffness", {"contacts.kg3": 0}, "contacts.kg3", "0", ["allowed: > 0 N/m"]),
    ("negative-damping", {"contacts.cw": -1}, "contacts.cw", "-1", ["allowed: >= 0 N*s/m"]),
    ("negative-preload", {"spring.delta_s": "-1 mm"}, "spring.delta_s", '"-1 mm"', ["allowed: >= 0 m"]),
    ("negative-clearance", {"machine.Cr": "-1 mm"}, "machine.Cr", '"-1 mm"', ["allowed: >= 0 m"]),
    (
        "friction-one",
        {"friction.mu1": 1.0},
        "friction.mu1",
        "1.0",
        ["1 is out of range", "allowed: 0 <= value < 1"],
    ),
    ("friction-negative", {"friction.mu2": -0.1}, "friction.mu2", "-0.1", ["allowed: 0 <= value < 1"]),
    ("friction-regularisation", {"friction.v_eps": 0}, "friction.v_eps", "0", ["allowed: > 0 m/s"]),
    (
        "negative-density",
        {"seal.density": "-7200 kg/m^3"},
        "seal.density",
        '"-7200 kg/m^3"',
        ["allowed: 0 < value <= 22590 kg/m^3"],
    ),
    ("negative-mass", {"seal.ms": "-1 g"}, "seal.ms", '"-1 g"', ["allowed: > 0 kg"]),
    ("zero-inertia", {"seal.Icg": 0}, "seal.Icg", "0", ["allowed: > 0 kg*m^2"]),
    ("negative-zeta0", {"seal.zeta0": "-0.1 mm"}, "seal.zeta0", '"-0.1 mm"', ["allowed: >= 0 m"]),
    ("zero-speed", {"operation.rpm": 0}, "operation.rpm", "0", ["allowed: > 0 rpm"]),
    ("periodic-tolerance", {"operation.periodic_tol": 0}, "operation.periodic_tol", "0", ["allowed: 0 < value < 1"]),
    (
        "port-width",
        {"machine.ports.outlet.width": "200 deg"},
        "machine.ports.outlet.width",
        '"200 deg"',
        ["200 deg is out of range", "allowed: 0 < value < 180 deg"],
    ),
    ("rtol", {"solver.rtol": 0.1}, "solver.rtol", "0.1", ["allowed: 1e-12 <= value <= 0.01"]),
    ("atol", {"solver.atol": -1e-9}, "solver.atol", "-1e-09", ["allowed: 0 < value <= 1"]),
    ("event-tolerance", {"solver.event_tol": "0 rad"}, "solver.event_tol", '"0 rad"', ["allowed: 0 < value <= 1e-06 rad"]),
    (
        "chatter-window",
        {"solver.chatter_window": "-1 deg"},
        "solver.chatter_window",
        '"-1 deg"',
        ["allowed: 0 < value <= 6.28319 rad"],
    ),
    (
        "negative-pressure",
        {**CONSTANT, "pressure.Pa": "-1 bar"},
        "pressure.Pa",
        '"-1 bar"',
        ["allowed: >= 0 Pa"],
    ),
    # structure
    (
        "unknown-key",
        {"contacts.kww": 1},
        "contacts.kww",
        "1",
        ["unknown key (did you mean 'kw'?); known: kw, kg1, kg2, kg3, kg4, cw, cr, cs, zeta_w, zeta_g, zeta_s"],
    ),
    (
        "unknown-nested-key",
        {"operation.initial_state.phii": "0 deg"},
        "operation.initial_state.phii",
        '"0 deg"',
        ["did you mean 'phi'?", "known: x, y, phi, xd, yd, phid"],
    ),
    (
        "unknown-effect",
        {"effects.inertial": True},
        "effects.inertial",
        "true",
        ["did you mean 'inertia'?", "known: inertia, housing_contact"],
    ),
    (
        "unknown-section",
        {"sael.Ws": 3},
        "sael",
        "{Ws = 3}",  # as TOML writes an inline table (a Python dict before)
        ["unknown section (did you mean 'seal'?); if it is a submodel's, its package is not installed here "
         "(apexseal scene lists those that are); known: machine, operation, seal"],
    ),
    ("top-level-key", {"title": "x"}, "title", '"x"', ["unknown top-level key", "known: machine"]),
    ("missing-key", {"seal.Ws": None}, "seal.Ws", MISSING, ["required; give a length in m", "> 0 m"]),
    (
        "missing-nested-key",
        {"machine.ports.inlet.length": None},
        "machine.ports.inlet.length",
        MISSING,
        ["required; give a length in m"],
    ),
    (
        "missing-port",
        {"machine.ports.inlet": None},
        "machine.ports.inlet",
        MISSING,
        ["required; give a table with keys angle, width, length"],
    ),
    ("missing-section", {"machine": None}, "machine", MISSING, ["required section [machine] is missing"]),
    (
        "missing-key-of-an-effect-on",
        {"friction.mu2": None},
        "friction.mu2",
        MISSING,
        ["required while effects.groove_friction is on; give a plain number, 0 <= value < 1, or set "
         "effects.groove_friction = false"],
    ),
    ("section-not-a-table", {"seal": 5}, "seal", "5", ["expected a table: [seal]"]),
    ("key-not-a-table", {"operation.initial_state": 3}, "operation.initial_state", "3", ["expected a table"]),
    # physical consistency
    (
        "aspect-ratio",
        {"machine.r": "20 mm"},
        "machine.r",
        '"20 mm"',
        ["b = r/L = 0.4 exceeds 0.25", "Eq. 4", "allowed: r <= 0.25 L = 12.5 mm"],
    ),
    (
        "lobe-clearance",
        {"machine.embodiment": "circolimacon", "machine.Cr": "60 mm"},
        "machine.Cr",
        '"60 mm"',
        ["Eq. 5", "allowed: 0 <= Cr < L = 50 mm"],
    ),
    (
        "circular-lobe-reaches-the-housing",
        {"machine.embodiment": "circolimacon", "machine.k": "10 mm", **GAS},
        "machine.k",
        '"10 mm"',
        ["chamber b's volume reaches -60.53 cm^3 (<= 0) at theta = 0 deg", "Eqs. 1-8",
         "allowed: k > 19.7732 mm for machine.r = 10 mm, machine.L = 50 mm, machine.Cr = 0.1 mm"],
    ),
    (
        "limacon-lobe-without-clearance",
        {"machine.Cr": "0 mm", **GAS},
        "machine.Cr",
        '"0 mm"',
        ["volume reaches 0 cm^3 (<= 0)", "allowed: 0 < Cr < 2 L - 8 r / pi = 74.5352 mm"],
    ),
    (
        "port-longer-than-machine",
        {"machine.ports.inlet.length": "0.2 m", **GAS},
        "machine.ports.inlet.length",
        '"0.2 m"',
        ["allowed: <= machine.H = 100 mm"],
    ),
    (
        "groove-narrower",
        {"seal.Wg": "2.9 mm"},
        "seal.Wg",
        '"2.9 mm"',
        ["groove must be wider than the seal", "allowed: Wg > seal.Ws = 3 mm"],
    ),
    ("groove-equal", {"seal.Wg": "3 mm"}, "seal.Wg", '"3 mm"', ["allowed: Wg > seal.Ws = 3 mm"]),
    ("tip-radius", {"seal.ro": "1 mm"}, "seal.ro", '"1 mm"', ["Eq. 24", "allowed: ro >= Ws/2 = 1.5 mm"]),
    (  # the groove's mouth on the tip arc: the side gap and the side face's area of the model were wrong there
        "mouth-on-tip-arc",
        {"seal.zeta0": "0.3 mm"},
        "seal.zeta0",
        '"0.3 mm"',
        ["mouth would lie on the seal's tip arc", "l1 = ds0 + zeta0 - ds1 = -0.101924 mm",
         "allowed: zeta0 > ro (1 - cos beta_o) = 0.401924 mm for seal.ro = 3 mm"],
    ),
    (  # a semicircular tip (the hard scene tip-arc-edge) with the default's protrusion
        "semicircular-tip-mouth-on-arc",
        {"seal.ro": "1.5 mm"},
        "seal.zeta0",
        '"0.71 mm"',
        ["allowed: zeta0 > ro (1 - cos beta_o) = 1.5 mm for seal.ro = 1.5 mm", "or a larger seal.ro"],
    ),
    (
        "tip-arc-does-not-fit",
        {"seal.ds1": "0.5 mm", "seal.ds2": "0.5 mm", "seal.ro": "1.5 mm", "seal.zeta0": "0.1 mm"},
        "seal.ds1",
        '"0.5 mm"',
        ["ds0 = ds1 - ro (1 - cos beta_o) = -1 mm", "must be > -ds2", "allowed: ds1 > 1 mm"],
    ),
    (
        "seal-taller-than-rotor",
        {"seal.ds2": "47 mm"},
        "seal.ds2",
        '"47 mm"',
        [
            "seal.ds1 + seal.ds2 = 51 mm",
            "groove bottom must lie inside the rotor",
            "allowed: ds1 + ds2 < machine.L = 50 mm",
        ],
    ),
    (
        "zeta0-too-large",
        {"seal.zeta0": "9 mm"},
        "seal.zeta0",
        '"9 mm"',
        ["leave its groove", "allowed: ro (1 - cos beta_o) = 0.401924 mm < zeta0 < ds1 + ds2 = 8 mm"],
    ),
    (
        "zeta0-not-computable",
        {"seal.zeta0": None},
        "seal.zeta0",
        MISSING,
        [
            "truncation z of Eqs. 6-8",
            "-0.581553 mm (<= 0)",
            "give seal.zeta0 explicitly",
            "allowed: ro (1 - cos beta_o) = 0.401924 mm < zeta0 < ds1 + ds2 = 8 mm",
        ],
    ),
    (
        "zeta0-truncation-undefined",
        {"machine.embodiment": "circolimacon", "machine.k": "1 m", "seal.zeta0": None},
        "seal.zeta0",
        MISSING,
        [
            "the groove truncation z of Eqs. 6-8 is undefined",
            "give seal.zeta0 explicitly",
            "allowed: ro (1 - cos beta_o) = 0.401924 mm < zeta0",
        ],
    ),
    (
        "zeta0-truncation-too-deep",
        {"machine.embodiment": "circolimacon", "machine.k": "0.5 m", "seal.zeta0": None},
        "seal.zeta0",
        MISSING,
        [
            "not below ds1 + ds2 = 8 mm",
            "give seal.zeta0 explicitly",
            "allowed: ro (1 - cos beta_o) = 0.401924 mm < zeta0 < ds1 + ds2 = 8 mm",
        ],
    ),
    (
        "density-needed",
        {"seal.density": None},
        "seal.density",
        MISSING,
        ["required to compute seal.ms (Eq. 80)", "kg/m^3"],
    ),
    # pressure source
    (
        "constant-needs-pressure",
        {**CONSTANT, "pressure.Pb": None},
        "pressure.Pb",
        MISSING,
        ['required with source = "constant"', "give a pressure in Pa"],
    ),
    (
        "table-needs-file",
        {"pressure.file": None},
        "pressure.file",
        MISSING,
        ['required with source = "table"', "give a file name"],
    ),
    (
        "key-unused-by-source",
        {"pressure.Pa": "1 bar"},
        "pressure.Pa",
        '"1 bar"',
        ['not used with source = "table"', 'only with source = "constant"'],
    ),
    (
        "unit-unused-by-source",
        {**CONSTANT, "pressure.unit": "bar"},
        "pressure.unit",
        '"bar"',
        ['not used with source = "constant"', 'only with source = "table"'],
    ),
    # effects
    (
        "effect-without-parent",
        {"effects.housing_contact": False, "effects.housing_friction": True},
        "effects.housing_friction",
        "true",
        ["needs effects.housing_contact = true", "allowed: false, or set effects.housing_contact = true"],
    ),
    ("initial-speed-overflow", {"operation.initial_state.xd": "1e300 m/s"}, "operation.initial_state.xd",
     '"1e300 m/s"', ["out of range", "-1000 <= value <= 1000 m/s"]),  # a derivative message blamed parameters
    ("seal-longer-than-machine", {"seal.Bs": "150 mm"}, "seal.Bs", '"150 mm"',
     ["longer than the machine is deep", "machine.H = 100 mm"]),
    ("housing-too-soft-for-the-preload", {"contacts.kw": "1e4 N/m"}, "contacts.kw", '"1e4 N/m"',  # was refused
     ["delta_w = 1000 µm", "allowed: delta_w <= 0.1 Ws = 300 µm", "contacts.kw >= 3.333e+04 N/m",  # at run time only
      "spring.delta_s <= 0.6 mm"]),
    (
        "no-contact-at-all",
        {key: False for key in ("effects.housing_contact", "effects.housing_damping", "effects.housing_friction",
                                "effects.groove_contact", "effects.groove_damping", "effects.groove_friction")},
        "effects.groove_contact",
        "false",
        ["nothing holds the seal", "allowed: true, or set effects.housing_contact = true"],
    ),
    (
        "pressure-effect-without-source",
        {"pressure.source": "none", "pressure.file": None, "pressure.unit": None},
        "effects.chamber_pressure",
        "true",
        ['pressure.source = "none" gives no chamber pressure', "allowed: false"],
    ),
]


@pytest.fixture(scope="module")
def default():
    return load_scene()


def _error(scene, overrides) -> SceneError:
    with pytest.raises(SceneError) as info:
        scene.with_overrides(**overrides)
    return info.value


@pytest.mark.parametrize(
    "overrides, key, shown, fragments", [c[1:] for c in CASES], ids=[c[0] for c in CASES]
)
def test_each_error_names_key_value_and_what_is_allowed(default, overrides, key, shown, fragments):
    err = _error(default, overrides)
    assert err.keys() == [key], str(err)
    (problem,) = err.errors
    line = f"{key} = {shown}: "
    assert line in str(err)
    assert str(problem).startswith(line)
    for fragment in fragments:
        assert fragment in problem.message, (fragment, problem.message)


def test_a_unit_without_a_word_of_its_own_is_shown_with_a_number():
    """A unit no table names (a user's submodel may declare any) is spelled as a value, "1 N*m": the example was the
    bare unit, "(e.g. N*m)", which is not a value a scene takes."""
    from apexseal.runtime.scenes.units import expected

    assert expected("N*m") == 'a quantity in N*m (e.g. "1 N*m")'
    assert expected("N") == 'a force in N (e.g. "5 N")' and expected("W") == 'a power in W (e.g. "60 W")'


def test_errors_are_key_value_message_tuples(default):
    err = _error(default, {"seal.Wg": "2.9 mm"})
    key, value, message = err.errors[0]
    assert (key, value) == ("seal.Wg", "2.9 mm") and "Wg > seal.Ws" in message
    assert isinstance(err, ValueError) and isinstance(err.errors[0], Problem)


def test_every_problem_is_reported_at_once(default):
    err = _error(
        default,
        {
            "seal.Wg": "2.9 mm",
            "spring.ks": "3 mm",
            "contacts.kww": 1,
            "machine.r": "20 mm",
            "solver.method": "rk45",
            "effects.spring": "yes",
        },
    )
    assert sorted(err.keys()) == sorted(
        ["seal.Wg", "spring.ks", "contacts.kww", "machine.r", "solver.method", "effects.spring"]
    )
    lines = str(err).splitlines()
    # the replaced keys are named: the problems are theirs, not the file's (the command line's --set, an API call)
    assert lines[0] == "scene default with seal.Wg, spring.ks, contacts.kww, machine.r, solver.method, effects.spring " \
                       "replaced: 6 problems"
    assert len(lines) == 7 and all(line.startswith("  ") for line in lines[1:])


def test_cross_checks_still_run_when_another_section_is_invalid(default):
    err = _error(default, {"seal.Wg": "2.9 mm", "solver.rtol": "fast"})
    assert set(err.keys()) == {"seal.Wg", "solver.rtol"}


def test_malformed_toml_gives_line_and_column():
    with pytest.raises(SceneError) as info:
        Scene.from_toml_string("[machine]\nr = 3 mm\n")
    (problem,) = info.value.errors
    assert problem.key == "toml" and problem.value == "r = 3 mm"
    assert (
        "line 2, column 7" in problem.message
        and 'must be a quoted string, e.g. r = "3 mm"' in problem.message
    )


def test_malformed_toml_at_end_of_document():
    with pytest.raises(SceneError) as info:
        Scene.from_toml_string("[machine]\nr = ")
    assert "malformed TOML at line 2, column 5: Invalid value" in str(info.value)


def test_duplicate_toml_key():
    """The line is shown in single quotes when it holds double ones ("Ws = "4 mm"" before), with a hint."""
    with pytest.raises(SceneError, match=r"""toml = 'Ws = "4 mm"': malformed TOML at line 3, column 12: Cannot """
                                         r"overwrite a value \(a key or a table given twice\?\)"):
        Scene.from_toml_string('[seal]\nWs = "3 mm"\nWs = "4 mm"\n')


def test_missing_scene_file(tmp_path):
    missing = tmp_path / "nope.toml"
    with pytest.raises(SceneError) as info:
        load_scene(missing)
    assert info.value.errors[0] == ("scene", str(missing), "file not found")


def test_the_default_scene_by_the_name_a_study_file_gives_it(tmp_path):
    """A study file's ``scene = "default"`` is the embedded default, and load_scene("default") was "file not found":
    both now take the name through one resolver (scene_file)."""
    from apexseal.runtime.scenes.scene import scene_file

    assert load_scene("default").content_hash() == load_scene().content_hash()
    assert load_scene("default", overrides={"spring.ks": 1e4}).parameters["ks"] == 1e4
    assert scene_file("default", tmp_path) is None and scene_file("my.toml", tmp_path) == tmp_path / "my.toml"
    with pytest.raises(TypeError, match=r"path = 3: expected the path of a scene file \(str or Path\), or None or "
                                        "'default' for the embedded default"):
        load_scene(3)


def test_unreadable_scene_file(tmp_path):
    with pytest.raises(SceneError) as info:
        load_scene(tmp_path)
    (problem,) = info.value.errors
    assert (problem.key, problem.value) == ("scene", str(tmp_path)) and "cannot read" in problem.message


def test_empty_scene_lists_every_required_section_and_every_key_an_effect_on_needs():
    """Every effect is on by default, so the keys they read are required too; each names the effect."""
    from apexseal.derive.submodels.registry import omissible_while_off, parameters

    with pytest.raises(SceneError) as info:
        Scene.from_toml_string("")
    required = [name for name, (_, req) in SECTIONS.items() if req]
    needed = [p.key for p in parameters(all_inputs=True) if omissible_while_off(p)]
    assert info.value.keys() == required + needed
    assert all(p.value is MISSING for p in info.value.errors)
    assert {"contacts.kw", "spring.ks", "friction.mu2"} <= set(needed)
    for p in info.value.errors[len(required):]:
        assert re.search(r"required while effects\.\w+ is on; give .*, or set effects\.\w+ = false", p.message)


@pytest.mark.parametrize(
    "overrides, fragment",
    [
        ({"seal.Ws.x": 1}, "seal.Ws is a value, not a table"),
        ({"seal..Ws": 1}, "not a key path"),
    ],
)
def test_bad_override_paths(default, overrides, fragment):
    err = _error(default, overrides)
    assert fragment in str(err) and list(overrides)[0] in str(err)


def test_effect_hierarchy_fills_children_of_an_effect_that_is_off(default):
    scene = default.with_overrides(**{"effects": {"housing_contact": False}})
    assert not scene.effects.housing_contact and not scene.effects.housing_friction
    assert scene.effects.groove_contact


def test_an_override_that_switches_an_effect_off_switches_off_the_children_the_scene_switched_on(default):
    """The default scene writes spring_damping = true: `--set effects.spring=false` alone switches the spring off
    with its damping and friction; a child the overrides switch on under it stays an error naming both."""
    assert default.effects.spring_damping and "spring_damping" in default._raw["effects"]
    scene = default.with_overrides(**{"effects.spring": False})
    assert not (scene.effects.spring or scene.effects.spring_damping or scene.effects.spring_friction)
    assert scene.effects.housing_friction and scene.effects.groove_damping
    err = _error(default, {"effects.spring": False, "effects.spring_friction": True})
    assert [p.key for p in err.errors] == ["effects.spring_friction"]
    assert "needs effects.spring = true" in str(err)


def test_a_mass_alone_needs_no_density_and_replaces_the_scene_s(default):
    """A scene giving seal.ms was refused without a density that no law reads (Icg follows from ms); an ms set on top
    of the default scene replaces its density, which stated the mass another way."""
    scene = default.with_overrides(**{"seal.ms": "40 g"})
    assert scene.seal.density is None and scene.parameters["ms"] == pytest.approx(0.04)
    s = scene.seal
    assert scene.parameters["Icg"] == pytest.approx(0.04 * (s.Ws**2 + (s.ds1 + s.ds2) ** 2) / 12)


def test_a_mass_beside_a_density_is_read_and_the_density_is_said_not_to_be(default, tmp_path):
    """The density only computes ms: given beside it, it was silently not read. A scene giving both (a result's
    scene.toml wrote both before the two were paired, and must still load) warns and takes the mass."""
    from apexseal.runtime.scenes.errors import IgnoredValueWarning

    with pytest.warns(IgnoredValueWarning, match=r'seal.density = "7200 kg/m\^3": not read: seal.ms = "40 g" is '
                                                 r"given, and seal.density only computes it"):
        scene = default.with_overrides(**{"seal.ms": "40 g", "seal.density": "7200 kg/m^3"})
    assert scene.parameters["ms"] == pytest.approx(0.04)
    from apexseal.runtime.scenes.resolved import resolved_toml

    text, files = resolved_toml(scene)
    assert "ms = " in text and "density = " not in text  # a result writes the one it read
    # ... and the content hash is that of what it read: the result's scene.toml hashed otherwise, so `apexseal show`
    # called it "not the scene the run computed" and --resume refused the folder
    for name, content in files.items():
        (tmp_path / name).write_text(content)
    (tmp_path / "scene.toml").write_text(text)
    assert load_scene(tmp_path / "scene.toml").content_hash() == scene.content_hash()
    assert scene.content_hash() == default.with_overrides(**{"seal.ms": "40 g"}).content_hash()


def test_an_override_of_the_pressure_source_drops_the_keys_the_new_source_does_not_use(default):
    """`--set pressure.source=chamber` on a table scene was refused for its pressure.file ("not used with source =
    chamber"), which --set cannot remove."""
    assert default.pressure.to_dict()["source"] == "table"
    chamber = default.with_overrides(**{"pressure.source": "chamber"})
    assert chamber.pressure.to_dict()["source"] == "chamber"
    constant = default.with_overrides(**{"pressure.source": "constant", "pressure.Pa": "2 bar", "pressure.Pb": "1 bar"})
    assert constant.pressure.to_dict() == {"source": "constant", "Pa": 2e5, "Pb": 1e5}
    assert _error(default, {"pressure.source": "constant"}).keys() == ["pressure.Pa", "pressure.Pb"]  # still needed


def test_a_gas_scene_without_ports_warns_that_its_chambers_are_sealed(default):
    """A chamber-gas scene without [machine.ports] ran with both chambers sealed, its gas compressed to
    hundreds of bar, without a word."""
    from apexseal.runtime.scenes.units import PlausibilityWarning

    with pytest.warns(PlausibilityWarning, match=r'machine.ports = \(missing\): pressure.source = "chamber" with no '
                                                 r"ports: both chambers are sealed"):
        default.with_overrides(**{"pressure.source": "chamber", "machine.ports": None})


def test_overlapping_ports_of_a_gas_scene_are_questioned(default):
    """An outlet over the inlet joins the supply to the exhaust through any chamber over both: it ran without a
    word. Ports apart (the default's, or one degree short of touching) pass in silence, and so do overlapping ones
    that no law reads (a pressure table)."""
    import warnings

    from apexseal.runtime.scenes.units import PlausibilityWarning

    with pytest.warns(PlausibilityWarning, match=r'machine.ports.outlet.angle = "-10 deg": the outlet \(-10 \+- 18 '
                                                 r"deg\) overlaps the inlet \(-25 \+- 11 deg\) by 14 deg"):
        default.with_overrides(**{**GAS, "machine.ports.outlet.angle": "-10 deg"})
    with pytest.warns(PlausibilityWarning, match="by 24 deg"):  # across the 0/360 deg seam
        default.with_overrides(**{**GAS, "machine.ports.outlet.angle": "340 deg"})
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        default.with_overrides(**GAS)
        default.with_overrides(**{**GAS, "machine.ports.outlet.angle": "5 deg"})  # 30 deg apart, half widths 29
        default.with_overrides(**{"machine.ports.outlet.angle": "-10 deg"})


def test_a_bare_mass_that_would_fit_in_grams_is_asked_about(default):
    """`seal.ms = 40` (kg) was refused by the osmium bound with no hint, where a bare length gets "did you mean"."""
    assert 'a bare number is in kg: did you mean "40 g"?' in str(_error(default, {"seal.ms": 40}))
    assert "did you mean" not in str(_error(default, {"seal.ms": "40 kg"}))  # a unit written: no slip to suggest


def test_a_switch_given_as_the_string_false_is_told_how_to_write_it(default):
    err = _error(default, {"effects.spring": "false"})
    assert "not the string 'false'" in str(err) and "from Python: False" in str(err)
    assert "not the string" not in str(_error(default, {"effects.spring": "off"}))


def test_the_docs_error_table_shows_these_messages(default):
    docs = (Path(__file__).resolve().parents[2] / "docs" / "scenes.md").read_text(encoding="utf-8")
    for _, overrides, *_ in CASES:
        assert f"`{_error(default, overrides).errors[0]}`" in docs


def test_overrides_from_numpy_and_pint_are_read_as_the_toml_would_hold_them(default):
    """From Python, `np.bool_(False)` switched effects.spring off but not its damping and friction (they follow a
    False), a 0-d numpy array was refused ("got ndarray"), and so was a pint quantity ("got Quantity"), pint being
    apexseal's own unit library."""
    import numpy as np
    import pint

    off = default.with_overrides(**{"effects.spring": np.bool_(False)})
    assert not off.effects.spring and not off.effects.spring_damping and not off.effects.spring_friction
    u = pint.UnitRegistry()
    odd = default.with_overrides(**{"seal.Ws": 2.9 * u.mm, "operation.rpm": np.array(1600.0),
                                    "contacts.kw": np.float32(2e9)})
    assert odd.seal.Ws == pytest.approx(2.9e-3) and odd.operation.rpm == 1600.0 and odd.contacts.kw == 2e9
    assert 'seal.Ws = "3.2 kilogram": wrong unit: expected a length' in str(_error(default, {"seal.Ws": 3.2 * u.kg}))


def test_an_unknown_embedded_scene_lists_the_embedded_ones():
    """embedded_scene_path("default") said only "no such embedded scene": the names (default.toml, hard/...) were
    found by browsing the package."""
    import apexseal

    with pytest.raises(SceneError, match=r'scene = "default": no such embedded scene; embedded: default\.toml, '
                       r"expander-gas\.toml, hard/.*soft-contacts\.toml"):
        apexseal.embedded_scene_path("default")


def test_a_misspelt_scene_name_is_told_the_name_and_where_it_was_looked_for(tmp_path, monkeypatch):
    """load_scene("defualt") said "file not found" alone: the closest of apexseal's own names, and for a relative
    name the path it was looked for at."""
    monkeypatch.chdir(tmp_path)
    for name, hint in (("defualt", "(did you mean 'default'?)"), ("soft-contact", "(did you mean 'soft-contacts'?); "
                       "apexseal's own scenes load with load_scene(apexseal.embedded_scene_path(\"<name>.toml\"))")):
        with pytest.raises(SceneError) as info:
            load_scene(name)
        assert info.value.errors[0].message == f"file not found (looked for {tmp_path / name}) {hint}"
