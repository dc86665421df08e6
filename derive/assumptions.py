"""Modelling choices where the paper is silent or physically doubtful: the "assumptions" slots of the options.

Each is recorded, with its reason, in the paper-check report (docs/paper-check.md);
each is a scene switch (``[assumptions]``) because users may want the other reading.
Like effects, they are structural: they change what is derived and generated. Each
submodel declares its choices (derive/submodels/); :class:`Assumptions` reads them.
"""

from __future__ import annotations

from ..suggest import did_you_mean, not_known
from .options import Option, OptionError, TableView
from .submodels.registry import slots


class AssumptionError(OptionError):
    pass


def declared() -> dict[str, Option]:
    """The modelling-choice slots of the registered submodels."""
    return slots("assumptions")


def __getattr__(name: str):
    """``CHOICES``: name -> (allowed values, default first; what it decides), from the registry."""
    if name == "CHOICES":
        return {n: (o.choices, o.meaning) for n, o in declared().items()}
    raise AttributeError(name)


class Assumptions(TableView):
    """The modelling choices (strings by name); each defaults to its first allowed value."""

    __slots__ = ()

    def __init__(self, **values: str) -> None:
        slots = declared()
        for key in values:
            if key not in slots:
                raise TypeError(f"Assumptions() got an unexpected choice {key!r}{did_you_mean(key, slots)}")
        resolved = {name: values.get(name, opt.default) for name, opt in slots.items()}
        for name, value in resolved.items():
            allowed = slots[name].choices
            if value not in allowed:
                raise AssumptionError(not_known(f"assumptions.{name} = {value!r}", value, allowed, "allowed",
                                                listing="allowed"))
        self._set(resolved)

    @classmethod
    def from_mapping(cls, values: dict[str, str]) -> Assumptions:
        slots = declared()
        for key in values:
            if key not in slots:
                raise AssumptionError(not_known(f"assumptions.{key}", key, slots, "a modelling choice"))
        return cls(**values)
