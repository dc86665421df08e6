"""The model's options: one slot per physical effect or modelling choice, each with its allowed choices.

Every submodel declares its slots (:class:`Option`): an *effect* (``housing_friction``,
whose choices are ``"on"`` and ``"none"``; scenes write ``true``/``false`` in
``[effects]``) or a *modelling choice* where the paper is silent
(``housing_stiffness``: ``"groove-axis"`` or ``"normal"``; scenes write it in
``[assumptions]``). "none" is an ordinary choice: an effect that is off is the
choice "none", never derived, generated or run (MuJoCo's disable flags, PyBaMM's
options). A slot may have a parent: no contact means no damping or friction at
that contact. :func:`resolve` validates a set of choices against the declared slots
in one place, with "did you mean" for a misspelt slot or choice (:class:`~.choices.Options`
holds the result for the registry's slots).

This module imports no sympy.
"""

from __future__ import annotations

from collections.abc import Mapping
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


def resolve(values: Mapping[str, str | bool], declared: Mapping[str, Option]) -> dict[str, str]:
    """The choice of every slot of ``declared`` (parents before children), validated: a slot ``values`` does not
    name takes its default, or "none" under a parent that is "none"; a slot or choice not declared, or a child on
    under a parent that is off, is an :class:`OptionError` (with "did you mean")."""
    values = dict(values)
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
    return resolved


def needed_effects(need) -> tuple[str, ...]:
    """The entries a ``needs`` names (one, several any of which reads the parameter, or none): effects, or
    modelling choices written ``"slot=choice"`` (:func:`need_met`)."""
    return () if need is None else (need,) if isinstance(need, str) else tuple(need)


def need_met(entry: str, choices: Mapping[str, str], unknown: bool) -> bool:
    """Whether one entry of a ``needs`` holds under ``choices`` (slot -> choice, e.g. an
    :class:`~.choices.Options`): an effect (``"housing_damping"``) while it is not "none", a modelling choice
    (``"damping_law=penetration"``) while its slot has that choice; ``unknown`` for a slot ``choices`` lacks."""
    slot, _, wanted = entry.partition("=")
    now = choices.get(slot)
    if now is None:
        return unknown
    return now == wanted if wanted else now != NONE


def needed_on(need, on) -> bool:
    """Whether a parameter whose ``needing`` is ``need`` is read, ``on(entry)`` telling which of its entries
    hold (:func:`need_met`): always without a need, else while any entry it names holds."""
    return need is None or any(on(n) for n in needed_effects(need))


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
