"""A contact's law must push the seal out of the contact where its guard says the contact is closed.

The hybrid model closes a contact while its guard is negative (``Guard``; the mode, the events, the activation
``ctx.activation(guard)``). A guard of the wrong sign (a penetration given where minus it is meant) leaves a law
written with ``laws.penalty`` at zero everywhere: closed (activation 1) where the penetration is negative, where
``max(penetration, 0)`` is 0, open where it pushes, and the contact never acts, silently. :func:`check` tests
each contact of a derived model at one point where its guard is negative: the seal's generalised force of the
contact, (F_X, F_Y, M_z) on (x, y, phi) (Eqs. 10-11: C moves along the groove frame's axes, the seal turns about
z, so this is its virtual work), must have a positive component along the guard's gradient there (the force
opens the contact), with the contact's activation 1, the seal at rest in its groove (no velocity: no damping, no
friction), the rotor stopped (omega = 0) and no chamber pressure. A contact whose force there is zero while the
same law with its activation 1 pushes against the gradient where the guard is positive (the penetration's side)
has its guard's sign inverted; one that pulls along it (a negative component) where the guard is negative is
refused too. Both are :class:`ContactPushError`. A contact whose force is zero on both sides at rest (a
velocity's law: a damper) is not judged.

The point: the default scene's parameters (the paper's case study, ``paper_check.values.DEFAULTS``; a user's
parameter at its declared default, else inside its declared range), theta = pi/3, and the state reached from
rest (x = y = phi = 0) by Newton steps along the guard's gradient to a guard of -``DEPTH`` times its value at
rest (a guard negative at rest is taken there; one zero at rest steps ``STEP``). Cheap: a few numeric
evaluations per contact (no simplification). A contact whose guard or force has no finite value there, or whose
guard does not depend on the seal's position, is not judged.
"""

from __future__ import annotations

import math

import sympy as sp

from .submodels.registry import RegistryError, guard, origin, parameters
from .symbols import P, Pa, Pb, qs, theta, us

#: the crank angle of the test point (the example state of the paper check)
THETA = sp.pi / 3
#: the guard's value sought on its closed side, as a fraction of its value at rest (of the other sign)
DEPTH = 0.1
#: a step (m, rad) along the gradient for a guard that is zero at rest
STEP = 1e-7
#: a force component this small relative to the largest one evaluated is zero (rounding)
ZERO = 1e-9


class ContactPushError(RegistryError):
    """A contact's law does not push the seal out where its guard says it is closed (a RegistryError: the command
    line reports it as an error line, as it does a submodel's other mistakes)."""


def _values(options) -> dict:
    """Parameter symbol -> value: the default scene's, a user's parameter at its default or inside its range."""
    try:
        from .paper_check.values import DEFAULTS
    except LookupError:  # a parameter of the default model with no value (paper_check.values.MissingValue)
        DEFAULTS = {}
    out = {}
    for p in parameters(opts=options):
        v = DEFAULTS.get(p.name, p.default)
        if v is None:
            low = next((b for b in (p.gt, p.ge) if b is not None), None)
            high = next((b for b in (p.lt, p.le) if b is not None), None)
            v = (low + high) / 2 if low is not None and high is not None else \
                (low + 1.0 if low is not None else high - 1.0 if high is not None else 1.0)
        out[P[p.name]] = sp.Float(v)
    out[P["omega"]] = sp.S.Zero  # the rotor stopped: no sliding at the tip, no friction
    return out


def _number(expr, subs: dict) -> float:
    """``expr`` at ``subs`` (any other symbol at 0), or nan."""
    expr = sp.sympify(expr).xreplace(subs)
    expr = expr.xreplace({s: sp.S.Zero for s in expr.free_symbols})
    try:
        value = complex(expr.evalf(30))
    except (TypeError, ValueError):
        return math.nan
    return value.real if abs(value.imag) <= 1e-12 * max(abs(value.real), 1e-300) else math.nan


def _gradient(g, subs):
    return [_number(g.diff(q), subs) for q in qs]


def _closed_point(g: sp.Expr, base: dict) -> tuple[dict, dict] | None:
    """(a state where the guard ``g`` is negative, one where it is positive), each as symbol -> value, or None."""
    at = dict(base)
    g0 = _number(g, at)
    grad = _gradient(g, at)
    norm2 = sum(d * d for d in grad)
    if not math.isfinite(g0) or not math.isfinite(norm2) or norm2 == 0:
        return None

    def towards(target: float) -> dict | None:
        point = dict(at)
        for _ in range(8):
            value, slope = _number(g, point), _gradient(g, point)
            n2 = sum(d * d for d in slope)
            if not (math.isfinite(value) and math.isfinite(n2)) or n2 == 0:
                return None
            if value * target > 0 and abs(value) >= 0.5 * abs(target):
                return point
            step = (target - value) / n2
            point = point | {q: sp.Float(float(point[q]) + step * d) for q, d in zip(qs, slope, strict=True)}
        return None

    size = abs(g0) if g0 != 0 else STEP * math.sqrt(norm2)
    closed = at if g0 < 0 else towards(-DEPTH * size)
    opened = towards(DEPTH * size if g0 < 0 else size)
    return None if closed is None or opened is None else (closed, opened)


def _push(g, forces: dict, point: dict) -> float:
    """The contact's generalised force (F_X, F_Y, M_z) along the guard's gradient in (x, y, phi) at ``point``."""
    q = [_number(forces[k], point) for k in ("X", "Y", "M")]
    return sum(a * b for a, b in zip(q, _gradient(g, point), strict=True))


def check(cls, contact: str, guard_name: str, g: sp.Expr, forces: dict, activations: dict, options) -> None:
    """Raise :class:`ContactPushError` unless the contact ``contact`` of submodel ``cls`` (its guard
    ``guard_name``, expression ``g``, closed while negative; ``forces``: its ``F_<c>_X``, ``F_<c>_Y``, ``M_<c>``
    outputs) pushes the seal out where ``g`` is negative (the module's docstring). ``activations``: every guard's
    activation symbol, by guard name (the others' set to 0: open)."""
    own = activations.get(guard_name)
    mine = {"X": forces[f"F_{contact}_X"], "Y": forces[f"F_{contact}_Y"], "M": forces[f"M_{contact}"]}
    base = _values(options) | {s: sp.S.Zero for s in (*qs, *us, Pa, Pb)} | {theta: THETA}
    base |= {a: sp.S.Zero for a in activations.values()}
    points = _closed_point(g, base)
    if points is None:
        return
    closed, opened = points
    with_contact = {own: sp.S.One} if own is not None else {}
    inside = _push(g, mine, closed | with_contact)
    outside = _push(g, mine, opened | with_contact)
    if not (math.isfinite(inside) and math.isfinite(outside)):
        return
    small = ZERO * max(abs(inside), abs(outside))
    if inside > small or (abs(inside) <= small and outside >= -small):
        return
    gd = guard(guard_name)
    where = (f"the submodel {cls.name} ({origin(cls)}): contact {contact!r}, guard {guard_name!r} "
             f"({gd.meaning!r}; the contact is closed while the guard is negative)")
    if abs(inside) <= small:
        raise ContactPushError(
            f"{where} never pushes the seal out: where its guard is negative (closed) its force is zero, and where "
            "the guard is positive (open) its law pushes towards the guard's negative side: the guard's sign is "
            "inverted. Return as the guard minus the penetration (the gap, positive while the bodies are apart), "
            f"e.g. ContactModel({contact!r}, ..., guard=-penetration), and declare Guard(..., sign=...) to match "
            "its output (+1: a gap, -1: a penetration)")
    if inside < 0:
        raise ContactPushError(
            f"{where} pulls the seal into the contact where its guard is negative (closed): its force opposes the "
            "guard's gradient there. A contact pushes the bodies apart: write its force along the direction in "
            "which the guard grows (laws.penalty(k, -guard, activation) times that direction), or give the guard "
            "the other sign if it is the penetration")
