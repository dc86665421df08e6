"""A submodel's mistakes in its own declarations and laws are refused where it is declared, registered or derived,
naming the submodel, what is wrong and what is allowed (each was accepted silently, or failed far from its cause
with a bare traceback)."""

from __future__ import annotations

import re
import warnings

import pytest

from apexseal.derive.effects import Effects
from apexseal.derive.options import NONE, ON, Option
from apexseal.derive.parameters import Parameter
from apexseal.derive.submodels import registry
from apexseal.derive.submodels.base import ContactModel, Guard, Load, Submodel
from apexseal.derive.submodels.declarations import RESERVED_KEYS, RESERVED_SECTIONS


def _with(**changes) -> type[Submodel]:
    """A submodel "zz" with one parameter, the parameter's declaration changed by ``changes``."""
    kw = {"name": "c_zz", "unit": "N*s/m", "meaning": "a damper", "key": "zz.c", "default": 1.0, "ge": 0} | changes
    p = Parameter(kw.pop("name"), kw.pop("unit"), kw.pop("meaning"), **kw)
    return type("ZZ", (Submodel,), {"name": "zz", "__module__": "elsewhere", "parameters": (p,)})


@pytest.mark.parametrize(("changes", "message"), [
    # an IndexError in Parameter.leaf on every command before
    ({"key": "radial_damper_c"}, r"key='radial_damper_c' is not a scene key \"section.name\""),
    ({"ge": 5, "le": 1, "default": None}, r"its range ge=5, le=1 holds no value"),
    ({"gt": 1, "lt": 1, "default": None}, r"its range gt=1, lt=1 holds no value"),
    # `apexseal scene` called the default valid and used it
    ({"default": 1e5, "le": 1e4}, r"default=100000.0 is outside its own range \(le=10000.0\)"),
    # it was a ValueError when the parameter was declared, asking for sign="real" or the lower bound ge=0 it has
    ({"default": -5.0}, r"default=-5.0 is outside its own range \(ge=0\)"),
    ({"unit": ""}, r"unit='' is empty .*\"1\" for a plain number"),
    ({"key": "effects.spring"}, r"key='effects.spring' is in the scene's \[effects\] table, whose keys are not "
                                r"parameters"),
    ({"key": "solver.c"}, r"key='solver.c' is in the scene's \[solver\] table"),
    ({"key": "machine.ports"}, r"key='machine.ports' is a scene key that is not a parameter's"),
    ({"plausible": (10, 1, "N*s/m")}, r"plausible=\(10, 1, 'N\*s/m'\) has its low end 10 above its high end 1"),
    ({"name": "p z"}, r"its name is not an identifier"),
])
def test_a_wrong_parameter_declaration_is_refused_at_registration(changes, message):
    """Each was accepted (or failed later, far from the declaration): refused naming the submodel, the parameter
    and what is allowed."""
    name = re.escape(changes.get("name", "c_zz"))
    with pytest.raises(registry.RegistryError, match=rf"submodel 'zz' \(from module elsewhere\): parameter '{name}': "
                                                     + message):
        registry.register(_with(**changes))
    assert "zz" not in {c.name for c in registry.submodels()}


@pytest.mark.parametrize(("changes", "message"), [
    # pint reads "Nm" as its number_meter: a unit, but no SI one
    ({"unit": "Nm/furlong"}, r"unit='Nm/furlong' is not an SI unit: pint reads it as number_meter / furlong"),
    ({"unit": "furlongz"}, r"unit='furlongz' is not a unit pint reads"),
    ({"show": "kg"}, r"show='kg' does not convert to 'N\*s/m'"),
    ({"plausible": (1, 10, "N")}, r"the unit 'N' of plausible=\(1, 10, 'N'\) does not convert"),
])
def test_a_unit_pint_cannot_read_is_refused_before_any_scene(changes, message):
    """A unit pint does not read (or not as SI) was accepted and no value could ever be given: the scene layer, which
    reads units with pint (the registry does not import it), refuses the submodel when it builds its tables, naming
    the submodel, the parameter and the unit, before any scene is read."""
    from apexseal.runtime.scenes.schema import sections

    with registry.registered(_with(**changes)), pytest.raises(
            registry.RegistryError, match=r"submodel 'zz' \(from module elsewhere\): parameter 'c_zz': " + message):
        sections()


def test_two_parameters_on_one_scene_key_are_refused():
    """One of them silently took the other's default."""
    twins = type("ZZ", (Submodel,), {"name": "zz", "__module__": "elsewhere", "parameters": (
        Parameter("c_zz", "N*s/m", "a damper", key="zz.c", default=1.0, ge=0),
        Parameter("k_zz", "N/m", "a spring", key="zz.c", default=5.0, ge=0))})
    with pytest.raises(registry.RegistryError, match=r"parameters 'c_zz' and 'k_zz' have the same scene key 'zz.c'"):
        registry.register(twins)


def test_a_switch_no_option_declares_is_refused():
    """``switch = "nope"`` was accepted: the submodel was never on, whatever the scene said."""
    nope = type("ZZ", (Submodel,), {"name": "zz", "__module__": "elsewhere", "switch": "nope",
                                    "options": (Option("zz", (NONE, ON), "a damper"),)})
    with pytest.raises(registry.RegistryError, match=r"submodel 'zz' .*switch='nope' is not an effect .*effects: .*zz "
                                                     r"\(declare options"):
        registry.register(nope)


def _guarded(**changes) -> type[Submodel]:
    """A submodel "zz" with one parameter and one guard, the guard's declaration (or the class's) changed by
    ``changes``."""
    guard = {"name": "gzz", "activation": "s_zz", "meaning": "a gap", "output": "zz_gap", "closed_label": "z",
             "open_label": "z0"}
    attrs = {k: changes.pop(k) for k in ("oscillators", "dampers", "damping_ratios") if k in changes}
    return type("ZZ", (Submodel,), {"name": "zz", "__module__": "elsewhere", "guards": (Guard(**guard | changes),),
                                    "parameters": _with().parameters} | attrs)


@pytest.mark.parametrize(("changes", "message"), [
    ({"output": ""}, r"guard 'gzz': output='' is not a name"),
    ({"output": None}, r"guard 'gzz': output=None is not a name"),
    ({"output": "xs5"}, r"guard 'gzz': output='xs5' is already that of guard 'xs5'"),
    # it shared the housing's activation symbol: the two contacts opened and closed as one
    ({"activation": "s_h"}, r"guard 'gzz': activation='s_h' is already that of guard 'xs5'"),
    ({"sign": 2}, r"guard 'gzz': sign=2 is not 1 or -1"),
    # a run read the modes "*_h0_*" of the cushion open as the tip off the housing
    ({"closed_label": "h", "open_label": "h0"}, r"guard 'gzz': the mode label 'h' is already one of guard 'xs5'"),
    ({"closed_label": "q1"}, r"guard 'gzz': the mode label 'q1' is already one of the groove's cases"),
    ({"open_label": "z_0"}, r"guard 'gzz': the mode label 'z_0' is not a word without underscores"),
    # a misspelt parameter failed only when a scene was run (a KeyError in the stability or damping checks)
    ({"oscillators": (("kzz", "cs"),)}, r"oscillators names 'kzz', which is no parameter"),
    ({"dampers": ("c_zzz",)}, r"dampers names 'c_zzz', which is no parameter \(did you mean 'c_zz'\?\)"),
    ({"damping_ratios": (("c_zz", "zeta_zz"),)}, r"damping_ratios names 'zeta_zz', which is no parameter"),
])
def test_a_wrong_guard_or_parameter_reference_is_refused_at_registration(changes, message):
    """Each was accepted at registration: an empty or taken output, a taken activation, a sign other than +-1, a
    mode label of another contact or a groove case, a stability check's parameter that does not exist. Refused,
    naming the submodel, the guard or field, and the value."""
    with pytest.raises(registry.RegistryError, match=r"submodel 'zz' \(from module elsewhere\): " + message):
        registry.register(_guarded(**changes))
    assert "zz" not in {c.name for c in registry.submodels()}
    registry.register(_guarded())  # the same submodel without the mistake
    registry.unregister("zz")


def test_a_misspelt_need_or_a_taken_scene_key_names_the_parameter():
    """The messages named the misspelt need alone (``need what is not an effect: cushon``) and the taken key with
    its owner's parameter, not which of the submodel's parameters declared it nor whose the key is."""
    cushion = type("ZZ", (Submodel,), {"name": "zz", "__module__": "elsewhere", "switch": "zz",
                                       "options": (Option("zz", (NONE, ON), "a pad"),),
                                       "parameters": (_with(needs="zzz").parameters[0],)})
    with pytest.raises(registry.RegistryError, match=r"submodel 'zz' \(from module elsewhere\) declares parameters "
                                                     r"that need what is not an effect: parameter 'c_zz': needs='zzz' "
                                                     r"\(did you mean 'zz'\?\)"):
        registry.register(cushion)
    with pytest.raises(registry.RegistryError, match=r"submodel 'zz' \(from module elsewhere\) declares scene keys "
                                                     r"that exist already: parameter 'c_zz': key='contacts.kw' is "
                                                     r"already that of parameter 'kw' of the housing"):
        registry.register(_with(key="contacts.kw"))
    assert "zz" not in {c.name for c in registry.submodels()}


def test_the_built_in_declarations_pass_every_check():
    """The built-in submodels skip the units' check of the scene layer (pint is not imported for them): they pass it
    and the registry's own."""
    from apexseal.derive.submodels.declarations import parameter_problems
    from apexseal.runtime.scenes.declared_units import unit_problems

    assert {c.name: parameter_problems(c) + [w for p in c.parameters for w in unit_problems(p)]
            for c in registry.submodels()} == {c.name: [] for c in registry.submodels()}


def test_the_reserved_scene_keys_are_the_schemas_own():
    """The sections and keys a parameter may not take are those the scene schema fills itself."""
    from apexseal.runtime.scenes.schema import key_paths, sections

    own = {s for s in sections() if not any(p.section == s for p in registry.parameters(all_inputs=True))}
    assert own == set(RESERVED_SECTIONS)
    declared = {p.key for p in registry.parameters(all_inputs=True)}
    fixed = {re.sub(r"^machine\.ports\..*", "machine.ports", k) for k in key_paths("machine.")} - declared
    assert fixed == set(RESERVED_KEYS)


def test_registering_the_same_class_twice_says_so():
    """It said "registered already (by ...SpringContact)", as if another class had taken the name."""
    from apexseal.derive.submodels.spring import SpringContact

    with pytest.raises(registry.RegistryError, match=r"'spring' .*SpringContact\) is registered already \(this very "
                                                     r"class"):
        registry.register(SpringContact)


class _Drag(Submodel):
    name = "zz"
    switch = "zz"
    options = (Option("zz", (NONE, ON), "a drag on the seal"),)
    parameters = (Parameter("c_zz", "N*s/m", "drag coefficient", key="zz.c", default=1.0, ge=0),)
    guards = (Guard("gzz", "s_zz", "a gap", output="zz_gap"),)
    #: what the laws return: (the contact's name, force along the groove axis, guard name, guard)
    law = ("zz", None, None, None)

    def contacts(self, ctx):
        import sympy as sp
        from sympy.physics.vector import Vector

        name, force, guard_name, guard = self.law
        f = force(ctx, sp) if force is not None else ctx.P["c_zz"] * ctx.X["xd"]
        return [ContactModel(name, [Load("zz", Vector(0), f * ctx.k.G.x)], guard_name=guard_name,
                             guard=guard(ctx, sp) if guard is not None else None)]


def _derive(law):
    from apexseal.derive.model import derive_model

    drag = type("Drag", (_Drag,), {"law": law, "__module__": "elsewhere"})
    with registry.registered(drag):
        return derive_model(Effects.from_mapping({"zz": True}))


@pytest.mark.parametrize(("law", "message"), [
    # a raw "KeyError: 'no CasADi value for symbol c_extra'" when the model was generated, before
    (("zz", lambda ctx, sp: sp.Symbol("c_extra") * ctx.X["xd"], None, None),
     r"the submodel zz \(from module elsewhere\) uses in contact zz symbol 'c_extra', which no submodel declares "
     r"\(declare it as a Parameter of zz and read it as ctx.P\['c_extra'\]\)"),
    pytest.param(("zz", None, "gzz", lambda ctx, sp: ctx.X["x"] - sp.Symbol("h_extra")),
                 r"uses in contact zz \(guard gzz\) symbol 'h_extra'", marks=pytest.mark.slow),
    (("zz", lambda ctx, sp: sp.Symbol("c_zz") * ctx.X["xd"], None, None),
     r"a symbol c_zz that is not the parameter c_zz .*ctx.P\['c_zz'\]"),
])
def test_a_law_in_a_symbol_no_submodel_declares_is_refused_at_derivation(law, message):
    with pytest.raises(registry.RegistryError, match=message):
        _derive(law)


def test_a_parameter_whose_effect_is_off_is_refused_in_a_law():
    """A law that reads a parameter not in the model's vector (its effect off) failed at generation too."""
    from apexseal.derive.model import derive_model

    drag = type("Drag", (_Drag,), {"__module__": "elsewhere",
                                   "law": ("zz", lambda ctx, sp: ctx.P["mus"] * ctx.X["xd"], None, None)})
    with registry.registered(drag), pytest.raises(registry.RegistryError,
                                                  match=r"parameter 'mus', which is not in this model's parameter "
                                                        r"vector while effects.spring_friction is off"):
        derive_model(Effects.from_mapping({"zz": True, "spring_friction": False}))


@pytest.mark.parametrize(("law", "message"), [
    # accepted: the outputs F_drag_* had no meaning, and the contact no entry among the registry's contacts
    (("drag", None, None, None), r"the submodel zz \(from module elsewhere\) returned ContactModel\('drag'\), a "
                                 r"contact it does not declare \(its contacts: zz;"),
    # a bare KeyError out of the registry's guard lookup
    (("zz", None, "gother", lambda ctx, sp: ctx.X["x"]), r"guard_name='gother', a guard it does not declare "
                                                         r"\(its guards: gzz\)"),
])
def test_a_contact_or_guard_the_submodel_does_not_declare_is_refused(law, message):
    with pytest.raises(registry.RegistryError, match=message):
        _derive(law)


@pytest.mark.parametrize("jump", ["sign", pytest.param("Heaviside", marks=pytest.mark.slow)])
def test_a_law_that_jumps_with_a_velocity_is_refused(jump):
    """A bare sign of a sliding velocity was derived without a word, and the run stopped at its step limit with a
    message about stiffness and friction.v_eps, which the law does not read."""
    law = ("zz", lambda ctx, sp: -ctx.P["c_zz"] * getattr(sp, jump)(ctx.X["yd"]), None, None)
    with pytest.raises(registry.RegistryError, match=rf"the submodel zz .*jumps with a velocity: {jump}\(yd\).*"
                                                     r"laws.coulomb"):
        _derive(law)


def test_a_kink_in_a_velocity_another_submodels_parameter_and_the_built_in_laws_pass():
    """Abs(v) is continuous (as the built-in laws' Max(v, 0)) and mu2 is in the vector: neither is refused; the
    default model derives without a warning."""
    from apexseal.derive.model import derive_model

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        derive_model()
    law = ("zz", lambda ctx, sp: -ctx.P["c_zz"] * ctx.P["mu2"] * sp.Abs(ctx.X["yd"]) * ctx.X["yd"], None, None)
    assert "F_zz_X" in _derive(law).outputs
