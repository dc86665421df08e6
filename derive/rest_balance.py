"""The rest balance of Eq. 9 (ks delta_s = kw delta_w as printed), checked on every derived model.

A scene places the housing wall delta_w into the seal's tip at rest (``SealBody.rest_wall_deflection``) so that the
housing's force balances the spring's force at rest (``SpringContact.rest_force``, Eq. 39) along the groove axis.
That balance is written for the model's laws: a law changed on one side only (the housing's, or a spring law not
written through ``SpringContact.push``), or a submodel of the user's whose force acts at rest (a contact closed
there), would start every run out of balance, silently. :func:`check` evaluates the X forcing of the derived model
at rest - the state at zero, theta = 0, no chamber pressure, no inertia (omega -> 0), the tip sliding forward along
the housing (the friction laws in their sliding limit sign(v), as Eq. 9 and Algorithm 2 take it) - with delta_w
from the rest balance, at a few exact points: it must be zero. At each point every contact is closed that is
closed there by the rule of the runs (its guard negative: ``Guard``, ``runtime/solving/preflight.py``) or by
declaration (``Guard.closed_at_rest``, the preloaded spring), every other one open: the housing (pressed in by
delta_w) and the spring (compressed by delta_s) are closed, the groove's gaps open, and a user's contact closed at
rest is in the balance with its force. The sliding limit is taken whatever form ``laws.slip_sign`` has
(tanh(v / v_eps), v / sqrt(v^2 + v_eps^2), ...): omega is set to :data:`OMEGA_REST` and v_eps to :data:`V_EPS_REST`,
exact and so small that the slide speed at rest (proportional to omega) is 10^40 regularisation widths, and what
omega contributes (inertia, damping) is 10^-20 of the forces at most. Cheap: one substitution of the rest state,
then, at each of three points, numeric evaluations of the guards and the forcing (never a simplification).
"""

from __future__ import annotations

import sympy as sp

from .submodels.housing import HousingContact
from .submodels.registry import RegistryError, guard, parameter_names
from .submodels.seal import SealBody, rest_force
from .submodels.spring import SpringContact
from .symbols import P, Pa, Pb, qs, theta, us

#: the residual allowed, relative to the spring's force at rest (the points are exact; delta_w may be a float)
REL_TOL = 1e-9
#: omega and v_eps at the test points: the slide before the stop, v / v_eps ~ 10^40 (see the module's docstring)
OMEGA_REST = sp.Rational(1, 10**20)
V_EPS_REST = sp.Rational(1, 10**60)


class RestBalanceError(RegistryError):
    """The model's laws do not balance at rest with the wall deflection delta_w of Eq. 9 (a RegistryError: the
    command line reports it as an error line, as it does a submodel's other mistakes)."""


def _point(shift: int, names) -> dict[str, sp.Rational]:
    """Distinct positive exact values 1.1 ... 3.3 for every parameter (a different assignment per ``shift``)."""
    return {n: sp.Rational(11 + (i + shift) % 23, 10) for i, n in enumerate(names)}


def check(forcing_x: sp.Expr, guards: dict[str, sp.Expr], activations: dict[str, sp.Symbol], options,
          parts: dict[str, sp.Expr] | None = None) -> None:
    """Raise :class:`RestBalanceError` unless the X forcing ``forcing_x`` vanishes at rest (see the module's
    docstring) with delta_w = ``SealBody.rest_wall_deflection`` (Eq. 9). ``guards``: guard name -> expression of
    the model's contacts (closed while negative); ``activations``: guard name -> activation symbol; ``parts``:
    submodel name -> the X force of its contacts, to name in the error those whose force is in the balance.
    Nothing to check unless the spring and the housing contact are both on."""
    if not (options.on("spring") and options.on("housing_contact")):
        return
    rest = {s: sp.S.Zero for s in (*qs, *us, theta, Pa, Pb)}
    at_rest = forcing_x.xreplace(rest)
    guards_at_rest = {n: g.xreplace(rest) for n, g in guards.items()}
    names = parameter_names(all_inputs=True)
    for shift in (0, 7, 19):
        values = _point(shift, names)
        values["delta_w"] = SealBody.rest_wall_deflection(values, options)
        # the slide before omega = 0 (which would stop the tip, and slip_sign(0) = 0 its friction)
        subs = {P[n]: v for n, v in values.items()} | {P["omega"]: OMEGA_REST, P["v_eps"]: V_EPS_REST}
        closed = closed_at_rest(guards_at_rest, activations, subs, shift)
        shut = {a: sp.S.One if name in closed else sp.S.Zero for name, a in activations.items()}
        residual = _evaluate(at_rest.xreplace(shut), subs, shift)
        force = float(rest_force(values, options))
        if not abs(residual) <= REL_TOL * max(abs(force), 1e-300):
            acting = {n: _evaluate(f.xreplace(rest | shut), subs, shift).real for n, f in (parts or {}).items()}
            raise RestBalanceError(_message(residual, force, options, acting, REL_TOL * abs(force), closed))


def closed_at_rest(guards_at_rest: dict[str, sp.Expr], activations: dict[str, sp.Symbol], subs: dict,
                   shift: int) -> list[str]:
    """The guards (of ``activations``) closed at a rest test point: declared closed at rest
    (``Guard.closed_at_rest``), or whose expression at rest (``guards_at_rest``) is negative there, as a run's
    start closes it (a guard at zero or without a real value there is open)."""
    def negative(name: str) -> bool:
        if name not in guards_at_rest:
            return False
        value = _evaluate(guards_at_rest[name], subs, shift)
        return abs(value.imag) <= 1e-12 * max(abs(value.real), 1e-300) and value.real < 0

    return [name for name in activations if guard(name).closed_at_rest or negative(name)]


def _evaluate(expr: sp.Expr, subs: dict, shift: int) -> complex:
    """``expr`` (at the rest state) at the parameter values ``subs``, any other symbol at :func:`_point`'s values."""
    expr = expr.xreplace(subs)
    return complex(expr.xreplace(_point(shift, sorted(expr.free_symbols, key=str))).evalf(30))


def _message(residual: complex, force: float, options, acting: dict[str, float], small: float,
             closed: list[str]) -> str:
    where = {cls.name: f"{cls.__module__}.{cls.__qualname__}" for cls in (HousingContact, SpringContact, SealBody)}
    stiffness = options["housing_stiffness"]
    forces = ", ".join(f"{n} {f:.6g} N" for n, f in acting.items() if abs(f) > small)
    return (
        f"Eq. 9: the seal is not in balance at rest: its X force is {residual.real:.6g} N against the force at rest "
        f"of {force:.6g} N that delta_w balances (at a test point, every parameter at an exact stand-in value "
        "between 1.1 and 3.3, not the scene's: the state at zero, theta = 0, the contacts of guards "
        f"{', '.join(closed) or 'none'} closed there (a negative guard, or closed at rest by declaration), every "
        "other contact open, no pressure, no inertia, the tip sliding forward"
        + (f"; the submodels' X forces there: {forces}" if forces else "") + "). The wall deflection "
        f"delta_w of Eq. 9 ({where['seal']}.rest_wall_deflection, housing_stiffness = {stiffness!r}) balances the "
        f"spring's law {where['spring']}.push with the housing's law kw delta_w of {where['housing']}.contacts: "
        "a submodel's law changed without the other side. Write the spring's law in SpringContact.push only "
        "(derive/submodels/spring.py; contacts() and the rest balance both call it), and when the housing's law "
        "changes, change SealBody.rest_wall_deflection (derive/submodels/seal.py, numbers.initial_wall_deflection) "
        "to the deflection at which that law balances SpringContact.rest_force; a submodel of your own whose "
        "force acts at rest (a load that always acts, a contact of it closed at rest) returns that force from its "
        "rest_force(p) (Submodel.rest_force, which delta_w balances with the spring's), or opens its contact at "
        "rest, or is switched off in the scene"
    )
