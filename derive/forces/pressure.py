"""Chamber gas pressure on the seal: Eqs. 75-79.

Chamber a (pressure Pa) lies on the seal's +Ys side, chamber b (Pb) on its -Ys
side. Each face carries its pressure times its area; the tip arcs are integrated
over the arc (their resultants pass through the arc centre Co, which fixes their
lines of action, Eqs. 77-78). The groove-bottom pressure Pend and the side-gap
pressures Ps2, Ps4 follow ``assumptions.pend_rule`` and ``assumptions.gap_pressure``.
"""

from __future__ import annotations

import sympy as sp

from .. import seal_shape as shape
from ..assumptions import Assumptions
from ..contact_geometry import ContactGeometry
from ..kinematics import Kinematics
from ..symbols import P, Pa, Pb
from .base import ACT, ContactModel, Load


def groove_bottom_pressure(assumptions: Assumptions) -> sp.Expr:
    """Pend under the seal's back face (Eq. 75 and the text after Eq. 76)."""
    return (Pa + Pb) / 2 if assumptions.pend_rule == "mean" else (Pa - Pb) / 2


def tip_arc_force(k: Kinematics, pressure: sp.Expr, a0: sp.Expr, a1: sp.Expr) -> sp.Vector:
    """Resultant of a pressure on the tip arc between arc angles a0 < a1 (Eqs. 75-78).

    -integral of p n(alpha) ro Bs d(alpha), n the outward normal (cos alpha, sin alpha) in Xs Ys.
    """
    alpha = sp.Symbol("alpha", real=True)
    S = k.S
    fx = -pressure * P["ro"] * P["Bs"] * sp.integrate(sp.cos(alpha), (alpha, a0, a1))
    fy = -pressure * P["ro"] * P["Bs"] * sp.integrate(sp.sin(alpha), (alpha, a0, a1))
    return fx * S.x + fy * S.y


def chamber_pressure(k: Kinematics, g: ContactGeometry, assumptions: Assumptions, groove_contact: bool) -> ContactModel:
    """Fs1..Fs4, Fs7, Fs8, Fs9 (Eq. 75) at s1..s4, s7 and on the arcs through Co."""
    S = k.S
    Bs = P["Bs"]
    Pend = groove_bottom_pressure(assumptions)
    if assumptions.gap_pressure == "open-side" and groove_contact:
        # the gap between seal side and groove sees its chamber while the mouth is open, else the groove bottom
        Ps2 = (1 - ACT["s_b1"]) * Pb + ACT["s_b1"] * Pend
        Ps4 = (1 - ACT["s_b3"]) * Pa + ACT["s_b3"] * Pend
    else:
        Ps2, Ps4 = Pb, Pa
    beta, beta_o = g.beta, shape.beta_o
    r_Co = shape.tip_centre(S)
    loads = [
        Load("s1", g.r_s1, Pb * g.l1 * Bs * S.y),  # Eqs. 75-76
        Load("s2", g.r_s2, Ps2 * g.l2 * Bs * S.y),
        Load("s3", g.r_s3, -Pa * g.l3 * Bs * S.y),
        Load("s4", g.r_s4, -Ps4 * g.l4 * Bs * S.y),
        Load("s7", -P["ds2"] * S.x, Pend * P["Ws"] * Bs * S.x),
        Load("s8", r_Co, tip_arc_force(k, Pb, -beta_o, beta)),  # chamber b: arc from c1 to s5
        Load("s9", r_Co, tip_arc_force(k, Pa, beta, beta_o)),  # chamber a: arc from s5 to c3
    ]
    return ContactModel("pressure", loads)
