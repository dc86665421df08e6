"""Modelling choices where the paper is silent or physically doubtful.

Each is recorded, with its reason, in the paper-check report (docs/paper-check.md);
each is a scene switch (``[assumptions]``) because users may want the other reading.
Like effects, they are structural: they change what is derived and generated.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass, fields

#: name -> (allowed values, default first; what it decides)
CHOICES: dict[str, tuple[tuple[str, ...], str]] = {
    "pend_rule": (
        ("mean", "half-difference"),
        "groove-bottom pressure Pend under the seal (Eq. 75): the mean (Pa + Pb)/2, or the text's "
        "literal 'half the difference' (Pa - Pb)/2",
    ),
    "gap_pressure": (
        ("open-side", "chamber"),
        "side-gap pressures Ps2, Ps4 (Eq. 75, no rule printed): 'open-side' = the chamber's pressure while "
        "the mouth contact on that side is open (b1 > 0, b3 > 0), else Pend; 'chamber' = always the chamber's",
    ),
    "damping": (
        ("in-contact", "always"),
        "contact damping (Eqs. 55, 62, 67, 73) acts on approach only; 'in-contact' also requires the contact "
        "to be closed, 'always' applies the printed velocity rule alone",
    ),
    "housing_stiffness": (
        ("groove-axis", "normal"),
        "kw xs5 is the groove-axis (X) component of the housing force, as Algorithm 2 prints ('groove-axis'), "
        "or the normal force, kw times the normal penetration xs5 cos(lambda) ('normal')",
    ),
}


class AssumptionError(ValueError):
    pass


@dataclass(frozen=True)
class Assumptions:
    pend_rule: str = "mean"
    gap_pressure: str = "open-side"
    damping: str = "in-contact"
    housing_stiffness: str = "groove-axis"

    def __post_init__(self) -> None:
        for f in fields(self):
            allowed = CHOICES[f.name][0]
            value = getattr(self, f.name)
            if value not in allowed:
                near = difflib.get_close_matches(str(value), allowed, n=1)
                hint = f"; did you mean '{near[0]}'?" if near else ""
                raise AssumptionError(
                    f"assumptions.{f.name} = {value!r} is not allowed{hint} Allowed: {', '.join(allowed)}"
                )

    @classmethod
    def from_mapping(cls, values: dict[str, str]) -> Assumptions:
        for key in values:
            if key not in CHOICES:
                near = difflib.get_close_matches(key, CHOICES, n=1)
                hint = f"; did you mean '{near[0]}'?" if near else ""
                raise AssumptionError(f"assumptions.{key} is not a modelling choice{hint} Known: {', '.join(CHOICES)}")
        return cls(**values)

    def as_dict(self) -> dict[str, str]:
        return {f.name: getattr(self, f.name) for f in fields(self)}
