"""Chamber volumes Va(theta), Vb(theta) of the three embodiments (Eqs. 1-8 and Fig. 1), derived in sympy.

The rotor chord p1 p2 passes through the pole o at crank angle theta (Eqs. 1-2), so the line of the chord
cuts the housing in two: chamber a on the chord's +Yr side (the seal's +Ys side, Eq. 75), chamber b on its
-Yr side. Each chamber is the part of the housing on its side of the chord less the rotor lobe on that side
(the region between the chord and the lobe), times the machine depth H::

    Va = H (A_housing_a(theta) - A_lobe),     Vb = H (A_housing_b(theta) - A_lobe)

Housing curves (Section 2):

* limaçon (limaçon-to-limaçon, limaçon-to-circular): Rh(psi) = 2 r sin(psi) + L about the pole (Eq. 2); the
  half on the +Yr side is the sector from theta to theta + pi, 1/2 integral Rh^2 dpsi;
* circle (circolimaçon): the paper prints no formula; our reading is the circle through the apices' extreme
  positions (+-L, 0) centred on the Yo axis at (0, 2 r), radius sqrt(L^2 + 4 r^2), which encloses the apex
  trace (Eq. 3) and touches it at theta = 0 and pi. The part on the +Yr side is a circular segment.

Rotor lobes (the two lobes are mirror images, so both chambers lose the same area):

* limaçon lobe (limaçon-to-limaçon): the housing's smaller half seen from the chord centre m, brought in by
  the rotor-housing clearance Cr, rho(alpha) = L - Cr - 2 r sin(alpha), alpha in [0, pi]: at theta = pi the
  lobe fits the housing with a uniform radial clearance Cr (the chamber's clearance volume);
* circular lobe (circolimaçon, limaçon-to-circular): the circle through (+-(L - Cr), 0) centred on the Yr
  axis at distance k on the other side of the chord, radius Rlc = sqrt((L - Cr)^2 + k^2) (Eq. 5).

``H`` is ``P["H"]``; the lobe's clearance and centre offset are ``P["Cr"]``, ``P["k"]``.
"""

from __future__ import annotations

import sympy as sp

from .symbols import P, theta

EMBODIMENTS = ("limacon-to-limacon", "circolimacon", "limacon-to-circular")

r, L, H, Cr, k = P["r"], P["L"], P["H"], P["Cr"], P["k"]
_psi = sp.Symbol("psi", real=True)
_t = sp.Symbol("t", real=True)


def segment_area(radius: sp.Expr, h: sp.Expr) -> sp.Expr:
    """Area of the part of a disc of ``radius`` beyond a line at signed distance ``h`` from its centre.

    Derived as the integral of the chord length 2 sqrt(R^2 - t^2) from t = h to R.
    """
    R = sp.Symbol("R", positive=True)
    hh = sp.Symbol("h", real=True)
    area = sp.integrate(2 * sp.sqrt(R**2 - _t**2), (_t, hh, R), conds="none")
    area = sp.simplify(area)
    return area.subs({R: radius, hh: h})


def housing_circle() -> tuple[sp.Expr, sp.Expr]:
    """Centre height on the Yo axis and radius of the circolimaçon's housing circle (our reading, see above)."""
    return 2 * r, sp.sqrt(L**2 + 4 * r**2)


def housing_area(embodiment: str, side: int = 1) -> sp.Expr:
    """Area of the housing on the chord's +Yr side (side=1, chamber a) or -Yr side (side=-1, chamber b)."""
    if embodiment not in EMBODIMENTS:
        raise ValueError(f"embodiment {embodiment!r}: allowed {', '.join(EMBODIMENTS)}")
    if embodiment == "circolimacon":
        c, R = housing_circle()
        # signed distance of the circle's centre from the chord, on the chamber's side (normal (-sin, cos) side)
        d = side * c * sp.cos(theta)
        return sp.pi * R**2 - segment_area(R, d)
    lo = theta if side == 1 else theta + sp.pi
    rho = 2 * r * sp.sin(_psi) + L  # Eq. 2
    return sp.simplify(sp.integrate(rho**2, (_psi, lo, lo + sp.pi)) / 2)


def lobe_area(embodiment: str) -> sp.Expr:
    """Area between the chord and one rotor lobe (the same for both lobes, which are mirror images)."""
    if embodiment not in EMBODIMENTS:
        raise ValueError(f"embodiment {embodiment!r}: allowed {', '.join(EMBODIMENTS)}")
    if embodiment == "limacon-to-limacon":
        rho = L - Cr - 2 * r * sp.sin(_psi)
        return sp.expand(sp.integrate(rho**2, (_psi, 0, sp.pi)) / 2)
    Rlc = sp.sqrt((L - Cr) ** 2 + k**2)  # Eq. 5
    return segment_area(Rlc, k)


def lobe_curve(embodiment: str) -> tuple[sp.Expr, sp.Expr]:
    """The a-side lobe in the rotor frame (origin m, Xr along the chord to p1) as (X, Y) of a parameter psi in
    [0, pi] (for drawing and for the polygon check)."""
    if embodiment == "limacon-to-limacon":
        rho = L - Cr - 2 * r * sp.sin(_psi)
        return rho * sp.cos(_psi), rho * sp.sin(_psi)
    Rlc = sp.sqrt((L - Cr) ** 2 + k**2)
    a0 = sp.atan2(k, L - Cr)  # the circle meets the chord at angles a0 and pi - a0 about its centre (0, -k)
    ang = a0 + _psi * (sp.pi - 2 * a0) / sp.pi
    return Rlc * sp.cos(ang), -k + Rlc * sp.sin(ang)


def chamber_volumes(embodiment: str) -> tuple[sp.Expr, sp.Expr]:
    """Va(theta), Vb(theta) in m^3 (see the module docstring)."""
    A = lobe_area(embodiment)
    return H * (housing_area(embodiment, 1) - A), H * (housing_area(embodiment, -1) - A)


PSI = _psi
