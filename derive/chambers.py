"""Chamber volumes Va(theta), Vb(theta) of the three embodiments (Eqs. 1-8 and Fig. 1): the one place they are written.

The rotor chord p1 p2 passes through the pole o at crank angle theta (Eqs. 1-2), so the line of the chord
cuts the housing in two: chamber a on the chord's +Yr side (the seal's +Ys side, Eq. 75), chamber b on its
-Yr side. Each chamber is the part of the housing on its side of the chord less the rotor lobe on that side
(the region between the chord and the lobe), times the machine depth H::

    Va = H (A_housing_a(theta) - A_lobe),     Vb = H (A_housing_b(theta) - A_lobe)

Housing curves (Section 2):

* limaçon (limaçon-to-limaçon, limaçon-to-circular): Rh(psi) = 2 r sin(psi) + L about the pole (Eq. 2); the
  half on the +Yr side is the sector from theta to theta + pi, 1/2 integral Rh^2 dpsi
  = pi r^2 + pi L^2 / 2 + 4 r L cos(theta);
* circle (circolimaçon): the paper prints no formula; our reading is the circle through the apices' extreme
  positions (+-L, 0) centred on the Yo axis at (0, 2 r), radius sqrt(L^2 + 4 r^2), which encloses the apex
  trace (Eq. 3) and touches it at theta = 0 and pi. The part on the +Yr side is the disc less the circular
  segment beyond the chord.

Rotor lobes (the two lobes are mirror images, so both chambers lose the same area):

* limaçon lobe (limaçon-to-limaçon): the housing's smaller half seen from the chord centre m, brought in by
  the rotor-housing clearance Cr, rho(alpha) = L - Cr - 2 r sin(alpha), alpha in [0, pi]: at theta = pi the
  lobe fits the housing with a uniform radial clearance Cr (the chamber's clearance volume); its area
  1/2 integral rho^2 dalpha = (pi a^2 - 8 r a + 2 pi r^2) / 2 with a = L - Cr;
* circular lobe (circolimaçon, limaçon-to-circular): the circle through (+-(L - Cr), 0) centred on the Yr
  axis at distance k on the other side of the chord, radius Rlc = sqrt((L - Cr)^2 + k^2) (Eq. 5); its area
  is the segment of that circle beyond the chord.

The integrals are written in closed form; tests/derive/test_chambers.py integrates them in sympy and compares
the volumes with polygon areas of the drawn housing and lobes.

Each formula is written once and evaluated with the operations ``ops`` it is given: :data:`NUMERIC` (``math``,
sympy-free: the scene checks, the gas model's derived parameters and initial state) or :func:`symbolic`
(sympy: the gas model's equations, derive/submodels/gas.py). The housing is chosen by a number,
``housing_circle`` (1 circle, 0 limaçon), so that the gas model's one expression serves every embodiment with
the housing kind and the lobe area as parameters.
"""

from __future__ import annotations

import math
from functools import lru_cache
from types import SimpleNamespace

EMBODIMENTS = ("limacon-to-limacon", "circolimacon", "limacon-to-circular")

#: the operations on floats; ``nonneg`` keeps a square root's argument, >= 0 in exact arithmetic, off rounding's
#: negative side
NUMERIC = SimpleNamespace(pi=math.pi, cos=math.cos, acos=math.acos, sqrt=math.sqrt, nonneg=lambda x: max(x, 0.0))


@lru_cache(maxsize=1)
def symbolic() -> SimpleNamespace:
    """The operations on sympy expressions (sympy is imported here, not with the module)."""
    import sympy as sp

    return SimpleNamespace(pi=sp.pi, cos=sp.cos, acos=sp.acos, sqrt=sp.sqrt, nonneg=lambda x: x)


def _check(embodiment: str) -> None:
    if embodiment not in EMBODIMENTS:
        raise ValueError(f"embodiment {embodiment!r}: allowed {', '.join(EMBODIMENTS)}")


def segment_area(R, h, *, ops=NUMERIC):
    """Area of the part of a disc of radius R beyond a line at signed distance h from its centre:
    the integral of the chord length 2 sqrt(R^2 - t^2) from t = h to R."""
    return R * R * ops.acos(h / R) - h * ops.sqrt(ops.nonneg(R * R - h * h))


def housing_area(side: int, theta, *, r, L, housing_circle, ops=NUMERIC):
    """Area of the housing on the chord's +Yr side (side=1, chamber a) or -Yr side (side=-1, chamber b) at crank
    angle theta: the circolimaçon's circle (housing_circle = 1) or the limaçon of Eq. 2 (housing_circle = 0)."""
    R = ops.sqrt(L * L + 4 * r * r)  # the circle: centre (0, 2 r), on the chamber's side of the chord by d
    d = side * 2 * r * ops.cos(theta)
    circle = ops.pi * R * R - segment_area(R, d, ops=ops)
    limacon = ops.pi * r * r + ops.pi * L * L / 2 + side * 4 * r * L * ops.cos(theta)  # 1/2 integral Rh^2, Eq. 2
    return housing_circle * circle + (1 - housing_circle) * limacon


def lobe_area(embodiment: str, *, r, L, Cr=0.0, k=0.0, ops=NUMERIC):
    """Area between the chord and one rotor lobe (the same for both lobes, which are mirror images)."""
    _check(embodiment)
    if embodiment == "limacon-to-limacon":  # 1/2 integral of (L - Cr - 2 r sin a)^2 over [0, pi]
        a = L - Cr
        return (ops.pi * a * a - 8 * r * a + 2 * ops.pi * r * r) / 2
    R = ops.sqrt((L - Cr) ** 2 + k**2)  # Eq. 5
    return segment_area(R, k, ops=ops)


def chamber_volume(side: int, theta, *, r, L, H, A_lobe, housing_circle, ops=NUMERIC):
    """Va (side=1) or Vb (side=-1) at crank angle theta, H (housing area - A_lobe)."""
    return H * (housing_area(side, theta, r=r, L=L, housing_circle=housing_circle, ops=ops) - A_lobe)


def chamber_volumes(embodiment: str, P, theta):
    """Va(theta), Vb(theta) of an embodiment in m^3, sympy expressions of ``P["r"], P["L"], P["H"], P["Cr"],
    P["k"]`` and ``theta`` (the parameter symbols by name, :data:`.symbols.P`, and the crank angle's symbol)."""
    _check(embodiment)
    ops = symbolic()
    r, L = P["r"], P["L"]
    A = lobe_area(embodiment, r=r, L=L, Cr=P["Cr"], k=P["k"], ops=ops)
    circle = 1 if embodiment == "circolimacon" else 0
    return tuple(chamber_volume(side, theta, r=r, L=L, H=P["H"], A_lobe=A, housing_circle=circle, ops=ops)
                 for side in (1, -1))


def lobe_curve(embodiment: str, psi, P):
    """The a-side lobe in the rotor frame (origin m, Xr along the chord to p1) as sympy (X, Y) of a parameter
    ``psi`` in [0, pi] (for drawing and for the polygon check), with the parameter symbols ``P`` by name
    (:data:`.symbols.P`)."""
    import sympy as sp

    _check(embodiment)
    r, L, Cr, k = P["r"], P["L"], P["Cr"], P["k"]
    if embodiment == "limacon-to-limacon":
        rho = L - Cr - 2 * r * sp.sin(psi)
        return rho * sp.cos(psi), rho * sp.sin(psi)
    Rlc = sp.sqrt((L - Cr) ** 2 + k**2)
    a0 = sp.atan2(k, L - Cr)  # the circle meets the chord at angles a0 and pi - a0 about its centre (0, -k)
    ang = a0 + psi * (sp.pi - 2 * a0) / sp.pi
    return Rlc * sp.cos(ang), -k + Rlc * sp.sin(ang)
