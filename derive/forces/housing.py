"""Seal tip - housing contact: Eqs. 33-34, 64-68 and Algorithm 2.

Normal and friction follow from the housing curve: the inward normal of the
limaçon at the apex leans from -X by lambda (Eq. 9), its tangent points along the
rotation. The elastic law is the paper's: kw xs5 is the groove-axis component of
the contact force (``assumptions.housing_stiffness = "groove-axis"``), or the
normal force from the normal penetration xs5 cos(lambda) (``"normal"``).
"""

from __future__ import annotations

import sympy as sp

from ..assumptions import Assumptions
from ..contact_geometry import ContactGeometry
from ..effects import Effects
from ..geometry import housing_normal_angle
from ..kinematics import Kinematics, theta_t
from ..symbols import P, theta
from .base import ACT, ContactModel, Load, approach, slip_sign


def housing_contact(k: Kinematics, g: ContactGeometry, effects: Effects, assumptions: Assumptions) -> ContactModel:
    """Fs5 = Fs5x + Fs5y at s5 (Eq. 68); its moment follows from where it acts."""
    G = k.G
    act = ACT["s_h"]
    lam = housing_normal_angle().subs(theta, theta_t)
    n_in = -sp.cos(lam) * G.x + sp.sin(lam) * G.y  # housing normal, pointing into the seal
    t_fwd = sp.sin(lam) * G.x + sp.cos(lam) * G.y  # housing tangent, along the rotation

    s5 = k.point_on_seal("s5", g.r_s5)
    v_abs = s5.vel(k.N)  # Eqs. 64-66: absolute velocity of the seal's point at s5
    v_rel = k.relative_velocity(g.r_s5)  # the same point relative to the groove (and the model's wall)
    # the model's wall is fixed in the groove frame at X = ds1 - delta_w, so the tip
    # approaches it at v_rel . X (Eq. 67 prints the absolute velocity instead: see errata)
    closing = v_rel.dot(G.x)
    velocity_guards = {"v_s5_X": closing}

    if assumptions.housing_stiffness == "groove-axis":
        Fw = act * P["kw"] * sp.Max(g.xs5, 0)  # Eq. 34: X component (a contact cannot pull)
    else:
        Fw = act * P["kw"] * sp.Max(g.xs5, 0) * sp.cos(lam)  # normal force
    if effects.housing_damping:
        damp = P["cw"] * approach(closing)
        Fw = Fw + (damp * act if assumptions.damping == "in-contact" else damp)

    if effects.housing_friction:
        v_slide = v_abs.dot(t_fwd)
        sigma = slip_sign(v_slide)
        velocity_guards["v_s5_slide"] = v_slide
        if assumptions.housing_stiffness == "groove-axis":
            # X component of N n_in - mu1 sigma N t_fwd equals -Fw (Algorithm 2)
            normal = Fw / (sp.cos(lam) + P["mu1"] * sigma * sp.sin(lam))
        else:
            normal = Fw
        force = normal * n_in - P["mu1"] * sigma * normal * t_fwd
        power = P["mu1"] * normal * sigma * v_slide
    else:
        normal = Fw if assumptions.housing_stiffness == "normal" else Fw / sp.cos(lam)
        force = normal * n_in
        power = sp.S.Zero
    load = Load("s5", g.r_s5, force, friction_power=power)
    return ContactModel("housing", [load], guard=-g.xs5, activation=act, velocity_guards=velocity_guards)
