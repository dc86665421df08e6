"""The model's options: one slot per physical effect or modelling choice, each with its allowed choices.

Every submodel declares its slots (:class:`Option`): an *effect* (``housing_friction``,
whose choices are ``"on"`` and ``"none"``; scenes write ``true``/``false`` in
``[effects]``) or a *modelling choice* where the paper is silent
(``housing_stiffness``: ``"groove-axis"`` or ``"normal"``; scenes write it in
``[assumptions]``). "none" is an ordinary choice: an effect that is off is the
choice "none", never derived, generated or run (MuJoCo's disable flags, PyBaMM's
options). A slot may have a parent: no contact means no damping or friction at
that contact. :class:`Options` validates a set of choices against the registry in
one place, with "did you mean" for a misspelt slot or choice.

This module imports no sympy.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass

from ..suggest import not_known

#: the choice that switches an effect off
NONE = "none"
ON = "on"


@dataclass(frozen=True)
class Option:
    """One slot: its name, choices (default first), meaning, parent slot, and the scene table it is written in."""

    name: str
    choices: tuple[str, ...]
    meaning: str
    parent: str | None = None
    #: "effects" (written true/false: ``choices`` are ("on", "none")) or "assumptions" (written as the choice)
    table: str = "effects"
    #: the scene key that decides the choice, where the scene does not state it itself (``pressure_model``:
    #: ``pressure.source``), for messages that say how to make it
    set_by: str | None = None

    @property
    def default(self) -> str:
        return self.choices[0]


class TableView:
    """An immutable view of one scene table's slots (``[effects]`` or ``[assumptions]``), read as attributes.

    Subclasses validate in ``__init__(**values)`` and store the resolved values with :meth:`_set`.
    """

    __slots__ = ("_values",)

    def _set(self, values: dict) -> None:
        object.__setattr__(self, "_values", values)

    def __getattr__(self, name: str):
        try:
            return object.__getattribute__(self, "_values")[name]
        except KeyError:
            raise AttributeError(name) from None

    def __setattr__(self, name, value) -> None:
        raise AttributeError(f"{type(self).__name__} are immutable")

    def __reduce__(self):
        return _rebuild_view, (type(self), self._values)

    def as_dict(self) -> dict:
        return dict(self._values)

    def __eq__(self, other: object) -> bool:
        return type(other) is type(self) and self._values == other._values

    def __hash__(self) -> int:
        return hash(tuple(sorted(self._values.items())))

    def __repr__(self) -> str:
        return f"{type(self).__name__}({', '.join(f'{k}={v!r}' for k, v in self._values.items())})"


def _rebuild_view(cls: type, values: dict) -> TableView:
    return cls(**values)


class OptionError(ValueError):
    """A set of options that names an unknown slot or choice, or breaks a parent rule."""


class Options(Mapping[str, str]):
    """A validated choice for every slot of the registry (missing slots take their default, or "none" under a
    parent that is "none"). Read as a mapping (``options["damping"] == "in-contact"``) or with :meth:`on`."""

    __slots__ = ("_values",)

    def __init__(self, values: Mapping[str, str | bool] | None = None, *, declared: Mapping[str, Option] | None = None):
        if declared is None:
            from .submodels.registry import options as declared_options

            declared = declared_options()
        values = dict(values or {})
        for key in values:
            if key not in declared:
                raise OptionError(not_known(key, key, declared, "an option"))
        resolved: dict[str, str] = {}
        for name, opt in declared.items():  # parents are declared before their children
            parent_off = opt.parent is not None and resolved.get(opt.parent, opt.default) == NONE
            raw = values.get(name, NONE if parent_off else opt.default)
            choice = _choice(opt, raw)
            if parent_off and choice != NONE:
                p = opt.parent
                raise OptionError(f"{opt.table}.{name} = {_shown(opt, choice)} needs {declared[p].table}.{p} on "
                                  + without_parent(name, p))
            resolved[name] = choice
        self._values = resolved

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


def _choice(opt: Option, raw: str | bool) -> str:
    if isinstance(raw, bool):
        if opt.table != "effects":
            raise OptionError(f"{opt.table}.{opt.name} = {raw!r} is not allowed; allowed: {', '.join(opt.choices)}")
        return next(c for c in opt.choices if c != NONE) if raw else NONE
    if raw not in opt.choices:
        raise OptionError(not_known(f"{opt.table}.{opt.name} = {raw!r}", raw, opt.choices, "allowed", listing="allowed"))
    return raw


def without_parent(name: str, parent: str) -> str:
    """Why a child slot cannot be on while its parent is off, in words: "(there is no friction without the groove
    contact)"; the one wording of the options, the effects and the scene's checks."""
    return f"(there is no {name.split('_')[-1]} without the {parent.replace('_', ' ')})"


def _shown(opt: Option, choice: str) -> str:
    return ("true" if choice != NONE else "false") if opt.choices == (ON, NONE) else repr(choice)
