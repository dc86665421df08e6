"""Seal - groove contacts at g1..g4: Algorithm 1 and Eqs. 48-63.

Contact i1 (g1 on the seal's negative side) and i2 (g3 on its positive side) push
along -+Ys, normal to the seal's sides; c2 and c4 (the back corners) push along
-+Y, normal to the groove walls. Sliding is measured relative to the groove
(Eqs. 50-61); friction opposes it with the normal force of the contact.
"""

from __future__ import annotations

import sympy as sp
from sympy import Max

from ..assumptions import Assumptions
from ..contact_geometry import ContactGeometry
from ..effects import Effects
from ..kinematics import Kinematics
from ..symbols import P
from .base import ACT, ContactModel, Load, approach, slip_sign

#: contact -> (gap, seal point, stiffness, normal direction name, tangent direction name)
_CONTACTS = {
    "i1": ("b1", "r_i1", "kg1", ("S", "y", +1), ("S", "x")),
    "c2": ("b2", "r_c2", "kg2", ("G", "y", +1), ("G", "x")),
    "i2": ("b3", "r_i2", "kg3", ("S", "y", -1), ("S", "x")),
    "c4": ("b4", "r_c4", "kg4", ("G", "y", -1), ("G", "x")),
}


def groove_contacts(k: Kinematics, g: ContactGeometry, effects: Effects, assumptions: Assumptions) -> list[ContactModel]:
    """Fi1, Fc2, Fi2, Fc4 of Eq. 63: elastic (Algorithm 1) + damping (Eqs. 55, 62) + friction."""
    frames = {"S": k.S, "G": k.G}
    models = []
    for point, (gap_name, r_name, k_name, (nf, na, sgn), (tf, ta)) in _CONTACTS.items():
        gap = g.gaps[gap_name]
        act = ACT["s_" + gap_name]
        r = getattr(g, r_name)
        n = sgn * getattr(frames[nf], na)  # direction the groove pushes the seal
        tangent = getattr(frames[tf], ta)
        v = k.relative_velocity(r)  # Eqs. 50-61
        closing = -v.dot(n)  # > 0 while the seal moves into the groove wall
        guards = {f"v_{point}_n": closing}
        normal = act * P[k_name] * Max(-gap, 0)  # |b| kg while b < 0 (a contact cannot pull)
        if effects.groove_damping:
            damp = P["cr"] * approach(closing)
            normal = normal + (act * damp if assumptions.damping == "in-contact" else damp)
        force = normal * n
        power = sp.S.Zero
        if effects.groove_friction:
            v_slide = v.dot(tangent)
            sigma = slip_sign(v_slide)  # gamma_i of Algorithm 1, regularised
            force = force - P["mu2"] * sigma * normal * tangent
            power = P["mu2"] * normal * sigma * v_slide
            guards[f"v_{point}_slide"] = v_slide
        models.append(ContactModel(point, [Load(point, r, force, friction_power=power)], guard=gap,
                                   activation=act, velocity_guards=guards))
    return models
