"""Modelling choices where the paper is silent or physically doubtful: the "assumptions" slots of the options.

Each is recorded, with its reason, in the paper-check report (docs/paper-check.md);
each is a scene switch (``[assumptions]``) because users may want the other reading.
Like effects, they are structural: they change what is derived and generated. Each
submodel declares its choices (derive/submodels/); :class:`Assumptions` reads them.
"""

from __future__ import annotations

from .options import Option, OptionError, did_you_mean


class AssumptionError(OptionError):
    pass


def declared() -> dict[str, Option]:
    """The modelling-choice slots of the registered submodels."""
    from .submodels.registry import options

    return {n: o for n, o in options().items() if o.table == "assumptions"}


def __getattr__(name: str):
    """``CHOICES``: name -> (allowed values, default first; what it decides), from the registry."""
    if name == "CHOICES":
        return {n: (o.choices, o.meaning) for n, o in declared().items()}
    raise AttributeError(name)


class Assumptions:
    """The modelling choices (strings by name); each defaults to its first allowed value."""

    __slots__ = ("_values",)

    def __init__(self, **values: str) -> None:
        slots = declared()
        for key in values:
            if key not in slots:
                raise TypeError(f"Assumptions() got an unexpected choice {key!r}{did_you_mean(key, slots)}")
        resolved = {name: values.get(name, opt.default) for name, opt in slots.items()}
        for name, value in resolved.items():
            allowed = slots[name].choices
            if value not in allowed:
                raise AssumptionError(
                    f"assumptions.{name} = {value!r} is not allowed{did_you_mean(value, allowed)} "
                    f"Allowed: {', '.join(allowed)}"
                )
        object.__setattr__(self, "_values", resolved)

    def __getattr__(self, name: str) -> str:
        try:
            return object.__getattribute__(self, "_values")[name]
        except KeyError:
            raise AttributeError(name) from None

    def __setattr__(self, name, value) -> None:
        raise AttributeError("Assumptions are immutable")

    def __reduce__(self):
        return _rebuild, (self._values,)

    @classmethod
    def from_mapping(cls, values: dict[str, str]) -> Assumptions:
        slots = declared()
        for key in values:
            if key not in slots:
                raise AssumptionError(f"assumptions.{key} is not a modelling choice{did_you_mean(key, slots)} "
                                      f"Known: {', '.join(slots)}")
        return cls(**values)

    def as_dict(self) -> dict[str, str]:
        return dict(self._values)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Assumptions) and self._values == other._values

    def __hash__(self) -> int:
        return hash(tuple(sorted(self._values.items())))

    def __repr__(self) -> str:
        return f"Assumptions({', '.join(f'{k}={v!r}' for k, v in self._values.items())})"


def _rebuild(values: dict[str, str]) -> Assumptions:
    return Assumptions(**values)
