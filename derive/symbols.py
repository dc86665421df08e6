"""Symbols of the seal model: generalised coordinates, parameters and inputs.

Every physical parameter is a symbol, so one compiled library serves every value
(the parameter vector of the generated Functions follows :data:`PARAMETERS`).
Names are the paper's symbols written in ASCII.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from sympy.physics.mechanics import dynamicsymbols


@dataclass(frozen=True)
class Parameter:
    name: str
    unit: str
    meaning: str


#: The parameter vector, in order. (Eq. numbers say where each first appears.)
PARAMETERS: tuple[Parameter, ...] = (
    Parameter("omega", "rad/s", "rotor angular speed, constant (Eq. 13)"),
    Parameter("r", "m", "radius of the limaçon base circle (Eq. 1)"),
    Parameter("L", "m", "half chord of the rotor (Eq. 2)"),
    Parameter("Li", "m", "distance from the chord centre to the seal's centre of gravity at rest (Eq. 12)"),
    Parameter("zeta0", "m", "initial protrusion of the seal out of the groove (Eq. 17)"),
    Parameter("delta_w", "m", "initial deflection of the housing wall (Eq. 9)"),
    Parameter("Ws", "m", "seal width (Eq. 19)"),
    Parameter("Wg", "m", "groove width (Eq. 17)"),
    Parameter("ds1", "m", "centre of gravity to the seal tip along Xs (Eq. 16)"),
    Parameter("ds2", "m", "centre of gravity to the seal back face along Xs (Eq. 16)"),
    Parameter("ro", "m", "radius of the seal's tip arc (Eq. 27)"),
    Parameter("beta_o", "rad", "half-angle of the tip arc, asin(Ws / (2 ro)) (Eqs. 24, 76-78); computed by the scene"),
    Parameter("Bs", "m", "seal length along the machine axis (Eq. 76)"),
    Parameter("ms", "kg", "seal mass (Eq. 80)"),
    Parameter("Icg", "kg m^2", "seal moment of inertia about its centre of gravity (Eq. 80)"),
    Parameter("ks", "N/m", "spring stiffness (Eq. 39)"),
    Parameter("delta_s", "m", "spring preload deflection (Eq. 9)"),
    Parameter("kw", "N/m", "equivalent housing stiffness along the groove axis (Eq. 34)"),
    Parameter("kg1", "N/m", "groove stiffness at g1 (Algorithm 1)"),
    Parameter("kg2", "N/m", "groove stiffness at g2 (Algorithm 1)"),
    Parameter("kg3", "N/m", "groove stiffness at g3 (Algorithm 1)"),
    Parameter("kg4", "N/m", "groove stiffness at g4 (Algorithm 1)"),
    Parameter("cw", "N s/m", "housing contact damping (Eq. 67)"),
    Parameter("cr", "N s/m", "seal-groove contact damping (Eq. 55)"),
    Parameter("cs", "N s/m", "seal-spring contact damping (Eq. 73)"),
    Parameter("mu1", "1", "seal-housing friction coefficient (Algorithm 2)"),
    Parameter("mu2", "1", "seal-groove friction coefficient (Algorithm 1)"),
    Parameter("mus", "1", "seal-spring friction coefficient (Eq. 73)"),
    Parameter("v_eps", "m/s", "sliding-speed width of the friction regularisation tanh(v/v_eps)"),
)

PARAMETER_NAMES: tuple[str, ...] = tuple(p.name for p in PARAMETERS)

#: sympy symbols of the parameters, positive where the physics says so
P: dict[str, sp.Symbol] = {
    p.name: sp.Symbol(p.name, positive=p.name not in ("zeta0", "delta_w", "delta_s"), real=True)
    for p in PARAMETERS
}

#: chamber pressures: time-varying inputs, not parameters (chamber a on +Ys, b on -Ys; Eq. 75)
Pa, Pb = sp.symbols("Pa Pb", real=True)
INPUT_NAMES: tuple[str, ...] = ("Pa", "Pb")

#: time and crank angle; theta = omega t (Eq. 13 uses d(theta)/dt = omega)
t = sp.Symbol("t", real=True)
theta = sp.Symbol("theta", real=True)

#: generalised coordinates and speeds as functions of time (for differentiation)
x, y, phi = dynamicsymbols("x y phi", real=True)
xd, yd, phid = dynamicsymbols("x y phi", 1, real=True)

#: plain symbols standing for the state in the final expressions
STATE_NAMES: tuple[str, ...] = ("x", "y", "phi", "xd", "yd", "phid")
qs = sp.symbols("x y phi", real=True)
us = sp.symbols("xd yd phid", real=True)
udots = sp.symbols("xdd ydd phidd", real=True)


def to_plain(expr: sp.Expr) -> sp.Expr:
    """Replace x(t), x'(t), ... by the plain state symbols (derivatives first)."""
    from sympy.physics.mechanics import msubs

    t_dyn = dynamicsymbols._t

    second = {q.diff(t_dyn, 2): a for q, a in zip((x, y, phi), udots, strict=True)}
    return msubs(expr, second, dict(zip((xd, yd, phid), us, strict=True)), dict(zip((x, y, phi), qs, strict=True)))
