"""The model's options as chosen: a validated choice for every option slot of the registry (:class:`Options`), and
the one of a scene's effects and modelling choices (:func:`options_of`).

The slots and the rules on them are declared below the registry (derive/options.py); this module stands above it,
so the registry never imports what it validates against. This module imports no sympy.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping

from .options import NONE, Option, resolve
from .submodels.registry import options as declared_options


class Options(Mapping[str, str]):
    """A validated choice for every slot of the registry (missing slots take their default, or "none" under a
    parent that is "none"; :func:`~.options.resolve`). Read as a mapping (``options["damping"] == "in-contact"``)
    or with :meth:`on`."""

    __slots__ = ("_values",)

    def __init__(self, values: Mapping[str, str | bool] | None = None, *, declared: Mapping[str, Option] | None = None):
        self._values = resolve(values or {}, declared_options() if declared is None else declared)

    def __getitem__(self, name: str) -> str:
        return self._values[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._values)

    def __len__(self) -> int:
        return len(self._values)

    def on(self, name: str) -> bool:
        """True unless the slot's choice is "none" (False for a slot the registry does not know)."""
        return self._values.get(name, NONE) != NONE

    def replace(self, **changes: str | bool) -> Options:
        return Options({**self._values, **changes})

    def as_dict(self) -> dict[str, str]:
        return dict(self._values)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Options) and self._values == other._values

    def __hash__(self) -> int:
        return hash(tuple(sorted(self._values.items())))

    def __repr__(self) -> str:
        return f"Options({self._values})"


def options_of(effects, assumptions) -> Options:
    """The one options object of an :class:`~.effects.Effects` and :class:`~.assumptions.Assumptions` pair."""
    return Options({**effects.choices(), **assumptions.as_dict()})
