"""Symbols of the seal model: generalised coordinates, parameters and inputs.

Every physical parameter is a symbol, so one compiled library serves every value
(declared by the submodels in derive/submodels/ and looked up by name, ``P["kw"]``;
the parameter vector follows the registry: ``PARAMETER_NAMES``).
Names are the paper's symbols written in ASCII.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping

import sympy as sp
from sympy.physics.mechanics import dynamicsymbols

from .names import INPUT_NAMES, STATE_NAMES  # noqa: F401 - re-exported (sympy-free in .names)
from .submodels import registry


class _ParameterSymbols(Mapping[str, sp.Symbol]):
    """The sympy symbol of every parameter the registered submodels declare, by name (``P["kw"]``)."""

    def __getitem__(self, name: str) -> sp.Symbol:
        return registry.parameter(name).symbol

    def __iter__(self) -> Iterator[str]:
        return iter(registry.parameter_names(all_inputs=True))

    def __len__(self) -> int:
        return len(registry.parameter_names(all_inputs=True))


#: parameter symbols by name, declared by the submodels (derive/submodels/)
P: Mapping[str, sp.Symbol] = _ParameterSymbols()


def __getattr__(name: str):
    """``PARAMETERS`` / ``PARAMETER_NAMES``: the registry's parameter vector as it stands (derive/submodels/)."""
    if name == "PARAMETERS":
        return registry.parameters()
    if name == "PARAMETER_NAMES":
        return registry.parameter_names()
    raise AttributeError(name)


#: chamber pressures: time-varying inputs, not parameters (chamber a on +Ys, b on -Ys; Eq. 75)
Pa, Pb = sp.symbols("Pa Pb", real=True)

#: time and crank angle; theta = omega t (Eq. 13 uses d(theta)/dt = omega)
t = sp.Symbol("t", real=True)
theta = sp.Symbol("theta", real=True)

#: generalised coordinates and speeds as functions of time (for differentiation)
x, y, phi = dynamicsymbols("x y phi", real=True)
xd, yd, phid = dynamicsymbols("x y phi", 1, real=True)

#: plain symbols standing for the state in the final expressions
qs = sp.symbols("x y phi", real=True)
us = sp.symbols("xd yd phid", real=True)
udots = sp.symbols("xdd ydd phidd", real=True)


def state_symbol(name: str) -> sp.Symbol:
    """The plain symbol of a continuous state by name (the seal body's x ... phid, or a submodel's own)."""
    if name in STATE_NAMES:
        return (qs + us)[STATE_NAMES.index(name)]
    return sp.Symbol(name, real=True)


def to_plain(expr: sp.Expr) -> sp.Expr:
    """Replace x(t), x'(t), ... by the plain state symbols (derivatives first)."""
    from sympy.physics.mechanics import msubs

    t_dyn = dynamicsymbols._t

    second = {q.diff(t_dyn, 2): a for q, a in zip((x, y, phi), udots, strict=True)}
    return msubs(expr, second, dict(zip((xd, yd, phid), us, strict=True)), dict(zip((x, y, phi), qs, strict=True)))
