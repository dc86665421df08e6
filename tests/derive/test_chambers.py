"""Chamber volumes (derive/chambers.py): its closed forms against the integrals they stand for, and the volumes
against the polygon area of the sampled housing and rotor curves."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

from apexseal.derive import chambers
from apexseal.derive.symbols import P, theta

PSI = sp.Symbol("psi", real=True)
r, L, Cr = P["r"], P["L"], P["Cr"]

#: r, L, H, Cr, k; k = 30 mm lets the circular lobes fit inside the housing (a valid machine)
GEOM = {"r": 0.010, "L": 0.050, "H": 0.100, "Cr": 1e-4, "k": 0.030}


#: the polygons' sampling error, m^3: 2e-6 of H pi L^2 (the clearance volume at theta = pi is ~1e-6 m^3)
SAMPLING = 2e-6 * GEOM["H"] * math.pi * GEOM["L"] ** 2


def _subs():
    return {P[n]: v for n, v in GEOM.items()}


def _shoelace(xy: np.ndarray) -> float:
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _clip(poly: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Sutherland-Hodgman: the part of a polygon where p . n >= 0 (a half-plane through the origin)."""
    out = []
    for i in range(len(poly)):
        a, b = poly[i], poly[(i + 1) % len(poly)]
        da, db = a @ n, b @ n
        if da >= 0:
            out.append(a)
        if (da >= 0) != (db >= 0):
            out.append(a + (b - a) * da / (da - db))
    return np.array(out)


def _housing(embodiment: str, m: int = 20000) -> np.ndarray:
    r, L = GEOM["r"], GEOM["L"]
    s = np.linspace(0, 2 * math.pi, m, endpoint=False)
    if embodiment == "circolimacon":
        R = math.hypot(L, 2 * r)
        return np.c_[R * np.cos(s), 2 * r + R * np.sin(s)]
    rho = 2 * r * np.sin(s) + L  # Eq. 3: the apex trace
    return np.c_[rho * np.cos(s), rho * np.sin(s)]


def _lobe(embodiment: str, th: float, side: int, m: int = 4000) -> np.ndarray:
    X, Y = chambers.lobe_curve(embodiment, PSI, P)
    f = sp.lambdify(PSI, [X.subs(_subs()), Y.subs(_subs())], "numpy")
    s = np.linspace(0, math.pi, m)
    xr, yr = (np.broadcast_to(np.asarray(v, float), s.shape) for v in f(s))
    yr = side * yr
    c = 2 * GEOM["r"] * math.sin(th)  # chord centre m on the chord, s = 2 r sin(theta) from the pole (Eq. 1)
    e1, e2 = np.array([math.cos(th), math.sin(th)]), np.array([-math.sin(th), math.cos(th)])
    return c * e1 + np.outer(xr, e1) + np.outer(yr, e2)


@pytest.mark.parametrize("embodiment", chambers.EMBODIMENTS)
def test_volumes_match_the_polygon_area_of_the_drawn_geometry(embodiment):
    va, vb = (sp.lambdify(theta, v.subs(_subs()), "numpy") for v in chambers.chamber_volumes(embodiment, P, theta))
    housing = _housing(embodiment)
    for th in np.radians([0.0, 37.0, 90.0, 151.0, 180.0, 233.0, 300.0]):
        n = np.array([-math.sin(th), math.cos(th)])
        for side, V in ((1, va), (-1, vb)):
            area = _shoelace(_clip(housing, side * n)) - abs(_shoelace(_lobe(embodiment, th, side)))
            assert float(V(th)) == pytest.approx(GEOM["H"] * area, rel=2e-6, abs=SAMPLING)
            assert float(V(th)) > 0


def test_symmetric_machine_chambers_are_pi_out_of_phase():
    for embodiment in chambers.EMBODIMENTS:
        va, vb = chambers.chamber_volumes(embodiment, P, theta)
        diff = (va.subs(theta, theta + sp.pi) - vb).subs(_subs())
        assert all(abs(float(diff.subs(theta, t))) < 1e-15 for t in (0.1, 1.3, 2.9, 4.4))


def test_limacon_chamber_displacement_is_8rLH():
    va, _ = chambers.chamber_volumes("limacon-to-limacon", P, theta)
    swept = sp.simplify(va.subs(theta, 0) - va.subs(theta, sp.pi))
    assert sp.simplify(swept - 8 * P["r"] * P["L"] * P["H"]) == 0


def test_unknown_embodiment_is_refused():
    with pytest.raises(ValueError, match="embodiment 'wankel'"):
        chambers.chamber_volumes("wankel", P, theta)


def test_segment_area_is_the_integral_of_the_chord_length():
    R, h, t = sp.Symbol("R", positive=True), sp.Symbol("h", real=True), sp.Symbol("t", real=True)
    integral = sp.integrate(2 * sp.sqrt(R**2 - t**2), (t, h, R), conds="none")
    closed = chambers.segment_area(R, h, ops=chambers.symbolic())
    for R_, h_ in ((1.0, 0.3), (1.0, -0.8), (0.05, 0.02), (2.0, 0.0)):
        at = {R: R_, h: h_}
        assert float(integral.subs(at)) == pytest.approx(float(closed.subs(at)), rel=1e-12)


@pytest.mark.parametrize("side", [1, -1])
def test_limacon_housing_area_is_half_the_integral_of_rh_squared(side):
    """Eq. 2: 1/2 integral of Rh^2 over the half of the housing on the chamber's side of the chord."""
    lo = theta if side == 1 else theta + sp.pi
    integral = sp.integrate((2 * r * sp.sin(PSI) + L) ** 2, (PSI, lo, lo + sp.pi)) / 2
    closed = chambers.housing_area(side, theta, r=r, L=L, housing_circle=0, ops=chambers.symbolic())
    assert sp.simplify(integral - closed) == 0


def test_limacon_lobe_area_is_half_the_integral_of_rho_squared():
    integral = sp.integrate((L - Cr - 2 * r * sp.sin(PSI)) ** 2, (PSI, 0, sp.pi)) / 2
    closed = chambers.lobe_area("limacon-to-limacon", r=r, L=L, Cr=Cr, ops=chambers.symbolic())
    assert sp.expand(integral - closed) == 0
