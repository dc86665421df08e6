"""The chamber gas model's pieces: numeric volumes, port openings, the orifice law (textbook formulas)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

from apexseal.derive import chambers, ports
from apexseal.derive.submodels.gas import orifice_flow
from apexseal.derive.symbols import P, theta

GEOM = {"r": 0.010, "L": 0.050, "H": 0.100, "Cr": 1e-4, "k": 0.030}


@pytest.mark.parametrize("embodiment", chambers.EMBODIMENTS)
def test_numeric_volumes_equal_the_sympy_ones(embodiment):
    """The chamber formulas (derive/chambers.py) on floats, as the volume check and the initial state evaluate
    them, and in sympy, as the gas model's equations hold them."""
    subs = {P[n]: v for n, v in GEOM.items()}
    geom = {n: GEOM[n] for n in ("r", "L", "Cr", "k")}
    A = chambers.lobe_area(embodiment, **geom)
    A_sym = chambers.lobe_area(embodiment, r=P["r"], L=P["L"], Cr=P["Cr"], k=P["k"], ops=chambers.symbolic())
    assert A == pytest.approx(float(A_sym.subs(subs)), rel=1e-12)
    for side, V in zip((1, -1), chambers.chamber_volumes(embodiment, P, theta), strict=True):
        for th in (0.0, 0.7, 2.0, 3.5, 5.9):
            num = chambers.chamber_volume(side, th, r=GEOM["r"], L=GEOM["L"], H=GEOM["H"], A_lobe=A,
                                          housing_circle=float(embodiment == "circolimacon"))
            assert num == pytest.approx(float(V.subs(subs).subs(theta, th)), rel=1e-10)


def _fractions(th, c, w):
    fa, fb = ports.open_fractions(theta, sp.Float(c), sp.Float(w))
    return float(fa.subs(theta, th)), float(fb.subs(theta, th))


def test_a_port_is_open_to_the_chamber_whose_arc_holds_it():
    c, w = math.radians(140), math.radians(36)  # the outlet of Table 1, datum 0
    assert _fractions(math.radians(0), c, w) == (1.0, 0.0)  # chamber a spans 0..180 deg
    assert _fractions(math.radians(200), c, w) == (0.0, 1.0)
    fa, fb = _fractions(math.radians(140), c, w)  # the seal at p1 is at the port's centre
    assert fa == pytest.approx(0.5) and fb == pytest.approx(0.5)
    fa, fb = _fractions(math.radians(-30), c, w)  # p2 (theta + pi = 150 deg) crosses it: 8 of 36 deg in b
    assert fa == pytest.approx(28 / 36) and fb == pytest.approx(8 / 36)
    for th in np.linspace(-7, 7, 41):  # the two always add up to the whole port, whatever the turn
        fa, fb = _fractions(th, c, w)
        assert fa + fb == pytest.approx(1.0) and -1e-12 <= fa <= 1 + 1e-12 and -1e-12 <= fb <= 1 + 1e-12


def _textbook(cd_a, p0, T0, p, gamma=1.4, R=287.0):
    """Isentropic nozzle flow (e.g. Anderson, Modern Compressible Flow; ISO 6358 form)."""
    crit = (2 / (gamma + 1)) ** (gamma / (gamma - 1))
    if p / p0 <= crit:  # choked
        return cd_a * p0 * math.sqrt(gamma / (R * T0)) * (2 / (gamma + 1)) ** ((gamma + 1) / (2 * (gamma - 1)))
    pr = p / p0
    return cd_a * p0 * math.sqrt(2 * gamma / ((gamma - 1) * R * T0) * (pr ** (2 / gamma) - pr ** ((gamma + 1) / gamma)))


@pytest.mark.parametrize("p_down", [1.0e5, 2.0e5, 3.0e5, 3.2e5, 4.5e5, 5.5e5, 5.99e5])
def test_orifice_flow_matches_the_textbook_subsonic_and_choked(p_down):
    law = float(orifice_flow(sp.Float(0.8e-4), sp.Float(6e5), sp.Float(300.0), sp.Float(p_down), sp.Float(1.4),
                             sp.Float(287.0)))
    assert law == pytest.approx(_textbook(0.8e-4, 6e5, 300.0, p_down), rel=1e-6)


def test_choked_flow_does_not_depend_on_the_downstream_pressure():
    """Evaluated as the model runs it: lowered to CasADi (generated/lower.py) and evaluated in doubles, where the
    flow between equal pressures is exactly zero (sympy's own multiprecision evaluation of the unevaluated
    ``Max_``/``Min_`` leaves a residue of 1e-122 there)."""
    import casadi as ca

    from apexseal.generated.lower import Lowering

    p_down, x = sp.Symbol("p_down", positive=True), ca.SX.sym("p_down")
    law = ca.Function("law", [x], [Lowering({p_down: x})(orifice_flow(1.0, 6e5, 300.0, p_down, 1.4, 287.0))])
    f = [float(law(p)) for p in (1e4, 1e5, 3e5)]
    assert f[0] == pytest.approx(f[1], rel=1e-12) and f[1] == pytest.approx(f[2], rel=1e-12)
    assert f[0] == pytest.approx(float(orifice_flow(1.0, 6e5, 300.0, sp.Float(1e4), sp.Float(1.4), 287.0)), rel=1e-12)
    assert float(law(6e5)) == 0.0


def test_unevaluated_max_and_min_survive_substitution_and_lower_to_fmax_fmin():
    """The gas model's Max_/Min_ are never evaluated, also when a substitution rebuilds them (sympy's Max compares
    its arguments pairwise, which cost most of the leakage model's cold derivation), evaluate to numbers, and lower
    like Max/Min."""
    import casadi as ca

    from apexseal.derive.submodels.laws import Max_, Min_
    from apexseal.generated.lower import Lowering

    a, b, c = sp.symbols("a b c", real=True)
    e = Max_(Min_(a, b, a + 1), 0)  # Min(a, a + 1) would drop a + 1 if evaluated

    def inner(m):
        return next(x for x in m.args if isinstance(x, Min_))

    assert len(inner(e).args) == 3
    r = e.subs(b, c)
    assert isinstance(r, Max_) and len(inner(r).args) == 3
    assert float(r.subs({a: -2.0, c: 0.5})) == 0.0 and float(r.subs({a: 0.2, c: 0.5})) == 0.2
    x = ca.SX.sym("x", 3)
    low = Lowering({a: x[0], b: x[1], c: x[2]})(e)
    f = ca.Function("f", [x], [low])
    assert float(f([0.3, 0.7, 0.0])) == pytest.approx(0.3) and float(f([-1.0, 0.7, 0.0])) == 0.0
