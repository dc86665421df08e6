"""The submodel contract: what a contact or load declares, and what the derivation hands it.

A :class:`Submodel` declares, as class attributes, its parameters (:class:`~..parameters.Parameter`: unit,
meaning, scene key, range, default), its option slots (:class:`~..options.Option`), its guards
(:class:`Guard`: the contact is closed while the guard is negative; the name of its output and the labels of
its modes), which option switches it on, its (stiffness, damping) pairs and its friction laws that can stick
(:class:`Friction`) for the stability checks of the explicit fixed-step methods, its damping coefficients that a
ratio of critical damping may state instead, and plain numeric functions for its other derived parameters. Its laws
are written in :meth:`Submodel.contacts`, which returns the loads it puts on the seal, given a :class:`Context`
(kinematics, contact geometry, options, parameter symbols, the chamber pressures, activation symbols).

Declarations import no sympy (a scene is read without it); :meth:`Submodel.contacts` imports what it needs.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar

from ..numbers import damping_of_ratio
from ..options import Option, need_met
from ..parameters import Parameter


@dataclass(frozen=True)
class State:
    """A continuous state a submodel owns: its name, SI unit, meaning, and the scale engines integrate it in."""

    name: str
    unit: str
    meaning: str
    #: integrators see state / scale (of order 1)
    scale: float = 1.0
    #: a rate of the rotor-driven motion (the seal's velocities): integrated in units of scale * omega
    rate: bool = False
    #: the unit results show it in (figures, summaries), and display value = display_scale * SI value
    display: str = ""
    display_scale: float = 1.0
    #: the unit a scene's initial value of it and the messages about that value show it in (default: ``unit``; as
    #: ``Parameter.show``), and the largest magnitude a scene may start it at (None: no scene key sets it)
    show: str | None = None
    initial_limit: float | None = None


@dataclass(frozen=True)
class Guard:
    """A contact's guard: the contact is closed while the guard expression is negative."""

    name: str  # e.g. "xs5"
    activation: str  # the activation symbol's name, e.g. "s_h" (1 while closed)
    meaning: str
    #: name of the result's output of ``sign * guard`` (a gap: +1; a penetration or compression: -1)
    output: str
    sign: int = 1
    #: parts of a mode's label while the contact is closed / open (e.g. "h" / "h0")
    closed_label: str = ""
    open_label: str = ""
    #: closed at rest by design (a preloaded spring): its depth says nothing about leaving the model's domain
    closed_at_rest: bool = False
    #: the contact it opens and closes (the prefix of that contact's outputs); None: the submodel's name
    contact: str | None = None

    @property
    def labels(self) -> tuple[str, str]:
        """Its (closed, open) parts of a mode's label: the declared ones, or its name and its name + "0"."""
        return self.closed_label or self.name, self.open_label or self.name + "0"

    @property
    def symbol(self):
        """The activation as a sympy symbol (1 while closed, 0 while open; the one way it is made, so every
        substitution of it matches)."""
        import sympy as sp

        return sp.Symbol(self.activation, nonnegative=True)


@dataclass(frozen=True)
class Friction:
    """A regularised Coulomb law mu N tanh(v / v_eps) of the submodel (:func:`.laws.coulomb`; Algorithm 1, Eq. 73)
    whose sliding velocity passes through zero (the seal sticks and slips back). There the law is a damper of
    coefficient mu N / v_eps on each contact's sliding velocity, the seal's slide minus the contact's offset across
    the sliding direction times the seal's turning rate; with the seal's mass ms and inertia Icg (Eq. 80) the law
    damps at the rates of the eigenvalues of M^-1 C, C = mu / v_eps sum N_c (1, -d_c)^T (1, -d_c) over its contacts
    c at offsets d_c. Explicit Euler resolves them only with a step h of at most 2 / rate
    (runtime/solving/friction_stability.py)."""

    #: the friction coefficient's parameter (the law is off, and not checked, while it has no slot)
    mu: str
    #: the contacts whose normal forces it multiplies (their outputs F_<c>_X, F_<c>_Y, Pf_<c>), all sliding one way
    contacts: tuple[str, ...]
    #: each contact's offset d_c from the centre of gravity across the sliding direction, signed, as (factor,
    #: parameter): factor * parameter; empty: every contact on the line through the centre of gravity
    offsets: tuple[tuple[float, str], ...] = ()
    #: what slides, for messages (e.g. "the seal along the groove walls")
    slide: str = ""


@dataclass
class Load:
    """A force ``force`` at the seal's material point ``r_CP`` (from C)."""

    name: str
    r_CP: Any  # sympy.physics.vector.Vector
    force: Any  # Vector
    #: rate at which friction at this contact dissipates energy (>= 0), or 0
    friction_power: Any = 0


@dataclass
class ContactModel:
    """The loads of one contact and the guard that opens and closes it."""

    name: str
    loads: list[Load] = field(default_factory=list)
    #: the guard's name (declared by the submodel) and expression; None for loads that always act (pressure)
    guard_name: str | None = None
    guard: Any = None
    #: velocity switches inside the contact law (for the guard outputs): name -> expression
    velocity_guards: dict[str, Any] = field(default_factory=dict)
    #: the seal's sliding velocity along the contact's surface (m/s, signed), the one its friction law takes,
    #: whether or not friction is on; the model outputs it as v_<name> (the wear numbers of a run read it:
    #: runtime/results/wear.py); None: a load that does not slide on a wall (the pressures)
    slide: Any = None


@dataclass(frozen=True)
class Context:
    """What the derivation hands a submodel: kinematics ``k``, contact geometry ``g``, ``options``, and symbols."""

    k: Any  # derive.kinematics.Kinematics
    g: Any  # derive.contact_geometry.ContactGeometry
    options: Any  # derive.choices.Options
    #: parameter symbols by name
    P: Mapping[str, Any]
    #: chamber pressures (sympy symbols Pa, Pb: chamber a on +Ys, b on -Ys; Eq. 75)
    Pa: Any
    Pb: Any
    #: the symbols of the continuous states, by name (the seal body's and every active submodel's own)
    X: Mapping[str, Any] = field(default_factory=dict)

    def activation(self, guard: Guard):
        """The activation symbol of a guard (1 = closed)."""
        return guard.symbol


def built_in(cls: type) -> bool:
    """True for apexseal's own submodels (and classes of its modules), False for a user's or a package's."""
    return cls.__module__.split(".")[0] == __package__.split(".")[0]


class Submodel:
    """A contact or load of the seal (see the module docstring)."""

    #: unique name; also the prefix of its outputs (F_<name>_X, F_<name>_Y, M_<name>, Pf_<name>)
    name: ClassVar[str] = ""
    parameters: ClassVar[tuple[Parameter, ...]] = ()
    options: ClassVar[tuple[Option, ...]] = ()
    guards: ClassVar[tuple[Guard, ...]] = ()
    #: continuous states it owns (the seal body: x, y, phi and their rates)
    states: ClassVar[tuple[State, ...]] = ()
    #: names of the contacts it declares (the prefixes of their outputs F_<c>_X, F_<c>_Y, M_<c>, Pf_<c>), when they
    #: differ from ``name`` (one submodel, several contacts)
    contact_names: ClassVar[tuple[str, ...]] = ()
    #: the option slot that switches the submodel on (None: always on)
    switch: ClassVar[str | None] = None
    #: for a submodel no effect switches: the modelling choices ("slot=choice") any of which brings it into a model
    #: (the chamber gas: ``pressure_model=chamber`` or ``=chamber+leakage``); none: always on (with its switch)
    enters_with: ClassVar[tuple[str, ...]] = ()
    #: (stiffness, damping) parameter names of the oscillators it adds (the explicit fixed-step methods' stability checks)
    oscillators: ClassVar[tuple[tuple[str, str], ...]] = ()
    #: damping parameter names of its dampers with no stiffness of their own, each a force -c v on the seal (the
    #: explicit fixed-step methods' stability checks: its motion decays at the rate c/ms, which a step must follow)
    dampers: ClassVar[tuple[str, ...]] = ()
    #: its friction laws whose sliding velocity passes through zero (the explicit fixed-step methods' stability checks)
    frictions: ClassVar[tuple[Friction, ...]] = ()
    #: (name, SI unit, meaning) of each of its named :meth:`outputs`, optionally followed by the unit results show
    #: it in and the factor to it from SI (e.g. "g/s", 1e3): the result's column, its CSV header and docs
    output_columns: ClassVar[tuple[tuple, ...]] = ()
    #: (damping coefficient, damping ratio) parameter names: unless the scene gives the coefficient, it is
    #: c = 2 zeta sqrt(k ms), k the mean stiffness of the oscillators damped by c (Eqs. 55, 62, 67, 73 take c; the
    #: ratio is the scene's way of stating it). A scene gives at most one of the two (an error names both).
    damping_ratios: ClassVar[tuple[tuple[str, str], ...]] = ()
    #: further pairs of scene keys that state one thing two ways: a scene gives at most one of each pair (an error
    #: names both), and an override of one replaces the other
    alternatives: ClassVar[tuple[tuple[str, str], ...]] = ()
    #: pairs (key, key it makes unread) that state one thing two ways where the first wins: a scene that gives both
    #: loads with a warning that the second is not read (a result's scene.toml wrote both before they were paired),
    #: and an override of one replaces the other
    supersedes: ClassVar[tuple[tuple[str, str], ...]] = ()
    #: scene keys, or tables of them, that its :meth:`derived` reads besides its parameters' keys (the gas model:
    #: ``machine.ports``): not read, so neither range-checked as errors nor questioned, while it is out of the model
    #: (the keys of a nested table keep the ranges of their own: a port 200 deg wide is refused whatever reads it)
    scene_inputs: ClassVar[tuple[str, ...]] = ()
    #: one line for the docs
    summary: ClassVar[str] = ""
    #: what each of its contacts is, for the result's columns and docs/outputs.md (default: :attr:`summary`)
    contact_meanings: ClassVar[dict[str, str]] = {}

    @classmethod
    def active(cls, options) -> bool:
        """Whether it enters a model of the options ``options``: its switch on, and one of :attr:`enters_with`."""
        return ((cls.switch is None or need_met(cls.switch, options, False))
                and (not cls.enters_with or any(need_met(e, options, False) for e in cls.enters_with)))

    @classmethod
    def derived(cls, values: dict[str, float], inputs: Mapping[str, Any], options) -> dict[str, float]:
        """Values of its derived parameters (plain numbers) from the values known so far and the scene inputs:
        each damping coefficient of :attr:`damping_ratios` the scene does not give, from its ratio."""
        out = {}
        for c, zeta in cls.damping_ratios:
            if values.get(c) is None:
                out[c] = damping_of_ratio(values[zeta], cls.damped_stiffness(c, values), values["ms"])
        return out

    @classmethod
    def damped_stiffness(cls, c: str, values: Mapping[str, Any]) -> Any:
        """The stiffness a ratio of the damping coefficient ``c`` refers to: the mean stiffness of the oscillators
        ``c`` damps (c = 2 zeta sqrt(k ms), :attr:`damping_ratios`), from the values by parameter name."""
        ks = [values[k] for k, damping in cls.oscillators if damping == c]
        return sum(ks) / len(ks)

    @classmethod
    def damping_alternatives(cls) -> tuple[tuple[str, str], ...]:
        """The scene keys of its damping coefficients beside those of their ratios (:attr:`damping_ratios`)."""
        key = {p.name: p.key for p in cls.parameters}
        return tuple((key[c], key[zeta]) for c, zeta in cls.damping_ratios)

    @classmethod
    def scene_alternatives(cls) -> tuple[tuple[str, str], ...]:
        """The pairs of scene keys that state one thing two ways (an override of one replaces the other, a resolved
        scene writes one): its damping coefficients beside their ratios, its further :attr:`alternatives`, and the
        pairs it :attr:`supersedes` (of which only these may both be given)."""
        return cls.damping_alternatives() + cls.alternatives + cls.supersedes

    @classmethod
    def rest_force(cls, p) -> Any:
        """The force along the groove axis (+X, towards the housing) that its laws put on the seal at rest (the
        state at zero, theta = 0, no chamber pressure, no inertia), which the housing's rest deflection delta_w of
        Eq. 9 balances with the others' (``SealBody.rest_wall_deflection``; the derivation checks the balance,
        derive/rest_balance.py). 0 by default; the spring's is its preload (Eq. 39); a load of one's own that
        acts at rest returns it here. ``p``: the parameters by name (numbers, or CasADi or sympy symbols)."""
        return 0

    def contacts(self, ctx: Context) -> list[ContactModel]:
        """The contacts and loads it puts on the seal."""
        return []

    def rates(self, ctx: Context) -> dict[str, Any]:
        """The time derivatives of its own states (by state name; the seal body's come from Eq. 80)."""
        return {}

    def chamber_pressures(self, ctx: Context) -> tuple[Any, Any] | None:
        """Pa, Pb as expressions of its states, when it computes them (then they replace the input u)."""
        return None

    def outputs(self, ctx: Context) -> dict[str, Any]:
        """Named outputs besides the loads' forces and moments (e.g. chamber volumes, mass flows); declare each
        one's unit and meaning in :attr:`output_columns`."""
        return {}

    @classmethod
    def initial_state(cls, values: Mapping[str, float], theta: float) -> dict[str, float]:
        """Initial values of its own states at crank angle ``theta`` from the parameter values (by name)."""
        return {}
