"""Contact laws shared by every contact, written once (sympy's actuators are the model).

Each contact combines them: an elastic penalty force that never pulls, damping that acts on approach only
(Eqs. 55, 62, 67, 73) and, by ``options["damping"]``, only while the contact is closed, and by
``options["damping_law"]`` in proportion to the penetration (:func:`damper_depth`; not in the paper), and Coulomb
friction regularised as tanh(v / v_eps) (Algorithm 1, Eq. 73) with the power it dissipates.
"""

from __future__ import annotations

import sympy as sp


def approach(v: sp.Expr) -> sp.Expr:
    """max(v, 0): the one-sided ('on approach only') velocity rule of Eqs. 55, 62, 67, 73."""
    return Max_(v, 0)


def penalty(stiffness: sp.Expr, penetration: sp.Expr, activation: sp.Expr) -> sp.Expr:
    """activation * k * max(penetration, 0): elastic, and a contact never pulls (Eq. 34, Algorithm 1; the spring's
    law, Eq. 39, is its own: SpringContact.push)."""
    return activation * stiffness * Max_(penetration, 0)


def damped(normal: sp.Expr, damping: sp.Expr, closing: sp.Expr, activation: sp.Expr, rule: str,
           depth: sp.Expr = sp.S.One) -> sp.Expr:
    """The normal force plus c * max(closing speed, 0) * depth, gated by the contact being closed unless
    rule = 'always' (the contact dampers of Eqs. 55, 62, 67 and 73, where depth = 1; the gate is the `damping`
    assumption, docs/paper-check.md; ``depth``: :func:`damper_depth`)."""
    damp = damping * depth * approach(closing)
    return normal + (activation * damp if rule == "in-contact" else damp)


def damper_depth(ctx, guard, penetration: sp.Expr) -> sp.Expr:
    """The factor by which a contact's damper multiplies c max(v, 0), by the modelling choice ``damping_law``.

    "velocity" (the default): 1, the paper's dampers (Eqs. 55, 62, 67, 73), whose force jumps from 0 to c v when the
    contact closes. "penetration": max(delta, 0) / delta_ref, delta the contact's ``penetration`` and delta_ref the
    scene's contacts.delta_ref, so that the damping force c max(v, 0) delta / delta_ref starts from 0 at the touch
    like the elastic force, and equals the paper's at delta = delta_ref. Not in the paper: the model family of
    K. H. Hunt and F. R. E. Crossley, "Coefficient of restitution interpreted as damping in vibroimpact", J. Appl.
    Mech. 42(2) (1975), F = k delta^n + lambda delta^n v, here with n = 1 (the linear penalty) and lambda =
    c / delta_ref, on approach only like the paper's. A contact closed at rest (the preloaded spring) keeps the
    factor 1 (:func:`.damping_rule.penetration_damped`, the rule the runtime's damping checks share)."""
    from .damping_rule import penetration_damped

    if not penetration_damped(guard, ctx.options["damping_law"]):
        return sp.S.One
    return Max_(penetration, 0) / ctx.P["delta_ref"]


def slip_sign(v: sp.Expr, v_eps: sp.Expr) -> sp.Expr:
    """Regularised sign(v) = tanh(v / v_eps) of the Coulomb friction laws (Algorithm 1, Eq. 73).

    A bare sign() makes every adaptive integrator stall once a contact sticks; the width v_eps is a scene
    parameter (friction.v_eps) and its effect is tested.
    """
    return sp.tanh(v / v_eps)


def coulomb(mu: sp.Expr, normal: sp.Expr, v_slide: sp.Expr, v_eps: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """(friction force along the sliding direction, dissipated power): -mu N sigma(v), mu N sigma(v) v: the Coulomb
    laws of Algorithm 1 (the groove), Algorithm 2 (the housing) and Eq. 73 (the spring), sign(v) of Eq. 54
    regularised (:func:`slip_sign`)."""
    sigma = slip_sign(v_slide, v_eps)
    return -mu * sigma * normal, mu * normal * sigma * v_slide


class _Unevaluated:
    """What :class:`Max_` and :class:`Min_` share: sympy's ``_op`` (Max or Min), never evaluated symbolically; its
    numbers through ``_choose`` (max or min); printed as ``_op``."""

    _op: type
    _choose: object

    def __new__(cls, *args, **kwargs):
        kwargs["evaluate"] = False
        return super().__new__(cls, *args, **kwargs)

    def _eval_evalf(self, prec):  # numbers: as sympy's op (evalf looks functions up by their exact type)
        from mpmath.libmp import prec_to_dps

        return _pick(self._op, self._choose, [a.evalf(prec_to_dps(prec)) for a in self.args])

    def evalf(self, n=15, **options):  # sympy's Max.evalf rebuilds with self.func, which would stay unevaluated
        return _pick(self._op, self._choose, [a.evalf(n, **options) for a in self.args])

    n = evalf

    def _printed(self, printer, *args, **kwargs):  # every printer prints it as the Max (Min) it is
        return printer._print(self._op(*self.args, evaluate=False), *args, **kwargs)

    # str (the paper check's report), LaTeX, C, and the Python printers of lambdify (math, numpy, mpmath) and of the
    # benchmark's numba peer: each looks a function's name up by its class, where Max_ is no name it knows
    _sympystr = _latex = _ccode = _pythoncode = _numpycode = _mpmathcode = _printed


class Max_(_Unevaluated, sp.Max):
    """``Max`` that is never evaluated, also when an expression holding it is rebuilt (substitutions rebuild every
    node). sympy's ``Max(a, b, ...)`` compares its arguments pairwise to drop the redundant ones (``factor_terms``
    of their differences); for the leakage model's kinematic gaps and flows (submodels/gas.py) that was most
    of a cold derivation (measured: 72 s, 25 s with these; the model's functions are the same, bit for bit, at
    40 random states), and so it was for the laws above, whose max(penetration, 0) and max(v, 0) every contact
    rebuilt when its expressions were brought to plain symbols (2026-11-29: the default model's cold `apexseal derive
    --refresh` 5.0-6.0 s, 3.0-4.1 s with these; the default and chamber gas models' expressions the same node for
    node but for the class, their generated C byte for byte). The lowering maps it to ``fmax`` like any ``Max``
    (generated/lower.py); every printer prints it as ``Max``."""

    _op, _choose = sp.Max, max


class Min_(_Unevaluated, sp.Min):
    """``Min`` that is never evaluated (see :class:`Max_`)."""

    _op, _choose = sp.Min, min


def _pick(op, choose, values):
    """The largest (smallest) of evaluated arguments when they are all numbers (compared as floats: a cancellation
    evaluates to a zero without precision, which sympy refuses to compare), else ``op`` of them."""
    if all(v.is_Number for v in values):
        return choose(values, key=float)
    return op(*values)
