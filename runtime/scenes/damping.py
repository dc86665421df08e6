"""Contact damping as a ratio of critical damping, and the ratios at which it makes a contact chatter.

Each contact's damping acts on approach only and only while the contact is closed (``derive/submodels/laws.py``:
c max(v, 0) of Eqs. 55, 62, 67, 73, v the closing speed of the seal's material point at the contact). The elastic
force starts from 0 at the touch, the damping force jumps from 0 to c v. Above critical damping
(zeta = c / (2 sqrt(k ms)) > 1) that jump outweighs the elastic force, and where the material point still
approaches while the penetration no longer grows (the tip's contact point s5 slides along the tip arc as the seal
rocks, Eqs. 29-31) it pushes the seal off the wall at zero penetration: the contact opens, the loads press it shut
again, and it closes with the same jump. It chatters, the more readily the larger c (docs/hard-cases.md, "Chattering").
A scene warns about such a ratio (``check_damping``, ``runtime/scenes/checks.py``), and a run that chatters on a
contact damped that strongly advises less damping (``chatter_advice``, ``runtime/solving/checks.py``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from ...derive.numbers import damping_of_ratio, ratio_of_damping
from ...derive.submodels.registry import parameter, submodels

#: the largest plausible damping ratio of a contact: critical damping (above it approach-only damping can chatter)
MAX_DAMPING_RATIO = 1.0

#: why a damping ratio above :data:`MAX_DAMPING_RATIO` is a problem (in the scene's warning and the run's advice)
WHY = ("the contact's damping acts on approach only and jumps from 0 to c v when the contact closes; above critical "
       "damping that jump outweighs its elastic force and can push the seal off at each touch, so that the contact "
       "chatters (more damping makes it worse)")


@dataclass(frozen=True)
class ContactDamping:
    """The damping coefficient of one submodel's contacts (cw: the housing; cr: the four groove contacts; cs: the
    spring) and its ratio of critical damping."""

    coefficient: str  # parameter name: cw, cr, cs
    ratio_name: str  # the name of its ratio: zeta_w, zeta_g, zeta_s
    c: float  # N s/m
    zeta: float  # c / (2 sqrt(k ms)), k the mean stiffness of the contacts c damps (as the ratio key states it)
    critical: float  # the coefficient at a ratio of MAX_DAMPING_RATIO, N s/m

    @property
    def keys(self) -> tuple[str, str]:
        """The scene keys of the coefficient and of its ratio (``contacts.cw``, ``contacts.zeta_w``)."""
        return parameter(self.coefficient).key, parameter(self.ratio_name).key

    @property
    def default_ratio(self) -> float | None:
        return parameter(self.ratio_name).default

    @property
    def too_high(self) -> bool:
        return self.zeta > MAX_DAMPING_RATIO


def contact_dampings(values: Mapping[str, Any]) -> dict[str, ContactDamping]:
    """The damping of each coefficient in ``values`` (parameter name -> SI value: a scene's parameters or a run's
    parameter vector, where a damping that is off has no entry), by the coefficient's name."""
    out = {}
    for cls in submodels():
        for c, zeta in cls.damping_ratios:
            if c in values:
                k, ms = cls.damped_stiffness(c, values), values["ms"]
                out[c] = ContactDamping(c, zeta, float(values[c]), float(ratio_of_damping(values[c], k, ms)),
                                        float(damping_of_ratio(MAX_DAMPING_RATIO, k, ms)))
    return out


def guard_damping(guard: str, values: Mapping[str, Any]) -> ContactDamping | None:
    """The damping of the contact ``guard`` opens and closes (None: an unknown guard, or its damping off): the
    coefficient of its oscillator (a submodel with one oscillator per guard), else its submodel's only one."""
    for cls in submodels():
        names = [g.name for g in cls.guards]
        if guard not in names:
            continue
        if len(cls.oscillators) == len(names):
            c = cls.oscillators[names.index(guard)][1]
        elif len(cls.damping_ratios) == 1:
            c = cls.damping_ratios[0][0]
        else:
            return None
        return contact_dampings(values).get(c)
    return None
