"""Assemble the seal model from the registered submodels: loads, guards, outputs, Eq. 80.

``derive_model(effects, assumptions)`` is the one entry point. It asks every active
submodel (derive/submodels/) for its contacts, so an effect that is off never appears
in any expression. Results are plain sympy expressions of the crank angle ``theta``,
the state (x, y, phi, xd, yd, phid), the parameters (named, in the registry's order),
the chamber pressures (Pa, Pb) and the activations of the contacts that exist.

A cold derivation reports its long steps through :mod:`apexseal.progress` (lines on stderr where progress is on:
the command line, ``simulate(..., progress=True)``): kinematics and contact geometry, the contacts and Eq. 80, and
for a submodel with its own states (the chamber gas: 1-2 s of its 5 s, docs/gas.md) each rate and output as it is
brought to plain symbols. The reports change nothing that is derived.
"""

from __future__ import annotations

from contextlib import nullcontext
from dataclasses import dataclass, field

import sympy as sp
from sympy.physics.vector import Vector

from ..progress import announce, stage
from . import contact_geometry, contact_push, eom, kinematics, law_symbols, rest_balance
from .assumptions import Assumptions
from .choices import Options, options_of
from .effects import Effects
from .kinematics import plain
from .submodels.base import ContactModel, Context, Submodel
from .submodels.declarations import contact_problem
from .submodels.registry import RegistryError, guard, laws_of, origin, parameter_names, state_names, submodels
from .symbols import STATE_NAMES, P, Pa, Pb, state_symbol


@dataclass
class DerivedModel:
    effects: Effects
    assumptions: Assumptions
    mass_matrix: sp.Matrix
    forcing: sp.Matrix
    #: contact guard name -> expression; the contact is closed while it is negative
    guards: dict[str, sp.Expr]
    #: contact guard name -> activation symbol
    activations: dict[str, sp.Symbol]
    #: velocity switches of damping and friction laws: name -> expression
    velocity_guards: dict[str, sp.Expr]
    #: named outputs: forces (groove-frame components, N), moments about C (N m), friction powers (W)
    outputs: dict[str, sp.Expr]
    #: intermediate quantities keyed by the paper's equation labels, for the paper check
    quantities: dict[str, sp.Expr] = field(default_factory=dict)
    #: the parameter vector's names, in order (the registry's at derivation time)
    parameter_names: tuple[str, ...] = ()
    #: the continuous states, in the order of the state vector: the seal body's six, then the active submodels' own
    state_names: tuple[str, ...] = STATE_NAMES
    #: time derivatives of the submodels' own states (the seal body's follow from Eq. 80), by state name
    rates: dict[str, sp.Expr] = field(default_factory=dict)
    #: Pa, Pb as expressions of the states when a submodel computes them (then the input u is not used)
    pressures: dict[str, sp.Expr] = field(default_factory=dict)

    @property
    def guard_names(self) -> tuple[str, ...]:
        return tuple(self.guards)

    @property
    def options(self) -> Options:
        return options_of(self.effects, self.assumptions)


def _context(k, g, options: Options) -> Context:
    names = state_names(options)
    return Context(k, g, options, P, Pa, Pb, {n: state_symbol(n) for n in names})


def _contacts(k, g, options: Options) -> list[tuple[type[Submodel], ContactModel]]:
    """The contacts of the active submodels, each with the submodel whose laws gave it (each one it declares, with
    a guard it declares: :func:`_refuse_undeclared`)."""
    ctx = _context(k, g, options)
    out = []
    for cls in submodels():
        if cls.active(options):
            with laws_of(cls, "contacts()"):
                own = cls().contacts(ctx)
            _refuse_undeclared(cls, own)
            out += [(cls, c) for c in own]
    return out


def _refuse_undeclared(cls: type[Submodel], contacts: list[ContactModel]) -> None:
    """A contact that submodel ``cls`` does not declare (its ``contact_names``), or a guard of it that ``cls`` does
    not declare, is refused, naming both (outputs of an undeclared contact had no meaning, a guard no mode)."""
    for c in contacts:
        why = contact_problem(cls, c.name)
        if why is None and c.guard is not None and c.guard_name not in {gd.name for gd in cls.guards}:
            why = (f"returned ContactModel({c.name!r}) with guard_name={c.guard_name!r}, a guard it does not declare "
                   f"(its guards: {', '.join(gd.name for gd in cls.guards) or 'none'})")
        if why is None:
            why = next((w for load in c.loads if (w := _load_problem(c, load)) is not None), None)
        if why is not None:
            raise RegistryError(f"the submodel {cls.name} ({origin(cls)}) {why}")


def _load_problem(c: ContactModel, load) -> str | None:
    """Why a ``Load`` of contact ``c`` cannot enter the equations of motion (its force and point are vectors of
    sympy.physics.vector, Eqs. 74-80 take their components), or None."""
    for what, value in (("force", load.force), ("r_CP", load.r_CP)):
        if not isinstance(value, Vector):
            return (f"returned ContactModel({c.name!r}) with a Load {getattr(load, 'name', '?')!r} whose {what} is "
                    f"{value} (a {type(value).__name__}), not a vector: give it as a magnitude times a unit vector, "
                    "e.g. force=F * k.G.x (the ground frame's X axis) or F * k.S.y (the seal's)")
    return None


def _contact_where(c: ContactModel) -> str:
    return f"contact {c.name}" + (f" (guard {c.guard_name})" if c.guard is not None else "")


def _own_states(k, g, options: Options, known: frozenset) -> tuple[dict, dict, dict]:
    """The submodels' own state derivatives, the chamber pressures they compute, and their extra outputs (each in
    the symbols ``known``: :func:`.law_symbols.check`)."""
    ctx = _context(k, g, options)
    moving = law_symbols.velocities(options)
    rates, pressures, outputs = {}, {}, {}
    for cls in submodels():
        if not cls.active(options):
            continue
        model = cls()
        with laws_of(cls, "rates()"):
            own_rates = model.rates(ctx)
        own_rates = _plain_each(cls, "rate of", own_rates)
        law_symbols.check(cls, "rates()", own_rates.values(), known, options, moving)
        rates.update(own_rates)
        with laws_of(cls, "chamber_pressures()"):
            pa_pb = model.chamber_pressures(ctx)
        if pa_pb is not None:
            if pressures:
                raise ValueError(f"two submodels compute the chamber pressures ({cls.name!r} is the second)")
            pressures = {"Pa": plain(pa_pb[0]), "Pb": plain(pa_pb[1])}
            law_symbols.check(cls, "chamber_pressures()", pressures.values(), known, options)
        with laws_of(cls, "outputs()"):
            own_outputs = model.outputs(ctx)
        own_outputs = _plain_each(cls, "output", own_outputs)
        law_symbols.check(cls, "outputs()", own_outputs.values(), known, options)
        outputs.update(own_outputs)
    own = [n for n in state_names(options) if n not in STATE_NAMES]
    missing = sorted(set(own) - set(rates))
    if missing:
        raise ValueError(f"states without a rate: {', '.join(missing)} (a submodel's rates() must give each)")
    return {n: rates[n] for n in own}, pressures, outputs


def _plain_each(cls: type[Submodel], what: str, exprs: dict) -> dict:
    """:func:`.kinematics.plain` of each expression, by name. For a submodel with its own states (the chamber gas:
    each of its rates and outputs takes seconds) a progress line before each, ``derivation: gas: rate of ma (1/4)``;
    the others' are quick and report nothing."""
    out = {}
    for i, (n, e) in enumerate(exprs.items(), start=1):
        if cls.states:
            announce(f"derivation: {cls.name}: {what} {n} ({i}/{len(exprs)})")
        out[n] = plain(e)
    return out


def submodel_contacts(name: str, k, g, options: Options | None = None) -> list[ContactModel]:
    """The contacts of one registered submodel (e.g. for the paper check), whether or not it is switched on."""
    cls = next(c for c in submodels() if c.name == name)
    return cls().contacts(_context(k, g, options or options_of(Effects(), Assumptions())))


def derive_model(effects: Effects | None = None, assumptions: Assumptions | None = None) -> DerivedModel:
    """Derive the model from frames, points and contact rules (Eqs. 10-80)."""
    effects = effects or Effects()
    assumptions = assumptions or Assumptions()
    options = options_of(effects, assumptions)
    with stage("derivation: kinematics and contact geometry (Eqs. 10-47)"):
        k = kinematics.build()
        g = contact_geometry.build(k)
    with stage("derivation: the contacts' laws and the equations of motion (Eqs. 33-80)"):
        owned = _contacts(k, g, options)
        contacts = [c for _, c in owned]
        loads = [load for c in contacts for load in c.loads]
        eq = eom.build(k, loads, inertia=options.on("inertia"))
        guards, vguards, outputs, parts = {}, {}, {}, {}
        activations = {c.guard_name: guard(c.guard_name).symbol for c in contacts if c.guard is not None}
        known, moving = law_symbols.known_symbols(options, activations.values()), law_symbols.velocities(options)
        for cls, c in owned:
            own_guards = {c.guard_name: plain(c.guard)} if c.guard is not None else {}
            own_vguards = {n: plain(e) for n, e in c.velocity_guards.items()}
            fx = sum((load.force.dot(k.G.x) for load in c.loads), sp.S.Zero)
            fy = sum((load.force.dot(k.G.y) for load in c.loads), sp.S.Zero)
            mz = sum((load.r_CP.cross(load.force).dot(k.G.z) for load in c.loads), sp.S.Zero)
            forces = {f"F_{c.name}_X": plain(fx), f"F_{c.name}_Y": plain(fy), f"M_{c.name}": plain(mz)}
            if any(load.friction_power != 0 for load in c.loads):
                forces[f"Pf_{c.name}"] = plain(sum((load.friction_power for load in c.loads), sp.S.Zero))
            if c.slide is not None:  # the seal's sliding velocity there, for the wear numbers (runtime/results/wear.py)
                forces[f"v_{c.name}"] = plain(c.slide)
            law_symbols.check(cls, _contact_where(c), [*own_guards.values(), *own_vguards.values()], known, options)
            law_symbols.check(cls, _contact_where(c), forces.values(), known, options, moving)
            if c.guard is not None:  # its law pushes the seal out where its guard says closed
                contact_push.check(cls, c.name, c.guard_name, own_guards[c.guard_name], forces, activations, options)
            guards.update(own_guards)
            vguards.update(own_vguards)
            outputs.update(forces)
            parts[cls.name] = parts.get(cls.name, sp.S.Zero) + forces[f"F_{c.name}_X"]
        # Eq. 9: the laws balance at rest with delta_w, every contact closed there in it
        rest_balance.check(eq.forcing[0], guards, activations, options, parts)
    pf = [e for n, e in outputs.items() if n.startswith("Pf_")]
    outputs["Pf_total"] = sum(pf, sp.S.Zero)
    own = [n for n in state_names(options) if n not in STATE_NAMES]
    with stage(f"derivation: the submodels' own states ({', '.join(own)}): rates, pressures, outputs") if own \
            else nullcontext():
        rates, pressures, own_outputs = _own_states(k, g, options, known)
    outputs.update(own_outputs)

    quantities = _quantities(k, g)
    return DerivedModel(effects, assumptions, eq.mass_matrix, eq.forcing, guards, activations, vguards,
                        outputs, quantities, parameter_names(opts=options), (*STATE_NAMES, *rates), rates, pressures)


def _quantities(k, g) -> dict[str, sp.Expr]:
    """The intermediate results the paper prints, by equation label (checked in derive/paper_check/)."""
    from . import kinematics as kin

    S = k.S
    q: dict[str, sp.Expr] = {}
    q["12.i"], q["12.j"] = kin.position_rotor(k)
    q["13.i"], q["13.j"] = kin.velocity_rotor(k)
    q["15.X1"], q["15.Y1"] = kin.acceleration_rotor(k)
    q["22"] = plain(g.l2)
    q["23"] = plain(g.l4)
    q["31"] = plain(g.beta)
    q["33"] = plain(g.xs5)
    q["36"] = plain(g.b6)
    q["37"] = plain(g.X_s6)
    q["38"] = plain(g.spring_compression)
    for i, name in enumerate(("b1", "b2", "b3", "b4"), start=40):
        q[str(i)] = plain(g.gaps[name])
    for label, vec in (("20", g.r_i1), ("21", g.r_i2), ("26", g.r_s5), ("44", g.r_s1), ("45", g.r_s2),
                       ("46", g.r_s3), ("47", g.r_s4)):
        q[label + ".X"], q[label + ".Y"] = k.components(vec)
    for label, vec in (("51", k.relative_velocity(g.r_i1)), ("57", k.relative_velocity(g.r_c2)),
                       ("59", k.relative_velocity(g.r_c4)), ("61", k.relative_velocity(g.r_i2)),
                       ("72", k.relative_velocity(g.r_s6))):
        q[label + ".X"], q[label + ".Y"] = k.components(vec)
    v_i1 = k.relative_velocity(g.r_i1)
    q["52"], q["53"] = plain(v_i1.dot(S.x)), plain(v_i1.dot(S.y))
    s5 = k.point_on_seal("s5q", g.r_s5)
    q["66.X"], q["66.Y"] = k.components(s5.vel(k.N))
    return q
