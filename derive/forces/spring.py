"""Seal - spring contact at s6: Eqs. 35-39 and 69-74.

The spring sits on the groove axis and pushes along +X on the seal's back face,
at the point s6 where the face crosses the axis (Eq. 36). Its force is
ks times its compression, delta_s at rest less the outward travel of s6
(Eq. 38); it exists while the compression is positive (the spring can only push).
"""

from __future__ import annotations

import sympy as sp

from ..assumptions import Assumptions
from ..contact_geometry import ContactGeometry
from ..effects import Effects
from ..kinematics import Kinematics
from ..symbols import P
from .base import ACT, ContactModel, Load, approach, slip_sign


def spring_contact(k: Kinematics, g: ContactGeometry, effects: Effects, assumptions: Assumptions) -> ContactModel:
    """Fs6 = Fsp X + Fd_s6 + Ff_s6 (Eq. 74)."""
    G = k.G
    act = ACT["s_sp"]
    v = k.relative_velocity(g.r_s6)  # Eqs. 70-72
    closing = -v.dot(G.x)  # > 0 while the seal moves down into the spring
    guards = {"v_s6_n": closing}
    normal = act * P["ks"] * sp.Max(g.spring_compression, 0)  # Eq. 39 (a spring cannot pull)
    if effects.spring_damping:
        damp = P["cs"] * approach(closing)  # Eq. 73
        normal = normal + (act * damp if assumptions.damping == "in-contact" else damp)
    force = normal * G.x
    power = sp.S.Zero
    if effects.spring_friction:
        v_slide = v.dot(G.y)
        sigma = slip_sign(v_slide)
        force = force - P["mus"] * sigma * normal * G.y  # Eq. 73
        power = P["mus"] * normal * sigma * v_slide
        guards["v_s6_slide"] = v_slide
    return ContactModel("spring", [Load("s6", g.r_s6, force, friction_power=power)],
                        guard=-g.spring_compression, activation=act, velocity_guards=guards)
