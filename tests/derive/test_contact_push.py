"""A contact's law pushes the seal out where its guard says closed (derive/contact_push.py, docs/extending.md).

A guard of the wrong sign (the cushion's gap returned where minus it is meant, or a penetration as the guard)
derived, generated and ran: the contact closed where the bodies were apart and ``laws.penalty`` gave zero there,
and where they overlapped it was open, so the cushion never pushed and nothing said so. A law that pulls the
seal into its contact was derived silently too. The derivation now refuses both, naming the submodel, its
contact and guard and what to change; every built-in contact passes.
"""

from __future__ import annotations

import pytest

from apexseal.derive import derive_model
from apexseal.derive.contact_push import ContactPushError
from apexseal.derive.effects import Effects
from apexseal.derive.options import NONE, ON, Option
from apexseal.derive.parameters import Parameter
from apexseal.derive.submodels import laws, registry
from apexseal.derive.submodels.base import ContactModel, Guard, Load, Submodel

#: a small model: the cushion acts at the spring's point s6
SMALL = ("spring", "housing_contact")


def cushion(guard_sign: int = 1, pull: bool = False) -> type[Submodel]:
    """The cushion of docs/extending.md; ``guard_sign=-1`` returns minus its gap as the guard (the mistake),
    ``pull=True`` writes its force towards the groove bottom."""

    class Cushion(Submodel):
        name = "cushion"
        summary = "a linear spring between the seal's back face and the groove bottom"
        switch = "cushion"
        parameters = (
            Parameter("kb", "N/m", "cushion stiffness", key="contacts.kb", default=2e5, gt=0),
            Parameter("hb", "m", "depth of the back face below its rest position at which the cushion closes",
                      key="contacts.hb", default=4e-6, gt=0),
        )
        options = (Option("cushion", (NONE, ON), "the cushion under the seal's back face"),)
        guards = (Guard("cb", "s_cb", "height of the back face above the cushion, hb below its rest position",
                        output="cushion_gap", sign=1, closed_label="c", open_label="c0"),)

        def contacts(self, ctx):
            g, P = ctx.g, ctx.P
            gap = g.X_s6 + P["ds2"] + P["hb"]
            force = laws.penalty(P["kb"], -gap, ctx.activation(self.guards[0])) * ctx.k.G.x
            return [ContactModel("cushion", [Load("cb", g.r_s6, -force if pull else force)], guard_name="cb",
                                 guard=guard_sign * gap)]

    return Cushion


def derive_with(cls: type[Submodel]):
    with registry.registered(cls):
        return derive_model(Effects.only(*SMALL, "cushion"))


def test_every_built_in_contact_pushes_the_seal_out():
    model = derive_model(Effects.only("spring", "housing_contact", "groove_contact", "groove_friction",
                                      "housing_friction"))
    assert {"xs5", "b1", "b2", "b3", "b4", "spring"} <= set(model.guards)


def test_the_cushion_as_documented_is_derived():
    assert "cb" in derive_with(cushion()).guards


def test_a_guard_of_the_wrong_sign_is_refused_naming_the_submodel_and_the_guard():
    with pytest.raises(ContactPushError) as err:
        derive_with(cushion(guard_sign=-1))
    text = str(err.value)
    assert "submodel cushion" in text and "guard 'cb'" in text and "never pushes" in text
    assert "the guard's sign is inverted" in text and "guard=-penetration" in text


def test_a_law_that_pulls_the_seal_into_its_contact_is_refused():
    with pytest.raises(ContactPushError, match="pulls the seal into the contact"):
        derive_with(cushion(pull=True))
