"""Where the seal touches the housing, the groove and the spring, Eqs. 17-47.

Contact rules (the paper's, Section 4.1):

* the housing touches the tip arc at s5, which stays on the groove axis X (Eq. 29);
  the housing wall of the model is the line X = ds1 - delta_w of the groove frame;
* the groove mouth corners g1, g3 (Eqs. 17-18) touch the seal sides at i1, i2, the
  feet of the perpendiculars from g1, g3 onto the sides (Eqs. 20-23);
* the back corners c2, c4 touch the groove walls Y = -+Wg/2 (at g2, g4);
* the spring acts along the groove axis on the back face, at s6 (Eqs. 35-36).

Each gap is a signed distance, negative when the bodies overlap.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from sympy.physics.vector import Vector

from . import seal_shape as shape
from .kinematics import Kinematics
from .symbols import P, phi, x, y

Ws, Wg, ds1, ds2, ro = P["Ws"], P["Wg"], P["ds1"], P["ds2"], P["ro"]
zeta0, delta_w, delta_s = P["zeta0"], P["delta_w"], P["delta_s"]

#: X of the groove mouth corners g1, g3 in the groove frame (Eqs. 17-18)
X_mouth = ds1 - zeta0 - delta_w


@dataclass(frozen=True)
class ContactGeometry:
    """Vectors from C (in frames of ``k``) and gaps, as time-dependent sympy expressions (Eqs. 17-47; each field
    names its equation)."""

    r_g1: Vector  # from Og, Eq. 17
    r_g3: Vector  # from Og, Eq. 18
    l2: sp.Expr  # Eq. 22: c2 to i1 along Xs
    l4: sp.Expr  # Eq. 23: c4 to i2 along Xs
    l1: sp.Expr  # i1 to c1 along Xs (after Eq. 47)
    l3: sp.Expr  # i2 to c3 along Xs
    r_i1: Vector  # Eq. 20
    r_i2: Vector  # Eq. 21
    r_c2: Vector  # Eq. 19
    r_c4: Vector  # Eq. 19
    beta: sp.Expr  # Eq. 31
    r_s5: Vector  # Eqs. 25-26, from C
    xs5: sp.Expr  # Eq. 33: penetration of the tip into the housing wall
    b6: sp.Expr  # Eq. 36: c2 to s6 along the back face
    r_s6: Vector  # Eq. 35: spring contact point, from C
    X_s6: sp.Expr  # X of s6 in the groove frame (Eq. 37)
    spring_compression: sp.Expr  # Eq. 38: delta_s less the outward travel of s6
    gaps: dict[str, sp.Expr]  # b1..b4, Eqs. 40-43
    r_s1: Vector  # Eqs. 44-47: mid-points of the exposed and gap-side faces, from C
    r_s2: Vector
    r_s3: Vector
    r_s4: Vector


def solve_tip_angle() -> sp.Expr:
    """Eqs. 29-31: beta from the constraint that s5 stays on the groove axis.

    Y(s5) = y + (ds1 - ro) sin(phi) + ro sin(beta + phi) = 0, solved for the
    branch with beta -> 0 when the seal is centred (x = y = phi = 0).
    """
    beta = sp.Symbol("beta", real=True)
    ys5 = y + (ds1 - ro) * sp.sin(phi) + ro * sp.sin(beta + phi)
    u = sp.Symbol("u", real=True)  # u = beta + phi
    sols = sp.solve(sp.Eq(ys5.subs(beta, u - phi), 0), u)
    centred = {x: 0, y: 0, phi: 0}
    branch = [s for s in sols if sp.simplify(s.subs(centred)) == 0][0]
    return branch - phi


def build(k: Kinematics) -> ContactGeometry:
    """The contact geometry of Eqs. 17-47: the groove's mouth corners (Eqs. 17-18), the seal's corners and contact
    points (Eqs. 19-23), the tip contact s5 and its penetration (Eqs. 25-34), the spring's point s6 (Eqs. 35-38),
    the gaps b1..b4 (Eqs. 40-43) and the pressure points s1..s4 (Eqs. 44-47)."""
    G, S = k.G, k.S
    rc = k.C.pos_from(k.Og)
    r_g1 = X_mouth * G.x - Wg / 2 * G.y
    r_g3 = X_mouth * G.x + Wg / 2 * G.y
    r_c2 = shape.corner(S, "c2")
    r_c4 = shape.corner(S, "c4")

    # i1, i2: feet of g1, g3 on the sides; l2, l4 measured from the back corners (Eqs. 20-23)
    l2 = (r_g1 - rc).dot(S.x) + ds2
    l4 = (r_g3 - rc).dot(S.x) + ds2
    r_i1 = (l2 - ds2) * S.x - Ws / 2 * S.y
    r_i2 = (l4 - ds2) * S.x + Ws / 2 * S.y
    l1 = shape.ds0 + ds2 - l2
    l3 = shape.ds0 + ds2 - l4

    # s5 and the housing penetration (Eqs. 25-33)
    beta = solve_tip_angle()
    r_s5 = shape.tip_point(S, beta)
    xs5 = (rc + r_s5).dot(G.x) - (ds1 - delta_w)

    # s6: the back face meets the groove axis Y = 0 (Eqs. 35-37)
    s = sp.Symbol("s", real=True)  # coordinate along Ys on the back face, from its centre
    r_face = -ds2 * S.x + s * S.y
    s6 = sp.solve(sp.Eq((rc + r_face).dot(G.y), 0), s)[0]
    b6 = s6 + Ws / 2
    r_s6 = r_face.subs(s, s6)
    X_s6 = (rc + r_s6).dot(G.x)
    # at rest (x = y = phi = 0) s6 is at X = -ds2 with the spring compressed by delta_s (Eq. 38)
    spring_compression = delta_s - (X_s6 + ds2)

    # b1..b4: signed gaps at g1..g4, measured along the contact normals (Eqs. 40-43)
    gaps = {
        "b1": (rc + r_c2 - r_g1).dot(S.y),
        "b2": (rc + r_c2 - r_g1).dot(G.y),
        "b3": -(rc + r_c4 - r_g3).dot(S.y),
        "b4": -(rc + r_c4 - r_g3).dot(G.y),
    }

    # mid-points of i1-c1, c2-i1, i2-c3, c4-i2 (Eqs. 44-47)
    r_s1 = (r_i1 + shape.corner(S, "c1")) / 2
    r_s2 = (r_c2 + r_i1) / 2
    r_s3 = (r_i2 + shape.corner(S, "c3")) / 2
    r_s4 = (r_c4 + r_i2) / 2

    return ContactGeometry(r_g1, r_g3, l2, l4, l1, l3, r_i1, r_i2, r_c2, r_c4, beta, r_s5, xs5, b6, r_s6,
                           X_s6, spring_compression, gaps, r_s1, r_s2, r_s3, r_s4)
