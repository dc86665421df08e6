"""A model parameter, declared once by the submodel that owns it.

A :class:`Parameter` says everything the rest of the project needs: its name (the
paper's symbol in ASCII), SI unit, meaning and equation, where a scene sets it
(``key``, e.g. ``"contacts.kw"``), its allowed range and default, and, for derived
parameters (the seal's mass, the tip arc's half-angle, ...), that a plain numeric
function of other values computes it. The parameter vector of the generated
Functions, the scene's sections and their documentation are built from these
declarations (:mod:`apexseal.derive.submodels.registry`); nothing refers to a
parameter by position.

This module imports no sympy: reading a scene needs only the declarations.
"""

from __future__ import annotations

from dataclasses import dataclass

#: the plausible range of a contact's stiffness (Parameter.plausible): 1e3 N/m (a soft pad) to 1e13 N/m (beyond a
#: hardened steel line contact of this size)
CONTACT_STIFFNESS = (1e3, 1e13, "N/m")


@dataclass(frozen=True)
class Parameter:
    """One entry of the model's parameter vector, or a scene input that feeds a derived one."""

    name: str
    unit: str  # SI, pint syntax ("m", "N/m", "N*s/m", "1")
    meaning: str
    #: scene key ("section.key"); None: derived, computed by its submodel's ``derived``
    key: str | None = None
    #: default when the scene omits the key (None: required, unless ``optional``)
    default: float | None = None
    #: the key may be omitted; the submodel's ``derived`` then computes the value
    optional: bool = False
    gt: float | None = None
    ge: float | None = None
    lt: float | None = None
    le: float | None = None
    #: unit in which messages show values (default: ``unit``)
    show: str | None = None
    #: unit of bare numbers in a scene (default: ``unit``)
    bare: str | None = None
    #: sympy assumptions of the symbol: "positive", "nonnegative" or "real"
    sign: str = "positive"
    #: False for scene inputs that only feed derived parameters (e.g. the seal's density)
    in_vector: bool = True
    #: the range of engineering practice (SI low, SI high, unit to show it in): outside it a scene still loads,
    #: with a warning (docs/scenes.md, "Plausible ranges"); None: no such range
    plausible: tuple[float, float, str] | None = None
    #: the effect that must be on for any law to read it (e.g. "groove_friction" for mu2); None: the switch of
    #: its submodel. While that effect is off a scene may omit it (registry.needing)
    needs: str | None = None

    @property
    def section(self) -> str | None:
        return self.key.split(".", 1)[0] if self.key else None

    @property
    def leaf(self) -> str | None:
        return self.key.split(".", 1)[1] if self.key else None

    @property
    def symbol(self):
        """The sympy symbol (imported lazily; equal symbols are shared by name and assumptions)."""
        import sympy as sp

        kw = {"positive": {"positive": True}, "nonnegative": {"nonnegative": True}}.get(self.sign, {})
        return sp.Symbol(self.name, real=True, **kw)

    def range_kwargs(self) -> dict[str, float]:
        return {k: v for k, v in (("gt", self.gt), ("ge", self.ge), ("lt", self.lt), ("le", self.le)) if v is not None}
