"""A scene leaves out what an effect that is off would read (registry.needing): it loads, runs as if it gave the
values, writes a resolved scene without them, and asks for them again once the effect is switched back on. What is
off has no slot in the parameter vector, given or not."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

import apexseal
from apexseal.runtime.scenes.errors import SceneError

#: the default scene without its spring: every key only the spring (and its damping and friction) reads left out
NO_SPRING = {"effects.spring": False, "effects.spring_damping": False, "effects.spring_friction": False}
SPRING_KEYS = ("spring.ks", "spring.delta_s", "friction.mus", "contacts.zeta_s")


def _without(scene, *keys: str):
    return scene.with_overrides(**dict.fromkeys(keys))


@pytest.fixture(scope="module")
def scenes():
    given = apexseal.load_scene().with_overrides(**NO_SPRING, **{"solver.samples_per_revolution": 360})
    return given, _without(given, *SPRING_KEYS)


def test_the_keys_of_an_effect_that_is_off_may_be_left_out(scenes):
    given, left_out = scenes
    p = left_out.parameters
    assert not {"ks", "delta_s", "mus", "cs"} & set(p)  # no slots: given or not, the spring is not in the model
    assert all(math.isfinite(v) for v in p.values())
    assert p == given.parameters and list(p) == list(given.parameters)


def test_it_runs_as_the_scene_that_gives_them(scenes, tmp_path):
    given, left_out = scenes
    a = apexseal.simulate(given)
    b = apexseal.simulate(left_out, out=tmp_path / "run")
    assert a.status == b.status == "completed"
    np.testing.assert_array_equal(a.state, b.state)
    np.testing.assert_array_equal(a.outputs["Pf_total"], b.outputs["Pf_total"])
    # the result's scene leaves them out too, and loads as the scene that ran
    text = (tmp_path / "run" / "scene.toml").read_text()
    assert "[spring]" not in text and not re.search(r"^(ks|delta_s|mus) =", text, re.M)
    assert apexseal.load_scene(tmp_path / "run" / "scene.toml").content_hash() == left_out.content_hash()


def test_switching_the_effect_on_asks_for_its_keys(scenes):
    _, left_out = scenes
    with pytest.raises(SceneError) as info:
        left_out.with_overrides(**{"effects.spring": True})
    assert info.value.keys() == ["spring.ks", "spring.delta_s"]
    assert "spring.ks = (missing): required while effects.spring is on; give a stiffness in N/m" in str(info.value)
    on = left_out.with_overrides(**{"effects.spring": True, "spring.ks": "5 kN/m", "spring.delta_s": "1 mm"})
    assert on.parameters["ks"] == 5e3 and "mus" not in on.parameters  # its friction is still off


def test_one_helper_says_whether_a_parameter_is_read():
    """registry.is_read: by the parameter, its name or its scene key; a friction coefficient while its friction is
    on, friction.v_eps while any friction is (its needs names all three), the seal body's always."""
    from apexseal.derive.effects import Effects
    from apexseal.derive.submodels.registry import is_read, parameter

    smooth_groove = Effects.from_mapping({"groove_friction": False})
    assert not is_read("friction.mu2", smooth_groove) and not is_read("mu2", smooth_groove)
    assert not is_read(parameter("mu2"), smooth_groove) and is_read("mu2", Effects())
    assert is_read("friction.v_eps", smooth_groove) and is_read("seal.Ws", Effects.only("housing_contact"))
    assert not is_read("v_eps", Effects.only("housing_contact", "groove_contact", "spring"))
    with pytest.raises(KeyError):
        is_read("friction.mu9", smooth_groove)


def test_the_gas_model_s_values_are_read_only_with_a_gas_pressure_source(default_scene):
    """The chamber gas submodel enters a model only with pressure.source = "chamber" or "chamber+leakage"
    (Submodel.enters_with): is_read said its values were read whatever the source, so gas.T_supply = "-5 K" stopped
    a scene with a pressure table, which reads no gas value. Now it is an ignored value naming the key that would
    read it; with the gas source it is the error naming key, value and range."""
    from apexseal.derive.assumptions import Assumptions
    from apexseal.derive.submodels.registry import is_read
    from apexseal.runtime.scenes.errors import IgnoredValueWarning
    from apexseal.runtime.scenes.scene import embedded_scene_path

    assert not is_read("gas.T_supply", default_scene.effects, default_scene.assumptions)
    assert is_read("gas.T_supply", default_scene.effects, Assumptions(pressure_model="chamber+leakage"))
    with pytest.warns(IgnoredValueWarning) as caught:
        odd = default_scene.with_overrides(**{"gas.T_supply": "-5 K"})
    (warning,) = [w for w in caught if w.category is IgnoredValueWarning]
    assert ("gas.T_supply = \"-5 K\" (not read while pressure.source is neither 'chamber' nor 'chamber+leakage'; "
            "allowed: > 0 K)") in str(warning.message)
    assert odd.parameters == default_scene.parameters
    gas = apexseal.load_scene(embedded_scene_path("expander-gas.toml"))
    with pytest.raises(SceneError) as info:
        gas.with_overrides(**{"gas.T_supply": "-5 K"})
    (problem,) = info.value.errors
    assert problem.key == "gas.T_supply" and "allowed: > 0 K" in problem.message


def test_ports_longer_than_the_machine_is_deep_are_ignored_without_the_gas_model(default_scene):
    """The ports (machine.ports) are read by the chamber gas model alone (ChamberGas.scene_inputs): a shallower
    machine than the default's 70 and 80 mm ports stopped the default scene, a pressure table that reads no port,
    and so a sweep over the machine depth. Now the one warning names them and what would read them; with the gas
    source the bound is the error it was."""
    from apexseal.runtime.scenes.errors import IgnoredValueWarning
    from apexseal.runtime.scenes.scene import embedded_scene_path

    with pytest.warns(IgnoredValueWarning) as caught:
        shallow = default_scene.with_overrides(**{"machine.H": "60 mm", "seal.Bs": "50 mm"})
    (warning,) = [w for w in caught if w.category is IgnoredValueWarning]
    for port, length in (("inlet", 70), ("outlet", 80)):
        assert (f'machine.ports.{port}.length = "{length} mm" (not read while pressure.source is neither \'chamber\' '
                "nor 'chamber+leakage'; allowed: <= machine.H = 60 mm)") in str(warning.message)
    assert shallow.machine.H == pytest.approx(0.06)
    gas = apexseal.load_scene(embedded_scene_path("expander-gas.toml"))
    with pytest.raises(SceneError) as info:
        gas.with_overrides(**{"machine.H": "60 mm", "seal.Bs": "50 mm"})
    assert {p.key for p in info.value.errors} == {"machine.ports.inlet.length", "machine.ports.outlet.length"}


def test_a_modelling_choice_another_key_makes_is_warned_when_it_differs(default_scene):
    """assumptions.pressure_model follows pressure.source (Option.set_by): "chamber" written beside a pressure table
    was overruled without a word, and the user believed the gas model ran. Now the warning names both keys; the
    value the source makes (a resolved scene writes it) passes in silence."""
    import warnings

    from apexseal.runtime.scenes.errors import IgnoredValueWarning

    with pytest.warns(IgnoredValueWarning) as caught:
        table = default_scene.with_overrides(**{"assumptions.pressure_model": "chamber"})
    (warning,) = [w for w in caught if w.category is IgnoredValueWarning]
    assert str(warning.message) == ('scene default: assumptions.pressure_model = "chamber": not read: pressure.source '
                                    "= \"table\" makes it 'input'; change pressure.source instead")
    assert table.assumptions == default_scene.assumptions
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        default_scene.with_overrides(**{"assumptions.pressure_model": "input"})


def test_out_of_range_values_no_law_reads_load_and_run_with_one_warning(scenes):
    """The spring's stiffness and friction out of range while the spring is off: the scene loads (it stopped),
    warns once with each key, value, effect and range, and runs as the scene with valid values does."""
    from apexseal.runtime.scenes.errors import IgnoredValueWarning

    given, _ = scenes
    with pytest.warns(IgnoredValueWarning) as caught:
        odd = given.with_overrides(**{"spring.ks": "-5 N/m", "friction.mus": 1.5})
    (warning,) = [w for w in caught if w.category is IgnoredValueWarning]
    assert str(warning.message) == (
        "scene default: ignored, out of range but read by no law of the scene's model: spring.ks = \"-5 N/m\" (not "
        "read while effects.spring is off; allowed: > 0 N/m), friction.mus = 1.5 (not read while "
        "effects.spring_friction is off; allowed: 0 <= value < 1); switching the effect on makes it an error")
    assert odd.spring.ks == -5 and odd.parameters == given.parameters
    a, b = apexseal.simulate(given), apexseal.simulate(odd)
    assert a.status == b.status == "completed"
    np.testing.assert_array_equal(a.state, b.state)


def test_constant_chamber_pressures_out_of_range_while_the_chamber_pressure_is_off(default_scene):
    """The constant pressures are the model's input, read only while the chamber pressure acts on the seal: off, a
    negative Pa loads with the one warning and an implausible Pb is not questioned (the first stopped the scene and
    the second warned, while the table of a table source was already neither read nor checked)."""
    import warnings

    from apexseal.runtime.scenes.errors import IgnoredValueWarning

    constant = {"pressure": {"source": "constant", "Pa": "-1 bar", "Pb": "1e9 bar"}}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        off = default_scene.with_overrides(**constant, **{"effects.chamber_pressure": False})
    assert [(w.category, str(w.message)) for w in caught] == [(IgnoredValueWarning, (
        "scene default: ignored, out of range but read by no law of the scene's model: pressure.Pa = \"-1 bar\" (not "
        "read while effects.chamber_pressure is off; allowed: >= 0 Pa); switching the effect on makes it an error"))]
    assert off.pressure.to_dict() == {"source": "constant", "Pa": -1e5, "Pb": 1e14}
    with pytest.raises(SceneError) as info:  # read: the error it always was
        default_scene.with_overrides(**constant)
    assert [str(p) for p in info.value.errors] == ['pressure.Pa = "-1 bar": -100000 Pa is out of range; allowed: >= 0 Pa']


def test_an_ignored_chamber_pressure_leaves_the_model_as_the_pressure_source_makes_it(default_scene):
    """assumptions.pressure_model follows pressure.source (the constant source: "input"), whatever [assumptions]
    says (a resolved scene.toml writes it). With an out-of-range Pa that no law reads, the modelling choices were
    resolved from the first reading of the scene, where [pressure] was refused and had no source: the scene kept
    the "chamber" written in [assumptions] and put the chamber gas model into a constant-pressure scene, which the
    same scene with a valid Pa does not."""
    import warnings

    from apexseal.runtime.scenes.errors import IgnoredValueWarning

    constant = {"pressure": {"source": "constant", "Pa": "2 bar", "Pb": "1 bar"}, "effects.chamber_pressure": False,
                "assumptions.pressure_model": "chamber"}
    valid = default_scene.with_overrides(**constant)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IgnoredValueWarning)
        ignored = default_scene.with_overrides(**constant, **{"pressure.Pa": "-1 bar"})
    assert valid.assumptions.pressure_model == "input"
    assert ignored.assumptions == valid.assumptions and ignored.parameters == valid.parameters


def test_the_same_values_read_are_errors_naming_key_value_and_range(scenes, default_scene):
    """With the effect on, the out-of-range value is the error it always was; friction.v_eps is read while any
    friction is on, so the groove's friction off does not excuse it."""
    given, _ = scenes
    with pytest.raises(SceneError) as info:
        given.with_overrides(**{"spring.ks": "-5 N/m", "friction.mus": 1.5, **dict.fromkeys(NO_SPRING, True)})
    assert [str(p) for p in info.value.errors] == ['spring.ks = "-5 N/m": -5 N/m is out of range; allowed: > 0 N/m',
                                                   "friction.mus = 1.5: 1.5 is out of range; allowed: 0 <= value < 1"]
    with pytest.raises(SceneError) as info:
        default_scene.with_overrides(**{"effects.groove_friction": False, "friction.v_eps": 0})
    assert [str(p) for p in info.value.errors] == ["friction.v_eps = 0: 0 m/s is out of range; allowed: > 0 m/s"]


def test_a_friction_coefficient_is_needed_only_with_its_friction(default_scene):
    smooth = default_scene.with_overrides(**{"effects.groove_friction": False, "friction.mu2": None})
    assert "mu2" not in smooth.parameters and smooth.parameters["mu1"] == default_scene.parameters["mu1"]
    with pytest.raises(SceneError, match=r"friction.mu2 = \(missing\): required while effects.groove_friction is on"):
        default_scene.with_overrides(**{"friction.mu2": None})


@pytest.mark.filterwarnings("ignore::apexseal.runtime.scenes.units.PlausibilityWarning")  # 0.5 rpm
def test_the_start_checks_weigh_only_the_contacts_in_the_model(default_scene):
    """The speed check (the stiffest contact followed in crank angle) and the explicit-Euler stability check took
    every declared contact, an effect that is off included: a housing switched off with a stiffness of 1e13 N/m
    refused a slow run, and a left-out stiffness (NaN) broke them."""
    from apexseal.runtime.api import model_functions
    from apexseal.runtime.solving.contact_stability import contact_growth
    from apexseal.runtime.solving.preflight import speed_problem

    off = default_scene.with_overrides(**{"effects.housing_contact": False, "effects.housing_damping": False,
                                          "effects.housing_friction": False, "contacts.kw": "1e13 N/m",
                                          "operation.rpm": "0.5 rpm"})
    fns = model_functions(off)
    assert "kw" not in fns.parameters_read() and {"kg1", "ks", "mu2"} <= fns.parameters_read()
    assert speed_problem(fns, off.parameter_vector()) is None
    on = default_scene.with_overrides(**{"contacts.kw": "1e13 N/m", "operation.rpm": "0.5 rpm"})
    assert "the seal's fastest ringing on its contacts" in speed_problem(model_functions(on), on.parameter_vector())
    left_out = off.with_overrides(**{"contacts.kw": None})
    names = [g.name for g in contact_growth(left_out.parameter_vector(), 200000, fns.parameter_names,
                                            fns.parameters_read())]
    assert "kw" not in names and "kg1" in names


def test_the_parameters_as_a_function_of_the_preload_follow_the_scene_s_vector(default_scene):
    """Scene.parameter_function (the preload study's p(delta_s)) has the scene's own vector, so the study runs on a
    scene with an effect off (it raised a CasADi type error on a left-out key), and the study finds a parameter by
    its name: with the groove friction off, ks and delta_s sit one slot earlier than in the default vector."""
    from apexseal.derive.symbols import PARAMETER_NAMES
    from apexseal.runtime.studies.preload.problem import preload_parameters

    smooth = default_scene.with_overrides(**{"effects.groove_friction": False, "friction.mu2": None})
    own, names = smooth.parameter_vector(), tuple(smooth.parameters)
    f = smooth.parameter_function("delta_s")
    np.testing.assert_array_equal(np.array(f(smooth.parameters["delta_s"])).ravel(), own)
    pmap = preload_parameters(smooth)
    assert pmap.names == names and "mu2" not in names and np.all(np.isfinite(pmap.p0)) and np.all(np.isfinite(pmap.dp))
    assert names.index("ks") == PARAMETER_NAMES.index("ks") - 1
    assert pmap.at("ks") == smooth.parameters["ks"] and pmap.at("kw") == smooth.parameters["kw"]
    np.testing.assert_allclose(pmap(smooth.parameters["delta_s"]), own, rtol=1e-12)


def test_the_parameter_function_takes_a_scene_key_and_names_an_unknown_name(default_scene):
    """``parameter_function("spring.delta_s")`` (the key a scene file and with_overrides use) was a bare KeyError:
    it is the parameter delta_s, and a name that is neither gets the closest known one and the list."""
    by_key, by_name = default_scene.parameter_function("spring.delta_s"), default_scene.parameter_function("delta_s")
    assert by_key.name_in(0) == "delta_s"
    np.testing.assert_array_equal(np.array(by_key(3e-3)), np.array(by_name(3e-3)))
    with pytest.raises(KeyError, match=r"'spring\.delta_x' is not a parameter of the scene's model nor its scene key "
                                       r"\(did you mean 'spring\.delta_s'\?\); known: omega, .*spring\.ks"):
        default_scene.parameter_function("spring.delta_x")
    smooth = default_scene.with_overrides(**{"effects.groove_friction": False, "friction.mu2": None})
    with pytest.raises(KeyError, match="'friction.mu2' is not a parameter"):  # an effect that is off reads none
        smooth.parameter_function("friction.mu2")


def test_quantities_of_a_contact_the_model_does_not_have_are_missing_not_zero(default_scene):
    """Without the housing contact the housing force, and without the groove's contacts the leakage gap, are null in
    summary.json and NaN among a sweep's quantities (as a friction power of a contact without friction is), and no
    spectrum of the housing force is drawn: they were 0, so a bound on the housing force passed trivially."""
    import math

    import apexseal
    from apexseal.runtime.results.quantities import collect
    from apexseal.runtime.results.saved_figures import figure_files

    off = default_scene.with_overrides(**{"effects.housing_contact": False, "effects.housing_damping": False,
                                          "effects.housing_friction": False})
    r = apexseal.simulate(off, revolutions=1, samples_per_revolution=360)
    s = r.summary()
    assert s["housing_force_N"] == {"mean": None, "max": None, "max_at_deg": None}
    assert "housing_force_spectrum_peaks" not in s and s["leakage_gap"]["max_um"] is not None
    q = collect(r, ("housing_force.max", "gap.max", "friction_power.total"))
    assert math.isnan(q["housing_force.max"]) and q["gap.max"] >= 0 and q["friction_power.total"] > 0
    assert "fig14_housing_spectrum.png" not in figure_files(r) and "fig13_forces.png" in figure_files(r)
    r2 = apexseal.simulate(default_scene.with_overrides(**{"effects.groove_contact": False,
                                                           "effects.groove_damping": False,
                                                           "effects.groove_friction": False}),
                           revolutions=1, samples_per_revolution=360)
    assert r2.summary()["leakage_gap"] == {"open_fraction": None, "mean_um": None, "max_um": None}
    assert math.isnan(collect(r2, ("gap.open_fraction",))["gap.open_fraction"])
    assert "flank" not in r2.summary() and math.isnan(collect(r2, ("flank.least",))["flank.least"])  # no l1..l4
