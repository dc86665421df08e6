"""Equations of motion, Eq. 80, by Kane's method.

Generalised speeds are u = (x', y', phi'). For each load F at the seal's material
point P, the generalised active force is F . dv_P/du_r; the inertia forces come
from the absolute acceleration of C and the seal's angular acceleration. The
result is a mass matrix M and a forcing vector f with M u' = f; nothing is
inverted symbolically (PyDy's practice). With ``inertia`` off, the groove frame
is treated as inertial: only the relative accelerations remain.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from sympy.physics.vector import Vector

from .kinematics import Kinematics, plain
from .submodels.base import Load
from .symbols import P, phid, udots, xd, yd

SPEEDS = (xd, yd, phid)


@dataclass(frozen=True)
class EquationsOfMotion:
    """Eq. 80 as M u' = f: the seal's mass matrix diag(ms, ms, Icg) and the rest of its three equations."""

    mass_matrix: sp.Matrix  # 3x3
    forcing: sp.Matrix  # 3x1, everything but the M u' terms
    generalized_active: sp.Matrix  # 3x1, sum of the loads' generalised forces
    inertial: sp.Matrix  # 3x1, -(generalised inertia forces) at u' = 0 (centrifugal, Coriolis, ...)


def partial_velocities(k: Kinematics, r_CP: Vector) -> list[Vector]:
    """dv_P/du_r for the seal's material point at r_CP (v_P = v_C + omega_S x r_CP), the velocities of the contact
    points of Eqs. 48, 64 and 69 differentiated by the speeds; Kane's form of Eq. 80."""
    v = k.C.vel(k.N) + k.S.ang_vel_in(k.N).cross(r_CP)
    return [v.diff(u, k.N, var_in_dcm=False) for u in SPEEDS]


def generalized_forces(k: Kinematics, loads: list[Load]) -> sp.Matrix:
    """F_r = sum over loads of F . dv_P/du_r (equivalently the forces and their moments about C): the right-hand
    sides of Eq. 80."""
    total = [sp.S.Zero] * 3
    for load in loads:
        for r, vr in enumerate(partial_velocities(k, load.r_CP)):
            total[r] += load.force.dot(vr)
    return sp.Matrix([plain(e) for e in total])


def build(k: Kinematics, loads: list[Load], inertia: bool) -> EquationsOfMotion:
    """Eq. 80: diag(ms, ms, Icg) [X1'', Y1'', phi''] = [sum Fx, sum Fy, sum M_CG], as M u' = f."""
    ms, Icg = P["ms"], P["Icg"]
    if inertia:
        a_C = k.C.vel(k.N).dt(k.N)  # Eqs. 14-15
        alpha = k.S.ang_acc_in(k.N)
    else:
        a_C = k.C.pos_from(k.Og).dt(k.G).dt(k.G)
        alpha = k.S.ang_acc_in(k.G)
    vC = [k.C.vel(k.N).diff(u, k.N, var_in_dcm=False) for u in SPEEDS]
    wS = [k.S.ang_vel_in(k.N).diff(u, k.N, var_in_dcm=False) for u in SPEEDS]
    minus_fstar = sp.Matrix([plain(ms * a_C.dot(vC[r]) + Icg * alpha.dot(wS[r])) for r in range(3)])
    M = minus_fstar.jacobian(sp.Matrix(udots))
    inertial = sp.expand(minus_fstar - M * sp.Matrix(udots))
    F = generalized_forces(k, loads)
    assert all(s not in inertial.free_symbols for s in udots)
    return EquationsOfMotion(M, F - inertial, F, inertial)
