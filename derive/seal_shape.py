"""The seal's outline in its own frame Xs Ys, Eqs. 16, 19, 24, 27-28.

A rectangle of width Ws from the back face (-ds2 along Xs) up to where the tip
starts (ds0), closed by a circular arc of radius ro centred at Co = (ds1 - ro) Xs
that passes through the tip point ds1 Xs. Everything follows from Ws, ds1, ds2, ro.
"""

from __future__ import annotations

import sympy as sp
from sympy.physics.vector import ReferenceFrame, Vector

from .numbers import tip_half_angle  # noqa: F401  (the value of beta_o, Eq. 24, sympy-free)
from .symbols import P

Ws, ds1, ds2, ro = P["Ws"], P["ds1"], P["ds2"], P["ro"]

#: Eq. 16
ds = ds1 + ds2

#: half-angle of the tip arc, a derived parameter: the arc meets the sides Ys = -+Ws/2 where ro sin(beta_o) = Ws/2,
#: and the scene computes the value (tip_half_angle, like ms and Icg). As an expression asin(Ws / (2 ro)) of the
#: model its infinite derivative at ro = Ws/2 would turn, times the zero seed of the parameters, into NaN in every
#: automatic derivative of the right-hand side (docs/hard-cases.md)
beta_o = P["beta_o"]



#: Eq. 24: distance from C to where the curved tip starts (c1, c3), from the arc meeting the sides
ds0 = ds1 - ro + ro * sp.cos(beta_o)


def corner(S: ReferenceFrame, name: str) -> Vector:
    """Eqs. 19, 24: corners c1..c4 of the seal outline, from C."""
    return {
        "c1": ds0 * S.x - Ws / 2 * S.y,
        "c2": -ds2 * S.x - Ws / 2 * S.y,
        "c3": ds0 * S.x + Ws / 2 * S.y,
        "c4": -ds2 * S.x + Ws / 2 * S.y,
    }[name]


def tip_centre(S: ReferenceFrame) -> Vector:
    """Co, the centre of the tip arc, from C: (ds1 - ro) along Xs (Eqs. 25, 77-78)."""
    return (ds1 - ro) * S.x


def tip_point(S: ReferenceFrame, beta: sp.Expr) -> Vector:
    """Eqs. 25, 27-28: the point of the tip arc at angle beta from the seal's axis, from C.

    Co + ro (cos beta Xs + sin beta Ys) = (ds1 - ao) Xs + b5 Ys with ao = ro (1 - cos beta), b5 = ro sin beta.
    """
    return tip_centre(S) + ro * sp.cos(beta) * S.x + ro * sp.sin(beta) * S.y
