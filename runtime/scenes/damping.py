"""Contact damping as a ratio of critical damping, and the ratios at which it makes a contact chatter.

Each contact's damping acts on approach only and only while the contact is closed (``derive/submodels/laws.py``:
c max(v, 0) of Eqs. 55, 62, 67, 73, v the closing speed of the seal's material point at the contact). The elastic
force starts from 0 at the touch, the damping force jumps from 0 to c v. Above critical damping
(zeta = c / (2 sqrt(k ms)) > 1) that jump outweighs the elastic force, and where the material point still
approaches while the penetration no longer grows (the tip's contact point s5 slides along the tip arc as the seal
rocks, Eqs. 29-31) it pushes the seal off the wall at zero penetration: the contact opens, the loads press it shut
again, and it closes with the same jump. It chatters, the more readily the larger c (docs/hard-cases.md, "Chattering").
A scene warns about such a ratio (``check_damping``, ``runtime/scenes/checks.py``), and a run that chatters on a
contact damped that strongly advises less damping or the damping law "penetration" (``chatter_advice``,
``runtime/solving/checks.py``).

Under the modelling choice ``assumptions.damping_law = "penetration"`` the dampers of the contacts that touch and
leave (the housing and the groove contacts, not the preloaded spring: ``derive/submodels/seal.py``,
``penetration_damped``) are c max(v, 0) delta / delta_ref (Hunt-Crossley type, not in the paper): their force starts
from 0 at the touch, so a ratio above critical is no cause of chatter there and is not warned about
(:attr:`ContactDamping.continuous`). The same damper vanishes at the touch, so the stability check of the explicit
fixed-step methods counts on none of it (:func:`continuous_dampers`, ``runtime/solving/contact_stability.py``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from ...derive.numbers import damping_of_ratio, ratio_of_damping
from ...derive.submodels.damping_rule import DAMPING_LAWS, penetration_damped
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
    spring; a user's submodel's own) and its ratio of critical damping."""

    coefficient: str  # parameter name: cw, cr, cs
    ratio_name: str  # the name of its ratio: zeta_w, zeta_g, zeta_s
    c: float  # N s/m
    zeta: float  # c / (2 sqrt(k ms)), k the mean stiffness of the contacts c damps (as the ratio key states it)
    critical: float  # the coefficient at a ratio of MAX_DAMPING_RATIO, N s/m
    #: its dampers are continuous at the touch (the damping law "penetration"): no jump, so no chatter from it
    continuous: bool = False
    #: the damping law "penetration" would make its dampers continuous at the touch (not the preloaded spring's)
    switchable: bool = False
    #: the submodel whose contacts it damps (its ``name``: "housing", "groove", "spring", a user's own), as the
    #: chattering message names the contact
    owner: str = ""

    @property
    def keys(self) -> tuple[str, str]:
        """The scene keys of the coefficient and of its ratio (``contacts.cw``, ``contacts.zeta_w``)."""
        return parameter(self.coefficient).key, parameter(self.ratio_name).key

    @property
    def default_ratio(self) -> float | None:
        return parameter(self.ratio_name).default

    @property
    def too_high(self) -> bool:
        """Above critical damping, where a damper that jumps at the touch makes the contact chatter (False for one
        that is :attr:`continuous`)."""
        return self.zeta > MAX_DAMPING_RATIO and not self.continuous

    @property
    def why(self) -> str:
        """Why its ratio above critical is a problem (:data:`WHY`), and the damping law that removes the jump where
        it applies to this contact."""
        return WHY + (f"; assumptions.damping_law = {DAMPING_LAWS[1]!r} damps in proportion to the penetration "
                      "(c v delta / contacts.delta_ref), from 0 at the touch" if self.switchable else "")


def damping_law(values: Mapping[str, Any]) -> str:
    """The choice ``assumptions.damping_law`` of the model whose parameters are ``values`` (by name): "penetration"
    where its reference penetration contacts.delta_ref has a slot (read under that choice only), else the paper's."""
    return DAMPING_LAWS[1] if "delta_ref" in values else DAMPING_LAWS[0]


def continuous_dampers(values: Mapping[str, Any]) -> frozenset[str]:
    """The damping coefficients (cw, cr, cs) whose dampers the damping law of ``values`` makes continuous at the touch
    (c max(v, 0) delta / delta_ref: every contact the coefficient damps is penetration-damped); none under the
    paper's law."""
    return _continuous(damping_law(values))


def _continuous(law: str) -> frozenset[str]:
    """The damping coefficients whose every contact the damping law ``law`` damps in proportion to its penetration."""
    return frozenset(c for cls in submodels() for c, _ in cls.damping_ratios
                     if _guards(cls, c) and all(penetration_damped(g, law) for g in _guards(cls, c)))


def _coefficient(cls, guard: str) -> str | None:
    """The damping coefficient of the contact ``guard`` (a guard of ``cls``) opens and closes: that of its oscillator
    (a submodel with one oscillator per guard), else its submodel's only one (None: neither)."""
    names = [g.name for g in cls.guards]
    if len(cls.oscillators) == len(names):
        return cls.oscillators[names.index(guard)][1]
    if len(cls.damping_ratios) == 1:
        return cls.damping_ratios[0][0]
    return None


def _guards(cls, c: str) -> list:
    """The guards of ``cls`` whose contacts the coefficient ``c`` damps."""
    return [g for g in cls.guards if _coefficient(cls, g.name) == c]


def contact_dampings(values: Mapping[str, Any]) -> dict[str, ContactDamping]:
    """The damping of each coefficient in ``values`` (parameter name -> SI value: a scene's parameters or a run's
    parameter vector, where a damping that is off has no entry), by the coefficient's name."""
    out = {}
    continuous, switchable = continuous_dampers(values), _continuous(DAMPING_LAWS[1])
    for cls in submodels():
        for c, zeta in cls.damping_ratios:
            if c in values:
                k, ms = cls.damped_stiffness(c, values), values["ms"]
                out[c] = ContactDamping(c, zeta, float(values[c]), float(ratio_of_damping(values[c], k, ms)),
                                        float(damping_of_ratio(MAX_DAMPING_RATIO, k, ms)), c in continuous,
                                        c in switchable, cls.name)
    return out


def guard_damping(guard: str, values: Mapping[str, Any]) -> ContactDamping | None:
    """The damping of the contact ``guard`` opens and closes (None: an unknown guard, or its damping off): the
    coefficient of its oscillator (a submodel with one oscillator per guard), else its submodel's only one."""
    for cls in submodels():
        if guard in [g.name for g in cls.guards]:
            c = _coefficient(cls, guard)
            return None if c is None else contact_dampings(values).get(c)
    return None
