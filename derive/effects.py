"""The physical effects a scene can switch on or off: the "effects" slots of the options (derive/options.py).

An effect that is off never enters the derivation: its forces are not built, its
guards do not exist, and nothing of it reaches the generated C or the run
(MuJoCo's disable flags, PyBaMM's options). Effects form a small hierarchy: no
contact means no damping and no friction at that contact. Each submodel declares
its effects (derive/submodels/); :class:`Effects` reads and writes them as
booleans, the way scenes write them in ``[effects]``.
"""

from __future__ import annotations

from ..suggest import did_you_mean, not_known
from .choices import Options
from .options import NONE, Option, OptionError, TableView, without_parent
from .submodels.base import built_in
from .submodels.registry import left_out_options, slots, submodels


def on_choice(opt: Option) -> str:
    """The choice that switches an effect on (its first choice other than "none")."""
    return next(c for c in opt.choices if c != NONE)


def orphans(values: dict[str, bool]) -> list[tuple[str, str]]:
    """(effect, its parent) for every effect of ``values`` that is on while its parent is set off there."""
    slots = declared()
    return [(name, slots[name].parent) for name, on in values.items()
            if on and slots[name].parent is not None and values.get(slots[name].parent) is False]


def off_with_parents(values: dict, switched_off, named) -> dict:
    """``values`` (effect name -> on) with every effect under one of ``switched_off`` (an override's ``false``) off
    too, transitively, but for those ``named`` by the overrides themselves (a child switched on under an effect
    that is off stays, and is refused as an orphan): ``--set effects.spring=false`` on a scene that writes
    ``spring_damping = true``, and ``apexseal generate --effects spring=off``."""
    out, off, named = dict(values), set(switched_off), set(named)
    for name, opt in declared().items():  # parents before children
        if opt.parent in off and name not in named:
            out[name] = False
            off.add(name)
    return out


class EffectError(OptionError):
    """An effect set that names an unknown effect or breaks the hierarchy."""


def refuse_unknown(names, slots: dict[str, Option]) -> None:
    """Raise :class:`EffectError` for the first of ``names`` that is none of the effects ``slots``, naming it and
    the registered ones: a submodel's effect exists only once the submodel is registered, so an effect set built
    before that would otherwise leave it off without a word."""
    for key in names:
        if key not in slots:
            raise EffectError(not_known(f"effects.{key}", key, slots, "an effect")
                              + " (a submodel's effect exists once the submodel is registered or its package "
                              "installed)")


def declared() -> dict[str, Option]:
    """The effect slots of the registered submodels, parents before children."""
    return slots("effects")


def __getattr__(name: str):
    """``EFFECTS``: effect name -> (parent effect or None, one-line meaning), from the registry."""
    if name == "EFFECTS":
        return {n: (o.parent, o.meaning) for n, o in declared().items()}
    raise AttributeError(name)


class Effects(TableView):
    """Which effects are on (booleans by effect name). All on by default (the paper's full model)."""

    __slots__ = ()

    def __init__(self, **on: bool) -> None:
        slots = declared()
        for key in on:
            if key not in slots:
                raise TypeError(f"Effects() got an unexpected effect {key!r}{did_you_mean(key, slots)}")
        values = {name: bool(on.get(name, opt.default != NONE)) for name, opt in slots.items()}
        for name, parent in orphans(values):
            raise EffectError(f"effects.{name} = true needs effects.{parent} = true " + without_parent(name, parent))
        self._set(values)

    @classmethod
    def from_mapping(cls, values: dict[str, bool]) -> Effects:
        """Build from a mapping; children of an effect that is off default to off."""
        slots = declared()
        refuse_unknown(values, slots)
        resolved: dict[str, bool] = {}
        for name, opt in slots.items():  # parents come before children
            default = opt.default != NONE and (opt.parent is None or resolved[opt.parent])
            resolved[name] = bool(values.get(name, default))
        return cls(**resolved)

    @classmethod
    def only(cls, *names: str) -> Effects:
        """Just these effects (and the parents they need); an effect that is not registered is an
        :class:`EffectError` (it was left off silently: ``Effects.only("cushion")`` before the cushion was
        registered built a model without it)."""
        slots = declared()
        refuse_unknown(names, slots)
        on = set(names)
        for name in names:
            parent = slots[name].parent
            while parent is not None:
                on.add(parent)
                parent = slots[parent].parent
        return cls.from_mapping({n: (n in on) for n in slots})

    def on(self) -> tuple[str, ...]:
        return tuple(n for n, v in self._values.items() if v)

    def choices(self) -> dict[str, str]:
        """The effects as option choices ("on"/"none")."""
        slots = declared()
        return {n: (on_choice(slots[n]) if v else NONE) for n, v in self._values.items()}

    @property
    def label(self) -> str:
        """Short label of the model's effects, for messages and the generated header: "all" when every built-in
        effect is on, else those that are on joined by "+" ("none" for none), and after it those of a user's or a
        package's submodel that are on ("all+drag"; one that enters no model, off at its defaults, is not named:
        :func:`~.submodels.registry.left_out_options`)."""
        out = left_out_options(Options(self.choices()))
        own = {o.name for cls in submodels() if built_in(cls) for o in cls.options}
        values = {n: v for n, v in self._values.items() if n not in out and n in own}
        extra = [n for n, v in self._values.items() if v and n not in out and n not in own]
        head = "all" if all(values.values()) else "+".join(n for n, v in values.items() if v)
        return "+".join([head] * bool(head) + extra) or "none"
