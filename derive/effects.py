"""The physical effects a scene can switch on or off.

An effect that is off never enters the derivation: its forces are not built, its
guards do not exist, and nothing of it reaches the generated C or the run
(MuJoCo's disable flags, PyBaMM's options). Effects form a small hierarchy: no
contact means no damping and no friction at that contact.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

#: effect name -> (parent effect or None, one-line meaning)
EFFECTS: dict[str, tuple[str | None, str]] = {
    "inertia": (None, "rotor-motion inertial loads on the seal: centrifugal, Coriolis, chord translation (Eq. 15)"),
    "housing_contact": (None, "elastic seal tip-housing contact, Eqs. 33-34"),
    "housing_damping": ("housing_contact", "damping of the tip-housing contact, Eq. 67"),
    "housing_friction": ("housing_contact", "Coulomb friction at the tip, Algorithm 2"),
    "spring": (None, "the groove-bottom spring and its preload, Eqs. 37-39"),
    "spring_damping": ("spring", "damping at the seal-spring contact, Eq. 73"),
    "spring_friction": ("spring", "Coulomb friction at the seal-spring contact, Eq. 73"),
    "groove_contact": (None, "elastic seal-groove contacts at g1..g4, Algorithm 1"),
    "groove_damping": ("groove_contact", "damping of the seal-groove contacts, Eqs. 55, 62"),
    "groove_friction": ("groove_contact", "Coulomb friction at the seal-groove contacts, Algorithm 1"),
    "chamber_pressure": (None, "gas pressure of the two chambers on the seal, Eqs. 75-79"),
}


class EffectError(ValueError):
    """An effect set that names an unknown effect or breaks the hierarchy."""


@dataclass(frozen=True)
class Effects:
    """Which effects are on. All on by default (the paper's full model)."""

    inertia: bool = True
    housing_contact: bool = True
    housing_damping: bool = True
    housing_friction: bool = True
    spring: bool = True
    spring_damping: bool = True
    spring_friction: bool = True
    groove_contact: bool = True
    groove_damping: bool = True
    groove_friction: bool = True
    chamber_pressure: bool = True

    def __post_init__(self) -> None:
        for name, (parent, _) in EFFECTS.items():
            if getattr(self, name) and parent is not None and not getattr(self, parent):
                raise EffectError(
                    f"effects.{name} = true needs effects.{parent} = true "
                    f"(there is no {name.split('_')[-1]} without the {parent.replace('_', ' ')})"
                )

    @classmethod
    def from_mapping(cls, values: dict[str, bool]) -> Effects:
        """Build from a mapping; children of an effect that is off default to off."""
        import difflib

        for key in values:
            if key not in EFFECTS:
                near = difflib.get_close_matches(key, EFFECTS, n=1)
                hint = f"; did you mean '{near[0]}'?" if near else ""
                raise EffectError(f"effects.{key} is not an effect{hint} Known: {', '.join(EFFECTS)}")
        resolved: dict[str, bool] = {}
        for name, (parent, _) in EFFECTS.items():  # parents come before children
            default = resolved[parent] if parent is not None else True
            resolved[name] = bool(values.get(name, default))
        return cls(**resolved)

    @classmethod
    def only(cls, *names: str) -> Effects:
        """Just these effects (and the parents they need)."""
        on = set(names)
        for name in names:
            parent = EFFECTS[name][0] if name in EFFECTS else None
            while parent is not None:
                on.add(parent)
                parent = EFFECTS[parent][0]
        return cls.from_mapping({n: (n in on) for n in EFFECTS})

    def on(self) -> tuple[str, ...]:
        return tuple(f.name for f in fields(self) if getattr(self, f.name))

    def as_dict(self) -> dict[str, bool]:
        return {f.name: getattr(self, f.name) for f in fields(self)}

    @property
    def label(self) -> str:
        """Short stable label, used in cache keys and file names."""
        return "all" if all(self.as_dict().values()) else "+".join(self.on()) or "none"
