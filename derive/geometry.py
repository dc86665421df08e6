"""Geometry of the limaçon machine, Eqs. 1-9, derived from the housing curve.

The housing is the limaçon traced by the rotor apex p1: in polar form about the
pole o, ``Rh(psi) = 2 r sin(psi) + L`` (Eqs. 1-2). Everything here follows from
that curve: its Cartesian form (Eqs. 3-4), the normal angle ``lambda`` (Eq. 9),
the groove truncation (Eqs. 6-8) and the initial deflections (Eq. 9). The chamber
volumes (Eqs. 1-8) are in derive/chambers.py.
"""

from __future__ import annotations

import sympy as sp

from . import numbers
from .numbers import MachineNumbers, machine_numbers  # noqa: F401  (numeric Eqs. 4-8, sympy-free)
from .symbols import P, theta

r, L = P["r"], P["L"]
psi = sp.Symbol("psi", real=True)
Wg = P["Wg"]
Cr, k = sp.symbols("Cr k", positive=True)  # rotor-housing clearance and lobe-centre offset (Eqs. 5, 8)
b = sp.Symbol("b", positive=True)  # aspect ratio r/L (Eq. 4)

#: Eqs. 1-2: chord centre offset s and housing radius Rh at crank angle theta
stroke = 2 * r * sp.sin(theta)
Rh = 2 * r * sp.sin(theta) + L


def housing_point(angle: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """Eq. 3: apex p1 (on the housing) in the fixed frame Xo Yo."""
    rho = Rh.subs(theta, angle)
    return sp.expand_trig(rho * sp.cos(angle)), sp.expand_trig(rho * sp.sin(angle))


def housing_point_aspect(angle: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """Eq. 4: Eq. 3 written with the aspect ratio b = r/L."""
    xp, yp = housing_point(angle)
    return sp.simplify(xp.subs(r, b * L)), sp.simplify(yp.subs(r, b * L))


def looping_free_limit() -> sp.Expr:
    """The largest aspect ratio b = r/L for a dimple-free limaçon (Costa et al., quoted before Eq. 4).

    Derived: the curvature of rho = L (1 + 2 b sin psi) must not change sign; its
    numerator rho^2 + 2 rho'^2 - rho rho'' is smallest at psi = -pi/2, where it is
    L^2 (1 - 2b)(1 - 4b) (to within a positive factor), so b <= 1/4.
    """
    rho = L * (1 + 2 * b * sp.sin(psi))
    num = rho**2 + 2 * sp.diff(rho, psi) ** 2 - rho * sp.diff(rho, psi, 2)
    at_min = sp.factor(sp.simplify(num.subs(psi, -sp.pi / 2)))
    roots = sorted(sp.solve(sp.Eq(at_min, 0), b), key=lambda v: float(v))
    return roots[0]


def housing_normal_angle() -> sp.Expr:
    """Eq. 9: angle lambda between the housing normal at p1 and the radial (groove) axis.

    For a polar curve the normal leans from the radius by atan(rho'/rho).
    """
    rho = Rh.subs(theta, psi)
    return sp.atan(sp.diff(rho, psi) / rho).subs(psi, theta)


def truncation_angle() -> sp.Expr:
    """Eq. 7: the crank angle theta0 of the groove edge, where the limaçon's Yo reaches Wg/2.

    Solves y_p1(theta0) = Wg/2 (Eq. 3) for sin(theta0): a quadratic
    2 r s^2 + L s - Wg/2 = 0 whose positive root is printed as Eq. 7.
    """
    s = sp.Symbol("s", real=True)
    _, yp = housing_point(psi)
    quad = sp.expand(sp.expand_trig(yp).subs(sp.sin(psi), s).subs(sp.cos(psi) ** 2, 1 - s**2)) - Wg / 2
    quad = sp.expand(quad.subs(sp.cos(psi), sp.sqrt(1 - s**2)))
    roots = sp.solve(sp.Eq(quad, 0), s)
    pos = [rt for rt in roots if sp.N(rt.subs({r: 0.01, L: 0.05, Wg: 3e-3})) > 0]
    return sp.asin(pos[0])


def truncation_limacon() -> sp.Expr:
    """Eq. 6: truncation z = L - x_p1(theta0) for the limaçon-to-limaçon embodiment."""
    th0 = sp.Symbol("theta0", real=True)
    xp, _ = housing_point(th0)
    return L - xp


def lobe_radius() -> sp.Expr:
    """Eq. 5: radius of a circular rotor lobe through the apex (L - Cr from the chord centre), centre offset k."""
    return sp.sqrt((L - Cr) ** 2 + k**2)


def truncation_circular() -> sp.Expr:
    """Eq. 8: truncation z of a circular lobe (circolimaçon and limaçon-to-circular embodiments).

    The lobe circle, centred at (0, -k) from the chord centre, meets the groove
    edge line Y = Wg/2 at X = sqrt(Rlc^2 - (k + Wg/2)^2).
    """
    X = sp.Symbol("X", positive=True)
    circle = sp.Eq(X**2 + (Wg / 2 + k) ** 2, lobe_radius() ** 2)
    Xe = [s for s in sp.solve(circle, X) if s.could_extract_minus_sign() is False][0]
    return L - Cr - Xe


def initial_wall_deflection() -> sp.Expr:
    """Eq. 9: delta_w from the force balance of the seal at rest, Fs = kw delta_w (ks delta_s = kw delta_w as printed).

    The X component of the housing force is kw delta_w (Algorithm 2 with xs5 =
    delta_w); the spring pushes with its force at rest Fs (Eq. 39, ``SpringContact.rest_force``);
    nothing else acts at rest.
    """
    from .submodels.spring import SpringContact

    return numbers.initial_wall_deflection(spring_force=SpringContact.rest_force(P), kw=P["kw"])
