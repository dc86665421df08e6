"""Eq. 9's rest balance follows the spring's law, and the derivation refuses laws that do not balance at rest.

The spring's law is written once (SpringContact.push, Eq. 39). Before, a progressive spring written into
contacts() left delta_w = ks delta_s / kw hand-written in numbers.py, and the seal started out of balance silently
(26 N of spring force against 10 N from the housing at k3 = 2 N/mm^3); the paper check crashed with
``KeyError: 'no value for symbol k3'`` because its values ignored the parameters' declared defaults.
"""

from __future__ import annotations

import re
from types import SimpleNamespace

import numpy as np
import pytest
import sympy as sp

import apexseal
from apexseal.derive import derive_model, rest_balance
from apexseal.derive.assumptions import Assumptions
from apexseal.derive.choices import options_of
from apexseal.derive.effects import Effects
from apexseal.derive.options import NONE, ON, Option
from apexseal.derive.paper_check import evaluation
from apexseal.derive.paper_check import values as paper_values
from apexseal.derive.parameters import Parameter
from apexseal.derive.rest_balance import RestBalanceError
from apexseal.derive.submodels import laws, registry
from apexseal.derive.submodels.base import ContactModel, Guard, Load, Submodel
from apexseal.derive.submodels.registry import activation_symbols
from apexseal.derive.submodels.seal import SealBody
from apexseal.derive.submodels.spring import SpringContact
from apexseal.derive.symbols import P, qs, theta, us

#: small models: the check needs only the spring and the housing (with its friction, under both stiffness rules)
EFFECTS = Effects.only("spring", "housing_contact", "housing_friction")


def cubic(compression, p):
    """A progressive spring: ks c + k3 c^3."""
    return p["ks"] * compression + p["k3"] * compression**3


def k3(**kw) -> Parameter:
    return Parameter("k3", "N/m**3", "cubic stiffness of a progressive spring", key="spring.k3", ge=0, **kw)


@pytest.fixture
def progressive(monkeypatch):
    """The user's change: the spring's push law with a cubic term and its parameter k3 (default 0)."""
    monkeypatch.setattr(SpringContact, "push", staticmethod(cubic))
    monkeypatch.setattr(SpringContact, "parameters", (*SpringContact.parameters, k3(default=0.0)))


def scene_values(assumptions: Assumptions, **over) -> dict[str, float]:
    """The default scene's parameters (as the paper check computes them) with ``over``, and delta_w derived again."""
    v = {**paper_values._default_values(), **over}
    opts = options_of(EFFECTS, assumptions)
    return {**v, **SealBody.derived(v, {"operation": SimpleNamespace(omega=v["omega"])}, opts)}


@pytest.mark.parametrize("stiffness", ["groove-axis", "normal"])
def test_a_progressive_spring_moves_delta_w_and_the_model_balances_at_rest(progressive, stiffness):
    """delta_w balances ks delta_s + k3 delta_s^3 (it stayed ks delta_s / kw), and the derived forcing is zero at rest
    with it at the default scene's values (k3 = 2 N/mm^3)."""
    assumptions = Assumptions(housing_stiffness=stiffness)
    model = derive_model(EFFECTS, assumptions)  # the derivation's own rest-balance check passes
    assert P["k3"] in model.forcing[0].free_symbols
    v = scene_values(assumptions, k3=2e9)
    rest_force = v["ks"] * v["delta_s"] + v["k3"] * v["delta_s"] ** 3
    assert SpringContact.rest_force(v) == pytest.approx(rest_force, rel=1e-15)
    act = activation_symbols()
    rest = {s: 0 for s in (*qs, *us, theta)} | {act["s_h"]: 1, act["s_sp"]: 1}
    x_force = model.forcing[0].xreplace(rest).replace(sp.tanh, lambda a: sp.S.One).xreplace({P["omega"]: 0})
    residual = float(x_force.xreplace({P[n]: x for n, x in v.items() if n in P}).evalf(30))
    assert abs(residual) < 1e-9 * rest_force
    v_linear = scene_values(assumptions, k3=0.0)
    assert v["delta_w"] / v_linear["delta_w"] == pytest.approx(rest_force / (v["ks"] * v["delta_s"]), rel=1e-12)


def test_the_paper_check_takes_a_new_parameter_s_declared_default(progressive, monkeypatch):
    """k3 is in no stated value: it takes its declared default (it was ``KeyError: no value for symbol k3``).

    (A k3 declared in spring.py is in the values when they are computed, at import; here they are computed again.)"""
    defaults = paper_values._default_values()
    assert defaults["k3"] == 0.0
    monkeypatch.setattr(evaluation, "DEFAULTS", defaults)
    monkeypatch.setattr(paper_values, "DEFAULTS", defaults)
    point = evaluation._values(["k3", "ks", "delta_w"], np.random.default_rng(1), jitter=True, ranges={})
    assert point["k3"] == 0.0 and point["delta_w"] == pytest.approx(point["ks"] * defaults["delta_s"] / defaults["kw"])


def test_a_new_parameter_without_default_is_named_by_the_paper_check(monkeypatch):
    monkeypatch.setattr(SpringContact, "parameters", (*SpringContact.parameters, k3()))
    with pytest.raises(paper_values.MissingValue, match=r"k3 \(spring.k3, declared by the submodel 'spring'.*"
                                                       r"default=.*STATED of derive/paper_check/values.py"):
        paper_values._default_values()


def test_a_spring_law_the_rest_balance_does_not_follow_stops_the_derivation(monkeypatch):
    """The law in contacts() and the force at rest must be the same: a cubic law with a linear rest force (the
    hand-written ks delta_s of before) is refused, naming Eq. 9, the submodels and what to edit."""
    monkeypatch.setattr(SpringContact, "parameters", (*SpringContact.parameters, k3(default=0.0)))
    monkeypatch.setattr(SpringContact, "push", staticmethod(cubic))
    monkeypatch.setattr(SpringContact, "rest_force", classmethod(lambda cls, p: p["ks"] * p["delta_s"]))
    with pytest.raises(RestBalanceError, match=r"Eq\. 9: the seal is not in balance at rest.*SpringContact\.push.*"
                                               r"HousingContact\.contacts.*SealBody\.rest_wall_deflection"):
        derive_model(EFFECTS)


def test_a_housing_law_changed_alone_stops_the_derivation(monkeypatch):
    """A Hertzian housing, kw xs5^1.5, with delta_w still the linear balance: refused, not a silent imbalance."""
    def hertz(stiffness, penetration, activation):
        return activation * stiffness * sp.Max(penetration, 0) ** sp.Rational(3, 2)

    monkeypatch.setattr(laws, "penalty", hertz)
    with pytest.raises(RestBalanceError, match=r"Eq\. 9.*housing_stiffness = 'groove-axis'.*change "
                                               r"SealBody\.rest_wall_deflection"):
        derive_model(EFFECTS)


@pytest.mark.parametrize("stiffness", ["groove-axis", "normal"])
def test_the_rest_balance_takes_the_sliding_limit_of_any_regularisation(monkeypatch, stiffness):
    """The friction laws' regularisation is the user's to change (laws.slip_sign's docstring): with the algebraic
    v / sqrt(v^2 + v_eps^2) the model still balances at rest. Before, the check took the sliding limit by replacing
    tanh with 1, so under housing_stiffness = "normal" (where the housing's friction is in the balance) the model
    was refused with a RestBalanceError that blamed the spring's and the housing's laws."""
    def algebraic(v, v_eps):
        return v / sp.sqrt(v**2 + v_eps**2)

    monkeypatch.setattr(laws, "slip_sign", algebraic)
    model = derive_model(EFFECTS, Assumptions(housing_stiffness=stiffness))
    assert not model.forcing[0].has(sp.tanh)


class ConstantPush(Submodel):
    """docs/extending.md's kind of user submodel: a constant load Fp along the groove axis, acting at rest too."""

    name = "push"
    switch = "push"
    parameters = (Parameter("Fp", "N", "a constant push on the seal's back face", key="push.Fp", default=5.0, ge=0),)
    options = (Option("push", (NONE, ON), "a constant push along the groove axis"),)

    def contacts(self, ctx):
        return [ContactModel("push", [Load("fp", ctx.g.r_s6, ctx.P["Fp"] * ctx.k.G.x)])]


def test_a_users_load_at_rest_is_refused_naming_the_submodels_in_the_balance():
    """A constant load of the user's own upsets Eq. 9: the error names the submodels whose X forces are in the
    balance, with their forces at the test point (it named only the spring, the housing and the seal, so the user
    could not tell their own submodel was the cause), and it is a RegistryError, which the command line reports
    as an ``Error:`` line (it was a raw traceback)."""
    with registry.registered(ConstantPush), pytest.raises(RestBalanceError) as info:
        derive_model(Effects.only("spring", "housing_contact", "push"))
    assert isinstance(info.value, registry.RegistryError)
    assert re.search(r"the submodels' X forces there: (spring|housing|push) .*push \d\.\d+ N", str(info.value))
    assert re.search(r"spring -?\d[.\d]* N", str(info.value)) and re.search(r"housing -?\d[.\d]* N", str(info.value))


class DeclaredPush(ConstantPush):
    """The constant push with its force at rest declared (``Submodel.rest_force``): delta_w balances it too."""

    @classmethod
    def rest_force(cls, p):
        return p["Fp"]


def test_a_users_load_that_declares_its_rest_force_is_balanced_by_the_housing():
    """A package's load that always acts could not be balanced at rest without editing apexseal's
    SealBody.rest_wall_deflection: declared through ``rest_force``, it derives (the rest balance holds at the test
    points) and moves delta_w by Fp / kw (Eq. 9 with the load beside the spring's preload); the spring's force at
    rest stays the spring's (the preload study's). Off, it moves nothing."""
    from apexseal.derive.choices import Options
    from apexseal.derive.submodels.seal import rest_force

    with registry.registered(DeclaredPush):
        derive_model(Effects.only("spring", "housing_contact", "push"))  # no RestBalanceError
        on, off = Options({"push": ON}), Options()
        values = {"ks": 5e3, "delta_s": 1e-3, "kw": 1e9, "Fp": 5.0}
        assert rest_force(values, on) == pytest.approx(10.0) and rest_force(values, off) == pytest.approx(5.0)
        assert SealBody.rest_wall_deflection(values, on) == pytest.approx(10.0 / 1e9, rel=1e-12)
        assert SealBody.rest_wall_deflection(values, off) == pytest.approx(5.0 / 1e9, rel=1e-12)
        assert SpringContact.rest_force(values) == pytest.approx(5.0)
        scene = apexseal.load_scene()
        pushed = scene.with_overrides(**{"effects.push": True, "push.Fp": "2 N"})
        w0 = scene.parameters["delta_w"]
        assert pushed.parameters["delta_w"] == pytest.approx(w0 + 2.0 / scene.parameters["kw"], rel=1e-12)


class PreloadedCushion(Submodel):
    """docs/extending.md's cushion as it was: a linear spring at s6 closed while the back face is less than hb above
    its rest position, so closed at rest (its gap -hb) and pushing kb hb along the groove axis there."""

    name = "cushion"
    switch = "cushion"
    parameters = (Parameter("kb", "N/m", "cushion stiffness", key="contacts.kb", default=2e5, gt=0),
                  Parameter("hb", "m", "height of the back face above rest below which the cushion acts",
                            key="contacts.hb", default=4e-6, sign="real"))
    options = (Option("cushion", (NONE, ON), "the cushion under the seal's back face"),)
    guards = (Guard("cb", "s_cb", "height of the back face above hb", output="cushion_gap", sign=1,
                    closed_label="c", open_label="c0"),)

    def contacts(self, ctx):
        gap = ctx.g.X_s6 + ctx.P["ds2"] - ctx.P["hb"]
        force = laws.penalty(ctx.P["kb"], -gap, ctx.activation(self.guards[0])) * ctx.k.G.x
        return [ContactModel("cushion", [Load("cb", ctx.g.r_s6, force)], guard_name="cb", guard=gap)]


def test_a_users_contact_closed_at_rest_is_in_the_balance_and_refused_naming_it():
    """The check closed only the housing and the spring at rest and took every other contact as open, so a user's
    contact closed at rest (the cushion docs/extending.md showed, preloaded by kb hb) was never in the balance:
    every run with it started out of balance, silently. Now a contact whose guard is negative at the test point is
    closed there, and the error names the cushion with its force kb hb."""
    with registry.registered(PreloadedCushion):
        values = rest_balance._point(0, registry.parameter_names(all_inputs=True))  # the first test point
        with pytest.raises(RestBalanceError) as info:
            derive_model(Effects.only("spring", "housing_contact", "cushion"))
    message = str(info.value)
    assert re.search(rf"the submodels' X forces there: .*cushion {float(values['kb'] * values['hb']):.6g} N", message)
    assert re.search(r"the contacts of guards [^)]*\bcb\b[^)]*closed there", message)


def test_the_command_line_reports_a_rest_balance_error_as_an_error_line(monkeypatch):
    """``apexseal derive`` (and every command that derives) prints ``Error: Eq. 9: ...`` and exits 1, no
    traceback."""
    from click.testing import CliRunner

    from apexseal.cli import main
    from apexseal.derive import cache

    def refused(*args, **kwargs):
        raise RestBalanceError("Eq. 9: the seal is not in balance at rest: ...")

    monkeypatch.setattr(cache, "cached_model", refused)
    r = CliRunner().invoke(main, ["derive"])
    assert r.exit_code == 1 and not isinstance(r.exception, RestBalanceError)
    assert "\nError: Eq. 9: the seal is not in balance at rest: ...\n" in r.output and "Traceback" not in r.output
