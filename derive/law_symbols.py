"""What a submodel's laws may be written in, checked as the model is derived.

A law's expression is lowered to CasADi with a value for each of its symbols (generated/lower.py): the crank angle
theta, the states of the model, the parameters in its vector, the chamber pressures Pa, Pb and the activations of
its guards. A symbol outside them (``sp.Symbol("c_extra")`` in a law, a parameter whose effect is off) failed only
when the model was generated, as a KeyError that named neither the submodel nor its contact; here the derivation
refuses it, naming both.

A law whose force jumps with a velocity (``sign(v)``, ``Heaviside(v)``, a ``Piecewise`` on a velocity) stalls every
adaptive integrator once the contact sticks (derive/submodels/laws.py, :func:`~.submodels.laws.slip_sign`): the
run stopped later with a step-limit message about stiffness. The derivation refuses it too, pointing to the
regularised laws (``laws.coulomb``, ``laws.slip_sign``). A kink (``Abs(v)``, ``Max(v, 0)``: the built-in laws'
one-sided damping) is continuous and allowed.
"""

from __future__ import annotations

from collections.abc import Iterable

import sympy as sp

from .submodels import registry
from .submodels.registry import RegistryError
from .symbols import P, Pa, Pb, state_symbol, theta

#: the functions that jump where their argument changes sign
JUMPS = (sp.sign, sp.Heaviside)


def known_symbols(options, activations: Iterable[sp.Symbol]) -> frozenset:
    """The symbols a law of the model of the options ``options`` may use (its lowering has a value for each)."""
    return frozenset({theta, Pa, Pb, *(state_symbol(n) for n in registry.state_names(options)),
                      *(P[n] for n in registry.parameter_names(opts=options)), *activations})


def velocities(options) -> frozenset:
    """The symbols of the model's velocity states (``State.rate``: the seal's xd, yd, phid)."""
    return frozenset(state_symbol(s.name) for s in registry.states(options) if s.rate)


def check(cls, where: str, exprs: Iterable, known: frozenset, options, moving: frozenset = frozenset()) -> None:
    """Refuse the expressions ``exprs`` of submodel ``cls`` (its ``where``: "contact drag (guard gd)", "rates()")
    when they use a symbol outside ``known``, or, with ``moving`` (velocity symbols), jump with one of them."""
    exprs = [sp.sympify(e) for e in exprs]
    stray = sorted({s for e in exprs for s in e.free_symbols} - known, key=str)
    if stray:
        raise RegistryError(f"the submodel {cls.name} ({registry.origin(cls)}) uses in {where} "
                            + "; ".join(_stray(s, cls, options) for s in stray)
                            + " (a law may use ctx.P[...] for its parameters, ctx.X[...] for the states, ctx.Pa, "
                            "ctx.Pb, the crank angle theta and ctx.activation(guard))")
    jumps = sorted({f"{type(j).__name__}({j.args[0]})" for e in exprs for j in _jumps(e, moving)})
    if jumps:
        raise RegistryError(f"the submodel {cls.name} ({registry.origin(cls)}) has in {where} a law that jumps with "
                            f"a velocity: {', '.join(jumps)}; a force that jumps where a velocity changes sign stalls "
                            "every adaptive integrator once the contact sticks (the run stops at its step limit): "
                            "write friction with laws.coulomb(mu, N, v, ctx.P['v_eps']) and a sign of a velocity as "
                            "laws.slip_sign(v, ctx.P['v_eps']) (tanh(v / v_eps); derive/submodels/laws.py)")


def _jumps(e: sp.Basic, moving: frozenset) -> list:
    if not moving or not (e.free_symbols & moving):
        return []
    out = []
    for node in sp.preorder_traversal(e):
        if isinstance(node, JUMPS) and node.args[0].free_symbols & moving:
            out.append(node)
        elif isinstance(node, sp.Piecewise) and any(pair.cond.free_symbols & moving for pair in node.args):
            out.append(node)
    return out


def _stray(s: sp.Symbol, cls, options) -> str:
    """Why symbol ``s`` has no value in the model, in words."""
    name = s.name
    if name in registry.parameter_names(all_inputs=True):
        p = registry.parameter(name)
        if p.symbol != s:
            return (f"a symbol {name} that is not the parameter {name} (made with other assumptions: take the "
                    f"parameter as ctx.P[{name!r}])")
        if not p.in_vector:
            return f"parameter {name!r}, a scene input that feeds derived parameters only (in_vector=False)"
        return (f"parameter {name!r}, which is not in this model's parameter vector while "
                f"{registry.unmet(registry.needing(p))} (its needs=, or its submodel's switch, must hold wherever a "
                "law reads it)")
    if name in registry.state_names():
        return f"state {name!r} of a submodel that is off in this model"
    if name in registry.activation_symbols():
        return (f"the activation {name!r} of a guard whose contact is not in this model (or not made with "
                "ctx.activation(guard))")
    return (f"symbol {name!r}, which no submodel declares (declare it as a Parameter of {cls.name} and read it as "
            f"ctx.P[{name!r}])")
