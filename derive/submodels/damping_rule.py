"""Which contact dampers the damping law scales by the penetration: the one rule of the laws
(:func:`.laws.damper_depth`) and of the runtime's damping checks (runtime/scenes/damping.py), below both the laws and
the seal's submodel, which declares the option."""

from __future__ import annotations

from .base import Guard

#: the choices of ``assumptions.damping_law``: the paper's contact dampers c max(v, 0) (Eqs. 55, 62, 67, 73), or
#: the same times the penetration over contacts.delta_ref (Hunt-Crossley type: continuous at the touch; not in the
#: paper), derive/submodels/laws.py
DAMPING_LAWS = ("velocity", "penetration")


def penetration_damped(guard: Guard, law: str) -> bool:
    """Whether the damping law ``law`` scales the damper of the contact ``guard`` opens and closes by its penetration:
    under "penetration", every contact but one closed at rest by design (the preloaded spring: its compression is
    mostly its preload, not the depth of an impact, and it does not touch and leave). The one rule of the laws
    (:func:`.laws.damper_depth`) and of the runtime's damping checks (runtime/scenes/damping.py)."""
    return law == DAMPING_LAWS[1] and not guard.closed_at_rest
