"""Symbolic derivation of the apex-seal model (Phung, Sultan, Appuhamillage 2018, Eqs. 1-80).

Entry points: :func:`derive_model` (always derives) and :func:`cached_model`
(content-hash cached). Both take the :class:`Effects` and :class:`Assumptions`
of a scene and return a :class:`DerivedModel`.
"""

from .assumptions import Assumptions
from .cache import cached_model
from .effects import EFFECTS, Effects
from .model import DerivedModel, derive_model

__all__ = ["Assumptions", "DerivedModel", "EFFECTS", "Effects", "cached_model", "derive_model"]
