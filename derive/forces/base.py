"""What every force model returns: loads on material points of the seal.

A :class:`Load` is a force applied at a material point of the seal (given by its
vector from C). Contact laws are written with an activation symbol per contact
(1 while the contact is closed, 0 while open), so that each contact case of the
paper is the same expression with the activations set to 0 or 1 (Algorithm 3).
Elastic forces are also clipped at zero penetration (max(-gap, 0)): a contact
never pulls, even if an event is located a hair before the gap closes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp
from sympy.physics.vector import Vector

from ..symbols import P

#: activation symbols, one per contact guard (1 = closed)
ACTIVATION_NAMES: tuple[str, ...] = ("s_b1", "s_b2", "s_b3", "s_b4", "s_h", "s_sp")
ACT: dict[str, sp.Symbol] = {n: sp.Symbol(n, nonnegative=True) for n in ACTIVATION_NAMES}


def approach(v: sp.Expr) -> sp.Expr:
    """max(v, 0): the one-sided ('on approach only') velocity rule of Eqs. 55, 62, 67, 73."""
    return sp.Max(v, 0)


def slip_sign(v: sp.Expr) -> sp.Expr:
    """Regularised sign(v) = tanh(v / v_eps) of the Coulomb friction laws (Algorithm 1, Eq. 73).

    A bare sign() makes every adaptive integrator stall once a contact sticks; the
    width v_eps is a scene parameter (friction.v_eps) and its effect is tested.
    """
    return sp.tanh(v / P["v_eps"])


@dataclass
class Load:
    """A force ``force`` at the seal's material point ``r_CP`` (from C)."""

    name: str
    r_CP: Vector
    force: Vector
    #: rate at which friction at this contact dissipates energy (>= 0), or 0
    friction_power: sp.Expr = sp.S.Zero


@dataclass
class ContactModel:
    """The loads of one contact and the guard that opens and closes it."""

    name: str
    loads: list[Load] = field(default_factory=list)
    #: guard: the contact is closed while guard < 0 (None: always acting, e.g. pressure)
    guard: sp.Expr | None = None
    activation: sp.Symbol | None = None
    #: velocity switches inside the contact law (for the guard outputs): name -> expression
    velocity_guards: dict[str, sp.Expr] = field(default_factory=dict)
