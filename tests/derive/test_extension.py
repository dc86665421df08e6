"""A new contact, defined entirely in this file, is derived, generated and simulated (docs/extending.md).

The example: a cushion, a linear spring between the seal's back face and the groove bottom that acts
while the back face is more than ``hb`` below its rest position (a bump stop: open at rest; the spring at s6
pushes along +X, out of the groove, with kb * (-hb - h), h the back face's height above rest). Its parameters,
option, guard and law are declared here, and nothing of the package is edited: the registry builds the parameter
vector, the scene's keys, the options, the modes and the outputs from these declarations.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import apexseal
from apexseal.derive.choices import Options
from apexseal.derive.options import NONE, ON, Option
from apexseal.derive.parameters import Parameter
from apexseal.derive.submodels import registry
from apexseal.derive.submodels.base import ContactModel, Context, Friction, Guard, Load, Submodel
from apexseal.runtime.scenes.errors import SceneError
from apexseal.runtime.scenes.units import PlausibilityWarning


class Cushion(Submodel):
    name = "cushion"
    summary = "a linear spring between the seal's back face and the groove bottom"
    switch = "cushion"
    parameters = (
        Parameter("kb", "N/m", "cushion stiffness", key="contacts.kb", default=2e5, gt=0, plausible=(1e3, 1e9, "N/m")),
        Parameter("hb", "m", "depth of the back face below its rest position at which the cushion closes",
                  key="contacts.hb", default=4e-6, gt=0),
    )
    options = (Option("cushion", (NONE, ON), "the cushion under the seal's back face"),)
    guards = (Guard("cb", "s_cb", "height of the back face above the cushion, hb below its rest position",
                    output="cushion_gap", sign=1, closed_label="c", open_label="c0"),)
    oscillators = (("kb", "cs"),)
    output_columns = (("cushion_height", "m", "height of the seal's back face above its rest position"),)

    def outputs(self, ctx: Context) -> dict:
        return {"cushion_height": ctx.g.X_s6 + ctx.P["ds2"]}

    def contacts(self, ctx: Context) -> list[ContactModel]:
        from apexseal.derive.submodels import laws

        g, P = ctx.g, ctx.P
        height = g.X_s6 + P["ds2"]  # the back face's height above its rest position (Eq. 37)
        gap = height + P["hb"]  # open at rest: the seal sinks hb into its groove before the cushion acts
        force = laws.penalty(P["kb"], -gap, ctx.activation(self.guards[0])) * ctx.k.G.x
        return [ContactModel("cushion", [Load("cb", g.r_s6, force)], guard_name="cb", guard=gap)]


@pytest.fixture
def cushion():
    with registry.registered(Cushion):
        yield


def test_the_registry_builds_everything_from_the_declarations(cushion):
    from apexseal.runtime.scenes.schema import key_paths

    assert registry.extended()
    assert registry.parameter_names(opts=Options({"cushion": ON}))[-2:] == ("kb", "hb")
    assert {"contacts.kb", "contacts.hb", "effects.cushion"} <= set(key_paths())
    scene = apexseal.load_scene()
    assert scene.effects.cushion is False and scene.contacts.kb == 2e5  # off unless a scene asks for it
    # off: no slot in the vector, which stays the built-in model's
    assert "kb" not in scene.parameters and tuple(scene.parameters) == registry.parameter_names()
    on = scene.with_overrides(**{"effects.cushion": True, "contacts.kb": "3e5 N/m"})
    assert on.effects.cushion and on.parameters["kb"] == 3e5
    with pytest.raises(SceneError, match="contacts.hb"):
        scene.with_overrides(**{"contacts.hb": "4 kg"})
    with pytest.warns(PlausibilityWarning, match=r"contacts.kb.*1000 to 1e\+09 N/m"):  # its declared range
        scene.with_overrides(**{"effects.cushion": True, "contacts.kb": "1e12 N/m"})
    with warnings.catch_warnings():  # off, no law reads it: not questioned
        warnings.simplefilter("error", PlausibilityWarning)
        scene.with_overrides(**{"contacts.kb": "1e12 N/m"})


def test_a_plausible_range_is_shown_in_the_unit_it_declares():
    """Any unit pint converts to (kN/m here): the range and the value were shown unconverted, 1000x off."""
    pad = type("Pad", (Submodel,), {"name": "pad", "__module__": "elsewhere", "parameters": (
        Parameter("kpad", "N/m", "pad stiffness", key="contacts.kpad", default=1e4, gt=0,
                  plausible=(1e3, 1e9, "kN/m")),)})
    with registry.registered(pad):
        with pytest.warns(PlausibilityWarning, match=r"contacts.kpad.*5e\+06 kN/m is far outside .*\(1 to 1e\+06 kN/m\)"):
            apexseal.load_scene().with_overrides(**{"contacts.kpad": "5e9 N/m"})


def test_the_results_name_quantities_and_check_penetrations_of_a_users_contact(cushion):
    """The result's columns, a sweep's and a comparison's quantities and the plausibility check come from the
    registry: a user's contact has them as the built-in ones do."""
    from apexseal.runtime.results.outputs import describe
    from apexseal.runtime.results.plausibility import penetrations
    from apexseal.runtime.results.quantities import quantity_help

    assert registry.contacts()["cushion"] == f"cushion ({Cushion.summary})" and registry.guard_contacts()["cb"] == "cushion"
    # a noun phrase after "the" ("from the a linear spring ..." before)
    assert describe("F_cushion_X").meaning.endswith(f"from the cushion ({Cushion.summary})")
    assert {"events.cb", "penetration.cushion", "friction_power.cushion"} <= set(quantity_help())
    assert penetrations()["cushion"] == (("cushion_gap", -1.0),)  # a gap: its negative is the penetration
    assert "spring" not in penetrations()  # closed at rest by design


def test_a_guard_of_a_contact_the_submodel_does_not_declare_is_refused():
    stray = type("Film", (Submodel,), {"name": "film", "__module__": "elsewhere", "guards": (
        Guard("gf", "s_gf", "film gap", output="film_gap", contact="wiper"),)})
    with pytest.raises(registry.RegistryError, match=r"guards of contacts it does not declare: wiper \(its contacts: "
                                                     r"film;"):
        registry.register(stray)
    # a guard without contact= stands for the submodel's name, which is no contact of one that names its contacts
    unnamed = type("Pads", (Submodel,), {"name": "pads", "__module__": "elsewhere", "contact_names": ("p1", "p2"),
                                         "guards": (Guard("gp1", "s_gp1", "pad gap", output="p1_gap"),)})
    with pytest.raises(registry.RegistryError, match=r"does not declare: pads \(its contacts: p1, p2;"):
        registry.register(unnamed)
    assert not registry.extended()


def test_a_friction_law_on_a_contact_or_coefficient_the_submodel_does_not_declare_is_refused():
    mu = Parameter("mu_f", "1", "film friction", key="friction.mu_f", default=0.1, ge=0, lt=1)
    stray = type("Film", (Submodel,), {"name": "film", "__module__": "elsewhere", "parameters": (mu,),
                                       "frictions": (Friction("mu_f", ("wiper",)),)})
    with pytest.raises(registry.RegistryError, match=r"friction laws on contacts it does not declare: wiper \(its "
                                                     r"contacts: film\)"):
        registry.register(stray)
    borrowed = type("Film", (Submodel,), {"name": "film", "__module__": "elsewhere", "parameters": (mu,),
                                          "frictions": (Friction("mu2", ("film",)),)})
    with pytest.raises(registry.RegistryError, match=r"friction laws whose coefficient is none of its parameters: mu2"):
        registry.register(borrowed)
    uneven = type("Film", (Submodel,), {"name": "film", "__module__": "elsewhere", "parameters": (mu,),
                                        "frictions": (Friction("mu_f", ("film",), offsets=((0.5, "Ws"), (-0.5, "Ws"))),)})
    with pytest.raises(registry.RegistryError, match=r"friction laws \(mu_f\) whose offsets are not one per contact"):
        registry.register(uneven)
    assert not registry.extended()


def test_a_contact_with_two_guards_is_checked_at_its_deepest():
    from apexseal.runtime.results.plausibility import penetration_check, penetrations

    two = type("Pads", (Submodel,), {"name": "pads", "__module__": "elsewhere", "guards": (
        Guard("gp1", "s_gp1", "first gap", output="p1_gap"), Guard("gp2", "s_gp2", "second gap", output="p2_gap"))})
    with registry.registered(two):
        assert penetrations()["pads"] == (("p1_gap", -1.0), ("p2_gap", -1.0))
        result = type("R", (), {"n": 3, "info": {}, "outputs": {"p1_gap": np.array([1e-6, -2e-6, 0.0]),
                                                               "p2_gap": np.array([0.0, -5e-6, 1e-6])}})()
        assert penetration_check(result, clearance=30e-6)["penetration_um"]["pads"] == pytest.approx(5.0)


def test_needs_names_an_effect():
    film = type("Film", (Submodel,), {"name": "film", "__module__": "elsewhere", "parameters": (
        Parameter("eta", "1", "film viscosity ratio", key="friction.eta", ge=0, needs="damping"),)})
    with pytest.raises(registry.RegistryError, match=r"need what is not an effect: parameter 'eta': "
                                                     r"needs='damping'"):
        registry.register(film)
    assert not registry.extended()


def test_an_effect_named_before_its_submodel_is_registered_is_refused(cushion):
    """``Effects.only("cushion")`` before the cushion was registered returned every effect off, the cushion's
    missing: a model derived from it had no cushion, without a word. It is refused, naming the effect and the
    registered ones, as ``Effects.from_mapping`` and ``Effects(...)`` refuse it; once registered it is on."""
    from apexseal.derive.effects import EffectError, Effects

    registry.unregister("cushion")
    with pytest.raises(EffectError, match=r"effects\.cushion is not an effect; known: inertia, .*chamber_pressure "
                                          r"\(a submodel's effect exists once the submodel is registered"):
        Effects.only("cushion")
    with pytest.raises(EffectError, match=r"effects\.cushon is not an effect \(did you mean 'cushion'\?\)"):
        registry.register(Cushion)
        Effects.only("inertia", "cushon")
    assert Effects.only("cushion").on() == ("cushion",)


@pytest.mark.filterwarnings("ignore::apexseal.runtime.results.plausibility.PenetrationWarning")  # a soft cushion
@pytest.mark.filterwarnings("error::apexseal.generated.manifest.StaleArtefactWarning")
def test_a_contact_declared_in_a_test_is_derived_generated_and_simulated(cushion, tmp_path):
    """With the cushion on, the model is derived and generated into the cache; with it off, the run is the
    default model's (the committed artefacts, without a warning that they are stale)."""
    from apexseal.derive.cache import cached_model
    from apexseal.generated.generate import generate
    from apexseal.runtime.results.quantities import collect

    # the gas under the seal and its inertia press it out of its groove: the default scene's seal sinks less than
    # 1 um below rest and never meets a cushion hb = 4 um down. Knocked into its groove at the start (0.2 m/s along
    # -X) it sinks past hb, the cushion (its defaults) closes, some micrometres deep, and throws it back out
    scene = apexseal.load_scene().with_overrides(**{"effects.cushion": True, "operation.initial_state.xd": "-0.2 m/s",
                                                    "solver.samples_per_revolution": 360, "solver.interpreted": True})
    model = cached_model(scene.effects, scene.assumptions)
    assert "cb" in model.guards and "F_cushion_X" in model.outputs
    manifest = generate(scene.effects, scene.assumptions, tmp_path / "gen", compile=False, echo=None)
    assert "cb" in manifest.data["names"]["guards"]
    assert any(m["label"].endswith("_c") for m in manifest.modes)
    assert len(manifest.modes) == 72  # the nine groove cases x housing x spring x cushion

    r = apexseal.simulate(scene, revolutions=1)
    assert r.status == "completed", r.stop
    i = r.guard_names.index("cb")
    assert r.events[i, -1] > 0  # the cushion closed and opened during the revolution
    closed = r.closed[i]
    assert not closed[0]  # open at rest: the seal starts hb above it
    F = r.outputs["F_cushion_X"]
    assert np.all(F[~closed] == 0) and np.all(F[closed] >= 0) and F[closed].max() > 0
    np.testing.assert_allclose(r.outputs["cushion_gap"][closed] < 1e-9, True)
    assert any(m.endswith("_c") for m in r.modes) and any(m.endswith("_c0") for m in r.modes)
    q = collect(r, ("events.cb", "penetration.cushion", "friction_power.cushion"))
    assert q["events.cb"] == r.events[i, -1] and np.isnan(q["friction_power.cushion"])  # no friction law
    assert q["penetration.cushion"] == pytest.approx(max(0.0, -r.outputs["cushion_gap"].min()) * 1e6)
    # its own output is a column with the unit it declares (a KeyError in the CSV, to_pandas and to_xarray before)
    df = r.to_pandas()
    np.testing.assert_array_equal(df["cushion_height"].to_numpy(), r.outputs["cushion_height"])
    assert r.to_xarray()["cushion_height"].attrs["units"] == "m"
    r.save(tmp_path / "saved", csv=True)
    assert "cushion_height [m]" in (tmp_path / "saved" / "trajectory.csv").read_text().splitlines()[1]

    still = apexseal.simulate(scene.with_overrides(**{"operation.initial_state.xd": "0 m/s"}), revolutions=1)
    assert still.status == "completed" and still.events[i, -1] == 0  # unknocked, the seal never reaches it

    without = apexseal.simulate(scene.with_overrides(**{"effects.cushion": False}), revolutions=1)
    assert "cb" not in without.guard_names  # off: not derived, not generated, not run
    assert abs(without.state[0] - r.state[0]).max() > 1e-7  # the cushion moves the seal


def test_a_users_submodel_that_is_off_changes_no_models_keys():
    """What is off never enters the derivation: a registered (or installed) submodel that is off leaves the default
    model's derivation key and input hash as they were, so the cached derivations and the committed default
    artefacts stay in use (every key changed before, and the first run after installing a package derived and
    generated the default model again); switched on, it changes both."""
    from apexseal.derive.assumptions import Assumptions
    from apexseal.derive.cache import derivation_key
    from apexseal.derive.effects import Effects
    from apexseal.generated.load import DEFAULT_DIR, artefact_dir, is_default
    from apexseal.generated.manifest import input_hash

    before = derivation_key(Effects(), Assumptions()), input_hash(Effects(), Assumptions())
    with registry.registered(Cushion):
        off, on = Effects(), Effects(cushion=True)
        assert off.as_dict()["cushion"] is False
        assert (derivation_key(off, Assumptions()), input_hash(off, Assumptions())) == before
        assert is_default(off, Assumptions()) and artefact_dir(off, Assumptions()) == DEFAULT_DIR
        assert registry.extended() and not registry.extended(Options()) and registry.extended(Options({"cushion": ON}))
        assert derivation_key(on, Assumptions()) != before[0] and input_hash(on, Assumptions()) != before[1]
        assert not is_default(on, Assumptions())


def test_a_users_submodel_enters_the_keys_once_a_scene_touches_its_options(tmp_path):
    """Left out only while it is off with its options at their defaults: a submodel on by default and switched
    off, or one whose own choice is made, enters the keys, so its options are recorded and read back (a manifest
    that left out the switch of a submodel on by default read it back on and called its own artefacts stale), and
    two choices of it never share a key (a submodel that is on may read another's option)."""
    from apexseal.derive.assumptions import Assumptions
    from apexseal.derive.cache import derivation_key
    from apexseal.derive.effects import Effects
    from apexseal.generated.generate import generate
    from apexseal.generated.load import is_default
    from apexseal.generated.manifest import input_hash, verify

    on_by_default = type("Pad", (Submodel,), {"name": "pad", "__module__": "elsewhere", "switch": "pad", "options": (
        Option("pad", (ON, NONE), "a pad, on unless a scene switches it off"),
        Option("pad_law", ("linear", "cubic"), "its law", table="assumptions"))})
    with registry.registered(on_by_default):
        off = Effects(pad=False)
        assert not registry.untouched(on_by_default, Options({"pad": NONE}))
        assert not is_default(off, Assumptions())
        manifest = generate(off, Assumptions(), tmp_path / "gen", compile=False, echo=None)
        assert manifest.effects == off  # read back from its record as it was asked for
        verify(tmp_path / "gen", expected_hash=input_hash(off, Assumptions()), trusted=True)  # not stale
        linear, cubic = (Assumptions.from_mapping({"pad_law": law}) for law in ("linear", "cubic"))
        assert derivation_key(off, linear) != derivation_key(off, cubic)


def test_a_derivation_cached_without_a_users_submodel_serves_the_model_with_it_off(tmp_path, monkeypatch):
    """The same key with and without a submodel that is off: the cached model is served (not derived again) with
    the caller's effects, so its options name the user's switch."""
    import pickle

    import sympy as sp

    from apexseal.derive import cache
    from apexseal.derive import model as derived
    from apexseal.derive.assumptions import Assumptions
    from apexseal.derive.effects import Effects

    monkeypatch.setenv("APEXSEAL_CACHE", str(tmp_path))
    stub = derived.DerivedModel(Effects(), Assumptions(), sp.eye(1), sp.Matrix([sp.Symbol("f")]), {}, {}, {}, {})
    path = tmp_path / "derive" / f"{cache.derivation_key(Effects(), Assumptions())}.pkl"
    path.parent.mkdir(parents=True)
    path.write_bytes(pickle.dumps(stub))
    monkeypatch.setattr(derived, "derive_model", lambda *a, **k: pytest.fail("derived again"))
    with registry.registered(Cushion):
        served = cache.cached_model(Effects(), Assumptions())
        assert served.forcing == stub.forcing and served.effects == Effects() and served.options["cushion"] == NONE


def test_a_sign_its_range_contradicts_is_refused():
    """The derivation simplifies with a parameter's sign (Max(p, 0), Abs(p) become p for a positive p): a range that
    admits negative values under the default sign "positive" ran a law that is wrong for them, silently."""
    with pytest.raises(ValueError, match=r"theta_e \(contacts.theta_e\): sign='positive' lets the derivation assume "
                                         r"theta_e > 0, but its range admits negative values \(ge=-3.15\): declare "
                                         r'sign="real"'):
        Parameter("theta_e", "rad", "load angle", key="contacts.theta_e", default=0.0, ge=-3.15, le=3.15)
    with pytest.raises(ValueError, match=r"Fe \(contacts.Fe\): sign='nonnegative' .*>= 0, but its range admits "
                                         r"negative values: declare"):
        Parameter("Fe", "N", "side force", key="contacts.Fe", default=5.0, sign="nonnegative")
    with pytest.raises(ValueError, match=r"sign='negative' is not one of 'positive', 'nonnegative', 'real'"):
        Parameter("Fe", "N", "side force", key="contacts.Fe", default=5.0, ge=0, sign="negative")
    angle = Parameter("theta_e", "rad", "load angle", key="contacts.theta_e", default=0.0, ge=-3.15, le=3.15,
                      sign="real")
    assert angle.symbol.is_positive is None and Parameter("Fe", "N", "side force", ge=0).symbol.is_positive


def test_a_scene_with_a_users_submodel_off_reads_as_one_without_it(tmp_path):
    """A submodel that is off enters neither the scene's content hash nor its resolved file (a result's
    scene.toml): a result of a run that never used it loads where it is not installed, and installing it changes no
    scene's hash; switched on, it is in both."""
    from apexseal.runtime.scenes.resolved import resolved_toml

    plain = apexseal.load_scene()
    with registry.registered(Cushion):
        scene = apexseal.load_scene()
        text, files = resolved_toml(scene)
        assert scene.content_hash() == plain.content_hash()
        assert {"contacts.kb", "contacts.hb", "effects.cushion"} <= scene.left_out_keys()
        assert "kb =" not in text and "cushion" not in text
        on = scene.with_overrides(**{"effects.cushion": True})
        assert on.content_hash() != plain.content_hash() and "cushion = true" in resolved_toml(on)[0]
    (tmp_path / "scene.toml").write_text(text)
    for name, body in files.items():
        (tmp_path / name).write_text(body)
    assert apexseal.load_scene(tmp_path / "scene.toml").content_hash() == plain.content_hash()


def test_a_result_whose_scene_needs_a_missing_submodel_names_its_package(tmp_path):
    """show, compare, --resume and SimulationResult.load read a result's scene.toml: one that does not load here
    (a submodel of the run's not installed) is a ResultFolderError naming the folder and the package, not a
    traceback."""
    from apexseal.runtime.results.reading import ResultFolderError, scene_of_result
    from apexseal.runtime.scenes.resolved import resolved_toml

    with registry.registered(Cushion):
        text, files = resolved_toml(apexseal.load_scene().with_overrides(**{"effects.cushion": True}))
    (tmp_path / "scene.toml").write_text(text)
    for name, body in files.items():
        (tmp_path / name).write_text(body)
    with pytest.raises(ResultFolderError, match=r"(?s)scene.toml does not load here; the run was made where "
                                                r"submodels this process lacks were installed: cushion "
                                                r"\(seal-extras 0.2\).*effects.cushion"):
        scene_of_result(tmp_path, {"versions": {"apexseal": "0.1.0", "submodel cushion": "seal-extras 0.2"}})


def test_without_a_users_submodel_the_registry_is_not_extended():
    assert not registry.extended()
    with registry.registered(Cushion):
        assert registry.extended()
    assert not registry.extended()


def _cell(source: str) -> type[Submodel]:
    """The class a notebook cell defines: ``source`` run in a module namespace named like a notebook's."""
    namespace = {"__name__": "notebook"}
    exec(compile(source, "<cell>", "exec"), namespace)  # noqa: S102 - the test's own text
    return namespace["Pad"]


PAD = """
from apexseal.derive.options import NONE, ON, Option
from apexseal.derive.parameters import Parameter
from apexseal.derive.submodels.base import Submodel


class Pad(Submodel):
    name = "pad"
    switch = "pad"
    parameters = (Parameter("kpad", "N/m", "pad stiffness", key="contacts.kpad", default={default}, gt=0),)
    options = (Option("pad", (NONE, ON), "a pad"),)
"""


def test_a_class_defined_again_replaces_its_earlier_definition_in_place():
    """A notebook cell run again after an edit registers the edited class where the first one was; another class
    of the same name is refused, naming where the registered one comes from."""
    first, edited = _cell(PAD.format(default=1e4)), _cell(PAD.format(default=2e4))
    try:
        registry.register(first)
        registry.register(Cushion)
        registry.register(edited)
        assert [c.name for c in registry.submodels()][-2:] == ["pad", "cushion"]
        assert registry.submodels()[-2] is edited and registry.parameter("kpad").default == 2e4
        clash = _cell(PAD.format(default=3e4).replace('Parameter("kpad"', 'Parameter("ks"'))
        # it named the parameter, not its owner
        with pytest.raises(registry.RegistryError, match=r"parameters that exist already: ks \(the spring's\)$"):
            registry.register(clash)
        assert registry.submodels()[-2] is edited  # a refused redefinition leaves the last good one
        other = type("Pad", (Submodel,), {"name": "pad", "__module__": "elsewhere"})
        with pytest.raises(registry.RegistryError, match="registered already \\(by notebook.Pad\\)"):
            registry.register(other)
    finally:
        registry.unregister("pad")
        registry.unregister("cushion")
    assert not registry.extended()


def test_a_scene_key_taken_or_a_choice_with_a_parent_is_refused():
    """A parameter under another's scene key silently took that key's value under its unit and range; an
    assumption with a parent made every scene fail to load."""
    taken = type("Film", (Submodel,), {"name": "film", "__module__": "elsewhere", "parameters": (
        Parameter("c_film", "N*s/m", "film damping", key="friction.mu1", default=1.0, gt=0),)})
    with pytest.raises(registry.RegistryError, match=r"scene keys that exist already: parameter 'c_film': "
                                                     r"key='friction.mu1' is already that of parameter 'mu1' of the "
                                                     r"housing"):
        registry.register(taken)
    ruled = type("Law", (Submodel,), {"name": "law", "__module__": "elsewhere", "switch": "law", "options": (
        Option("law", (NONE, ON), "a law"),
        Option("law_rule", ("linear", "cubic"), "its rule", table="assumptions", parent="law"))})
    with pytest.raises(registry.RegistryError, match="modelling choice .* with a parent"):
        registry.register(ruled)
    assert not registry.extended()


def test_a_submodel_off_with_its_own_parameters_does_not_break_the_start_check(default_scene):
    """The parameters of a submodel that is off are not in the vector, so the start check's contact frequencies
    skip its oscillator (every run with it off raised KeyError: 'kpad')."""
    from apexseal.runtime.solving.contact_stability import contact_frequencies

    pad = type("Pad", (Submodel,), {
        "name": "pad", "__module__": "elsewhere", "switch": "pad",
        "parameters": (Parameter("kpad", "N/m", "pad stiffness", key="contacts.kpad", default=1e4, gt=0),
                       Parameter("cpad", "N*s/m", "pad damping", key="contacts.cpad", default=1.0, gt=0)),
        "options": (Option("pad", (NONE, ON), "a pad"),), "oscillators": (("kpad", "cpad"),)})
    with registry.registered(pad):
        scene = apexseal.load_scene().with_overrides(**{"effects.pad": False})
        names = tuple(scene.parameters)  # the vector of a scene with the pad off
        assert "kpad" not in names
        freq = contact_frequencies(scene.parameter_vector(), names)
        assert "kpad" not in freq and "kw" in freq


def test_a_submodel_s_own_scene_section_is_written_to_the_resolved_scene(tmp_path):
    """A parameter in a section of its own ([film]) ran with the scene's value but was left out of the result's
    scene.toml, which then re-ran another scene (its content hash differed from the result's)."""
    from apexseal.runtime.scenes.resolved import resolved_toml

    film = type("Film", (Submodel,), {
        "name": "film", "__module__": "elsewhere", "switch": "film",
        "parameters": (Parameter("c_film", "N*s/m", "film damping", key="film.c", default=2.0, gt=0),),
        "options": (Option("film", (NONE, ON), "an oil film"),)})
    with registry.registered(film):
        scene = apexseal.load_scene().with_overrides(**{"effects.film": True, "film.c": "30 N*s/m"})
        text, files = resolved_toml(scene)
        assert "[film]" in text
        (tmp_path / "scene.toml").write_text(text)
        for name, content in files.items():
            (tmp_path / name).write_text(content)
        again = apexseal.load_scene(tmp_path / "scene.toml")
        assert again.parameters["c_film"] == 30.0 and again.content_hash() == scene.content_hash()


def test_an_error_in_a_users_laws_names_the_submodel(tmp_path):
    """contacts() of a user's submodel that raises (here: a helper it imports there does not exist) is reported as
    that submodel's failure, with its module, not as a bare traceback out of the derivation."""
    from apexseal.derive.cache import cached_model
    from apexseal.derive.effects import Effects

    broken = type("Broken", (Submodel,), {
        "name": "broken", "__module__": "my_models.broken", "switch": "broken",
        "options": (Option("broken", (NONE, ON), "a contact whose laws fail"),),
        "contacts": lambda self, ctx: __import__("my_models_missing_helper")})
    with registry.registered(broken), pytest.raises(registry.RegistryError) as info:
        cached_model(Effects.from_mapping({"broken": True}), refresh=True)
    message = str(info.value)
    assert "the submodel broken (from module my_models.broken) failed in contacts()" in message
    assert "ModuleNotFoundError" in message and "switch it off in the scene" in message


def _guide_python_blocks() -> list[str]:
    """The Python blocks of docs/extending.md, in order."""
    import re

    guide = (Path(__file__).parents[2] / "docs" / "extending.md").read_text()
    return re.findall(r"```python\n(.*?)```", guide, flags=re.S)


def test_the_guide_s_cushion_is_open_at_rest_and_derived_as_written():
    """docs/extending.md's cushion, run from the guide's own text (without its registry.register line): a bump stop
    open at rest, it passes the rest balance of Eq. 9 and the push check. As first written (its gap the back face's
    height less hb) it was closed at rest, pushing kb hb there, and derived only because the rest balance took
    every contact but the housing and the spring as open: every run with it started out of balance."""
    from apexseal.derive import derive_model
    from apexseal.derive.effects import Effects

    source = next(b for b in _guide_python_blocks() if "class Cushion" in b).split("\n\n\nregistry.register")[0]
    namespace = {"__name__": "guide"}
    exec(compile(source, "docs/extending.md", "exec"), namespace)  # noqa: S102 - the guide's text
    with registry.registered(namespace["Cushion"]):
        model = derive_model(Effects.only("spring", "housing_contact", "cushion"))
    assert "cb" in model.guards and "F_cushion_X" in model.outputs


def test_the_guide_s_load_that_always_acts_is_derived_as_written():
    """docs/extending.md's second example (a guardless ContactModel, the crank angle, a "real" angle), run from the
    guide's own text: its force peaks at Fe along the seal's Ys axis at theta = theta_e."""
    import re

    import sympy as sp

    from apexseal.derive import contact_geometry, kinematics
    from apexseal.derive.model import submodel_contacts
    from apexseal.derive.symbols import theta

    blocks = _guide_python_blocks()
    imports = next(b for b in blocks if "class Cushion" in b).split("\n\n\nclass")[0]
    source = next(b for b in blocks if "class SideLoad" in b)
    # the guide's submodels import sympy in their laws only (a top-level import is paid by every run)
    assert not [b for b in blocks if re.search(r"^(import sympy|from sympy|from apexseal\.derive\.symbols)", b, re.M)]
    namespace = {"__name__": "guide"}
    exec(compile(imports + "\n" + source, "docs/extending.md", "exec"), namespace)  # noqa: S102 - the guide's text
    with registry.registered(namespace["SideLoad"]):
        k = kinematics.build()
        (contact,) = submodel_contacts("side_load", k, contact_geometry.build(k), Options({"side_load": ON}))
        assert contact.guard is None and len(contact.loads) == 1
        P = registry.parameter("Fe").symbol, registry.parameter("theta_e").symbol
        along = contact.loads[0].force.dot(k.S.y).subs(theta, P[1])
        assert sp.simplify(along - P[0]) == 0 and registry.parameter("theta_e").symbol.is_positive is None


def _documented_damper(tmp_path):
    """The damper module of docs/extending.md ("a viscous damper from a package of your own"), as a module file of a
    package, imported the way its entry point is."""
    import importlib
    import re
    import sys

    text = (Path(__file__).resolve().parents[2] / "docs" / "extending.md").read_text(encoding="utf-8")
    section = text[text.index("## Example: a viscous damper"):]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    package = tmp_path / "my_seal_models_doc"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "damper.py").write_text(code)
    sys.path.insert(0, str(tmp_path))
    try:
        return importlib.import_module("my_seal_models_doc.damper").GrooveDamper
    finally:
        sys.path.remove(str(tmp_path))


def test_the_documented_damper_runs_as_the_docs_say(tmp_path):
    """docs/extending.md's damper example: its bad value's message, the default model left as it was while it is
    off, and a run with it on that has its outputs (the docs' example cannot rot)."""
    damper = _documented_damper(tmp_path)
    with registry.registered(damper):
        scene = apexseal.load_scene()
        assert tuple(scene.parameters) == registry.parameter_names() and "cv" not in scene.parameters
        with pytest.raises(SceneError) as info:
            scene.with_overrides(**{"effects.damper": True, "damper.cv": "-3 N*s/m"})
        said = 'damper.cv = "-3 N*s/m": -3 N*s/m is out of range; allowed: 0 <= value <= 1000 N*s/m'
        assert said in str(info.value)
        assert f"`{said}`" in (Path(__file__).resolve().parents[2] / "docs" / "extending.md").read_text()
        on = scene.with_overrides(**{"effects.damper": True, "damper.cv": "20 N*s/m",
                                     "solver.samples_per_revolution": 360, "solver.interpreted": True})
        r = apexseal.simulate(on, revolutions=1)
        assert r.status == "completed", r.stop
        F = r.outputs["F_damper_X"]
        assert {"F_damper_Y", "M_damper"} <= set(r.outputs) and np.all(np.isfinite(F)) and np.any(F != 0)


def test_a_damper_without_a_stiffness_is_weighed_by_the_explicit_methods_checks(tmp_path):
    """A damper with no stiffness of its own (docs/extending.md's, declared in ``dampers``) decays the seal's motion
    at the rate c/ms, which explicit Euler follows only while h c/ms < 2: beyond it the run is refused before its
    first step, naming the damper (it was not weighed, and such a run went on until its state was non-finite)."""
    import math

    from apexseal.runtime.solving.contact_stability import MAX_GROWTH, contact_growth

    documented = _documented_damper(tmp_path)
    wide = type("GrooveDamper", (documented,), {"__module__": documented.__module__, "parameters": (
        Parameter("cv", "N*s/m", "viscous damping of the seal in the groove", key="damper.cv", default=5.0,
                  ge=0, le=1e7),)})
    with registry.registered(wide):
        scene = apexseal.load_scene().with_overrides(**{"effects.damper": True, "damper.cv": "1e6 N*s/m",
                                                        "solver.method": "euler"})
        names, params = tuple(scene.parameters), scene.parameter_vector()
        growth = {g.name: g for g in contact_growth(params, 200_000, names)}
        g = growth["cv"]
        ms, omega = scene.parameters["ms"], scene.parameters["omega"]
        assert g.damper == 1e6 and math.isclose(g.omega, 1e6 / ms)
        h_rate = 2 * math.pi / omega / g.steps_needed * g.omega  # h c/ms at the steps it asks: Euler's bound 2
        assert 1.9 < h_rate <= 2.0 + math.log(MAX_GROWTH) / g.steps_needed * 2
        r = apexseal.simulate(scene, revolutions=1, samples_per_revolution=360)
        assert r.status == "failed" and r.n == 1 and r.stop.theta == 0  # refused at the start: its state only
        assert "amplifies the motion the cv damper damps (cv = 1e+06 N*s/m" in r.stop.reason
        import re

        advised = int(re.search(r"use at least (\d+) solver.euler_steps_per_revolution", r.stop.reason).group(1))
        assert g.steps_needed <= advised < 1.01 * g.steps_needed  # the least setting taking the steps it needs


def test_a_load_whose_force_is_not_a_vector_names_the_submodel():
    """docs/extending.md's damper with its force written as a scalar (-cv v, without * k.G.x): refused naming the
    submodel, the contact and the load, and saying how to write a vector. It was a bare
    ``AttributeError: 'Mul' object has no attribute 'dot'`` from deep in the equations of motion."""
    from apexseal.derive.cache import cached_model
    from apexseal.derive.effects import Effects

    def scalar(self, ctx):
        v = ctx.k.relative_velocity(ctx.g.r_s6).dot(ctx.k.G.x)
        return [ContactModel("damper", [Load("dv", ctx.g.r_s6, -ctx.P["cv"] * v)])]  # the docs': ... * v * k.G.x

    damper = type("GrooveDamper", (Submodel,), {
        "name": "damper", "__module__": "my_models.damper", "switch": "damper", "contacts": scalar,
        "parameters": (Parameter("cv", "N*s/m", "viscous damping", key="damper.cv", default=5.0, ge=0),),
        "options": (Option("damper", (NONE, ON), "the viscous damper between seal and groove"),)})
    with registry.registered(damper), pytest.raises(registry.RegistryError) as info:
        cached_model(Effects.from_mapping({"damper": True}), refresh=True)
    message = str(info.value)
    assert "the submodel damper (from module my_models.damper) returned ContactModel('damper')" in message
    assert "Load 'dv' whose force is -cv*" in message and "not a vector" in message and "* k.G.x" in message


def _drag():
    """A package's drag in the groove, off by default, with a law of its own to choose and a coefficient for each
    law (each parameter ``needs`` its choice)."""
    return type("Drag", (Submodel,), {"name": "drag", "__module__": "elsewhere", "switch": "drag", "parameters": (
        Parameter("cd1", "N*s/m", "linear drag coefficient", key="drag.cd1", default=10.0, ge=0, le=1e3,
                  needs="drag_law=linear"),
        Parameter("cd2", "N*s**2/m**2", "quadratic drag coefficient", key="drag.cd2", default=1.0, ge=0, le=100,
                  needs="drag_law=quadratic")),
        "options": (Option("drag", (NONE, ON), "a drag in the groove"),
                    Option("drag_law", ("linear", "quadratic"), "its law", table="assumptions"))})


def test_a_parameter_that_needs_a_choice_is_not_read_while_its_submodel_is_off():
    """A parameter whose ``needs`` is a choice of its own submodel was range-checked, as an error, while that
    submodel was off (the parameter vector left it out, the scene's checks did not): ``--set drag.cd1=-3`` with the
    drag off was refused, and a [drag] table given with it off loaded without the warning that it is not read.
    Off, the value is ignored with the warning naming the switch that is off; on, it is an error."""
    drag = _drag()
    with registry.registered(drag):
        scene = apexseal.load_scene()
        with pytest.warns(Warning, match=r'drag.cd1 = "-3 N\*s/m" \(not read while effects.drag is off; allowed: '):
            scene.with_overrides(**{"drag.cd1": "-3 N*s/m"})
        with pytest.warns(Warning, match=r'drag.cd2 = "500 N\*s\*\*2/m\*\*2" \(not read while effects.drag is off'):
            scene.with_overrides(**{"assumptions.drag_law": "quadratic", "drag.cd2": "500 N*s**2/m**2"})
        with pytest.warns(Warning, match=r"\[drag\] is not read: no law reads drag.cd1 while effects.drag is off"):
            scene.with_overrides(**{"drag.cd1": "20 N*s/m"})
        with pytest.raises(SceneError, match=r'drag.cd1 = "-3 N\*s/m": -3 N\*s/m is out of range'):
            scene.with_overrides(**{"effects.drag": True, "drag.cd1": "-3 N*s/m"})
        with pytest.warns(Warning, match=r"drag.cd2 = .500 .*not read while assumptions.drag_law is not 'quadratic'"):
            scene.with_overrides(**{"effects.drag": True, "drag.cd2": "500 N*s**2/m**2"})
        on = scene.with_overrides(**{"effects.drag": True, "drag.cd1": "20 N*s/m"})
        assert registry.is_read("drag.cd1", on.effects, on.assumptions)
        assert not registry.is_read("drag.cd1", scene.effects, scene.assumptions)


def test_a_package_whose_choice_a_scene_makes_is_in_the_runs_versions(monkeypatch):
    """A package's submodel off but with a choice of its own made enters the model (its option is recorded, the
    result's scene.toml writes it): the run's versions name the package, so a result read where it is missing says
    which package to install (they named it only while its submodel was on)."""
    drag = _drag()
    with registry.registered(drag):
        monkeypatch.setitem(registry._installed, "drag", "seal-drag 0.1")
        assert registry.installed(Options()) == {}
        assert registry.installed(Options({"drag_law": "quadratic"})) == {"drag": "seal-drag 0.1"}
        assert registry.installed(Options({"drag": ON})) == {"drag": "seal-drag 0.1"}


def test_the_effects_label_names_a_users_submodel_that_is_on():
    """The label of the derivation's progress, ``apexseal scene`` and the generated header said "all" for the
    default model and for the one with a user's submodel on alike."""
    from apexseal.derive.effects import Effects

    assert Effects().label == "all"
    with registry.registered(Cushion):
        assert Effects().label == "all"  # off at its defaults: the model without it
        assert Effects.from_mapping({"cushion": True}).label == "all+cushion"
        assert Effects.only("spring", "cushion").label == "spring+cushion"
        assert Effects.only("cushion").label == "cushion"
        assert Effects.only().label == "none"
