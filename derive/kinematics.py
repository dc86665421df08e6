"""Frames, points and seal kinematics, Eqs. 10-15, derived by differentiation.

Frames (all right-handed, z out of the page):

* ``N``  fixed frame Xo Yo, origin at the limaçon pole o;
* ``R``  rotor frame X1 Y1 (unit vectors i, j), same origin, turned by theta = omega t;
* ``G``  groove frame X Y, parallel to ``R``, origin Og on the rotor chord at
  2 r sin(theta) + Li from the pole (the rotor slides along its chord, Eq. 12);
* ``S``  seal frame Xs Ys at the seal's centre of gravity C, turned by phi from ``G`` (Eq. 11).

Velocities and accelerations come from ``Vector.dt`` in the fixed frame; nothing
here is copied from the printed results.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from sympy.physics.mechanics import Point, ReferenceFrame, dynamicsymbols
from sympy.physics.vector import Vector

from .symbols import P, phi, theta, to_plain, x, y

t = dynamicsymbols._t
#: crank angle as a function of time; d(theta)/dt = omega is substituted at the end
theta_t = dynamicsymbols("theta")
#: the crank angle's time functions as plain symbols at constant speed (Eq. 13: theta' = omega, theta'' = 0),
#: replaced in one pass over the tree: the node itself where it occurs, never its parts (xreplace; ``subs`` compared
#: every rebuilt subtree with the old one, most of the chamber gas model's derivation)
_CRANK = {theta_t.diff(t, 2): sp.S.Zero, theta_t.diff(t): P["omega"], theta_t: theta}


def plain(expr: sp.Expr) -> sp.Expr:
    """Turn a time-dependent expression into one of (theta, state symbols, parameters)."""
    expr = sp.sympify(expr).xreplace(_CRANK)
    return to_plain(expr)


@dataclass(frozen=True)
class Kinematics:
    """The frames and points of Eqs. 10-12: N fixed, R the rotor (turning at omega), G the groove, S the seal (turned
    by phi in the groove); Og the groove's origin and C the seal's centre of gravity."""

    N: ReferenceFrame
    R: ReferenceFrame
    G: ReferenceFrame
    S: ReferenceFrame
    o: Point
    Og: Point
    C: Point

    def components(self, vec: Vector, frame: ReferenceFrame | None = None) -> tuple[sp.Expr, sp.Expr]:
        """(X, Y) components of a planar vector in ``frame`` (default: groove frame), as plain expressions."""
        frame = frame or self.G
        return plain(vec.dot(frame.x)), plain(vec.dot(frame.y))

    def point_on_seal(self, name: str, r_CP: Vector) -> Point:
        """A material point of the seal at ``r_CP`` from C, with its velocity by rigid-body kinematics (the contact
        points' velocities of Eqs. 48, 64 and 69)."""
        p = self.C.locatenew(name, r_CP)
        p.v2pt_theory(self.C, self.N, self.S)
        return p

    def relative_velocity(self, r_CP: Vector) -> Vector:
        """Velocity of the seal's material point at r_CP relative to the groove (rotor), Eqs. 50, 56, 58, 60, 70.

        v_seal - v_groove = (v_Og + w x rc + rc' + (w + phi') x r) - (v_Og + w x rc + w x r) = rc' + phi' x r.
        """
        rc_dot = self.C.pos_from(self.Og).dt(self.G)
        return rc_dot + self.S.ang_vel_in(self.G).cross(r_CP)


def build() -> Kinematics:
    """Eqs. 10-12: the frames and the position of C."""
    N = ReferenceFrame("N")
    R = N.orientnew("R", "Axis", [theta_t, N.z])
    G = R.orientnew("G", "Axis", [0, R.z])
    S = G.orientnew("S", "Axis", [phi, G.z])
    o = Point("o")
    o.set_vel(N, 0)
    Og = o.locatenew("Og", (2 * P["r"] * sp.sin(theta_t) + P["Li"]) * R.x)
    Og.set_vel(N, Og.pos_from(o).dt(N))
    C = Og.locatenew("C", x * G.x + y * G.y)  # Eq. 10
    C.set_vel(N, C.pos_from(o).dt(N))
    return Kinematics(N, R, G, S, o, Og, C)


def frame_rotation(k: Kinematics) -> sp.Matrix:
    """Eq. 11: rows are Xs, Ys in terms of X, Y (the direction cosine matrix)."""
    return sp.Matrix([[plain(k.S.x.dot(k.G.x)), plain(k.S.x.dot(k.G.y))],
                      [plain(k.S.y.dot(k.G.x)), plain(k.S.y.dot(k.G.y))]])


def position_rotor(k: Kinematics) -> tuple[sp.Expr, sp.Expr]:
    """Eq. 12: position of C from the pole in the rotor frame (i, j)."""
    return k.components(k.C.pos_from(k.o), k.R)


def velocity_rotor(k: Kinematics) -> tuple[sp.Expr, sp.Expr]:
    """Eq. 13: absolute velocity of C, in rotor-frame components."""
    return k.components(k.C.vel(k.N), k.R)


def acceleration_rotor(k: Kinematics) -> tuple[sp.Expr, sp.Expr]:
    """Eqs. 14-15: absolute acceleration of C, in rotor-frame components (X1'', Y1'')."""
    return k.components(k.C.vel(k.N).dt(k.N), k.R)
