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

#: the plausible range of a contact's stiffness (Parameter.plausible): 1e3 N/m (a soft pad) to 1e12 N/m, beyond a
#: hardened steel line contact (of the order of E* times its length: 1.15e11 Pa x 2 m, the longest seal a scene
#: takes, is 2.3e11 N/m). Stiffer contacts were 1e13 N/m until a reviewer's run at that value created energy at
#: the default tolerance (the seal launched into its groove at 17 m/s) with no warning
CONTACT_STIFFNESS = (1e3, 1e12, "N/m")
#: the plausible range of an absolute gas pressure (a chamber's, the supply's, the exhaust's): 1 kPa (below a steam
#: condenser's 5 kPa) to 100 MPa (above the 90 MPa discharge of the hydrogen compressors that fill 70 MPa vehicle
#: tanks, the highest-pressure positive displacement gas machines; supercritical CO2 expanders work at 20-30 MPa)
ABSOLUTE_PRESSURE = (1e3, 1e8, "kPa")
#: the plausible range of a gas temperature: 4 K (the helium expanders of liquefiers, the coldest gas expanders) to
#: 3000 K (above the 2200-2400 K adiabatic flame temperature of hydrocarbon fuels in air, a rotary engine's gas)
GAS_TEMPERATURE = (4.0, 3000.0, "K")


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
    #: sympy assumptions of the symbol: "positive", "nonnegative" or "real" (a scene input's range must lie within
    #: it: a "positive" one needs a lower bound gt or ge of at least 0)
    sign: str = "positive"
    #: False for scene inputs that only feed derived parameters (e.g. the seal's density)
    in_vector: bool = True
    #: the range of engineering practice (SI low, SI high, unit to show it in): outside it a scene still loads,
    #: with a warning (docs/scenes.md, "Plausible ranges"); None: no such range
    plausible: tuple[float, float, str] | None = None
    #: the effect that must be on for any law to read it (e.g. "groove_friction" for mu2), or a tuple of effects
    #: any of which reads it (friction.v_eps: every friction law); None: the switch of its submodel. While it is
    #: off the parameter has no slot in the model, and a scene may omit it (registry.needing)
    needs: str | tuple[str, ...] | None = None
    #: True where a scene may give it as a schedule along the crank angle instead of one value: periodic and
    #: piecewise linear through values at knots (``[<section>.schedule]``, runtime/scenes/schedule.py), which the
    #: event-locating engines integrate exactly between output samples (the spring's preload delta_s)
    schedulable: bool = False

    def __post_init__(self) -> None:
        """Refuse a sign the declared range contradicts: the derivation simplifies with the symbol's assumptions
        (Max(p, 0), Abs(p), sqrt(p**2) become p for a positive p), so a scene value the sign excludes would run a
        law that is wrong for it. Zero is admitted under "positive" (the built-in damping and friction
        coefficients take it; tests/generated/test_gen_effects.py checks their laws there). A negative default
        within a range that admits no negative value lies outside that range: the registry refuses it as such
        (submodels/declarations.py), not as a question of sign."""
        signs = ("positive", "nonnegative", "real")
        if self.sign not in signs:
            raise ValueError(f"parameter {self.name}: sign={self.sign!r} is not one of {', '.join(map(repr, signs))}")
        if self.sign == "real" or self.key is None:  # a derived value: its submodel computes it, no scene sets it
            return
        low = max((b for b in (self.gt, self.ge) if b is not None), default=None)
        why = None
        if low is None or low < 0:
            why = "its range admits negative values" + ("" if low is None else f" ({'gt' if low == self.gt else 'ge'}"
                                                                             f"={low!r})")
        if why:
            raise ValueError(f"parameter {self.name} ({self.key}): sign={self.sign!r} lets the derivation assume "
                             f"{self.name} {'> 0' if self.sign == 'positive' else '>= 0'}, but {why}: declare "
                             f"sign=\"real\" for a quantity that may be negative, or a lower bound ge=0 or gt=0")

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
