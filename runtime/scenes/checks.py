"""Checks of a scene that involve more than one key: physical consistency.

Each check runs only when the sections it reads are valid on their own (see
:func:`.scene_schema.validate_sections`), and reports a
:class:`~.scene_errors.Problem` naming the key to change, the value given and
what is allowed. The paper's reasons are cited with each check.
"""

from __future__ import annotations

import functools
import math
from typing import Any

from apexseal.derive.assumptions import Assumptions
from apexseal.derive.effects import Effects, orphans
from apexseal.derive.numbers import (
    machine_numbers,
    outline_mass,
    smallest_chamber_volume,
    smallest_lobe_offset,
    tip_arc_start,
    tip_half_angle,
)
from apexseal.derive.options import without_parent
from apexseal.derive.submodels.seal import DENSEST

from .damping import MAX_DAMPING_RATIO, contact_dampings
from .errors import MISSING, Problem, show_value
from .pressure import TablePressure
from .schema import (
    GAS_SOURCES,
    PRESSURE_SOURCES,
    MachineSection,
    OperationSection,
    PressureSection,
    SealSection,
    Section,
    key_paths,
    raw_at,
    validator_of,
)
from .units import SETTINGS_PLAUSIBLE, bare_hint, implausible, plausible_ranges, table_pressures_implausible

#: largest aspect ratio b = r/L of a dimple-free limaçon (Eq. 4; derive.geometry.looping_free_limit)
MAX_ASPECT_RATIO = 0.25
#: a penalty contact may start at most this fraction of the seal width Ws inside its wall: the scene's bound on the
#: preload's wall deflection (:func:`wall_deflection_problem`) and the run's start check (runtime/solving/preflight.py)
MAX_START_PENETRATION = 0.1

def _mm(x: float) -> str:
    return f"{x * 1e3:.6g} mm"


def check_machine(m: MachineSection, raw: dict[str, Any]) -> list[Problem]:
    """Aspect ratio (Eq. 4), lobe clearance (Eq. 5), port lengths against the machine depth."""
    out = []
    b = m.r / m.L
    if b > MAX_ASPECT_RATIO:
        out.append(
            Problem(
                "machine.r",
                raw_at(raw, ["machine", "r"]),
                f"aspect ratio b = r/L = {b:.4g} exceeds {MAX_ASPECT_RATIO} (Eq. 4: the limaçon must be "
                f"dimple-free); allowed: r <= {MAX_ASPECT_RATIO} L = {_mm(MAX_ASPECT_RATIO * m.L)}",
            )
        )
    if m.embodiment != "limacon-to-limacon" and m.Cr >= m.L:
        out.append(
            Problem(
                "machine.Cr",
                raw_at(raw, ["machine", "Cr"]),
                f"the clearance must be smaller than the half chord (Eq. 5); allowed: "
                f"0 <= Cr < L = {_mm(m.L)}",
            )
        )
    if m.ports is not None:
        for name in ("inlet", "outlet"):
            port = getattr(m.ports, name)
            if port.length > m.H:
                out.append(
                    Problem(
                        f"machine.ports.{name}.length",
                        raw_at(raw, ["machine", "ports", name, "length"]),
                        f"a port cannot be longer than the machine is deep; allowed: "
                        f"<= machine.H = {_mm(m.H)}",
                    )
                )
    return out


def check_chamber_volumes(m: MachineSection, p: PressureSection, raw: dict[str, Any]) -> list[Problem]:
    """Both chamber volumes (Eqs. 1-8, ``derive.chambers``) positive all the revolution, for the gas model.

    The chamber gas model divides by the volume, so a rotor lobe that reaches the housing (a volume <= 0 somewhere
    on the revolution) is refused: on ``machine.k`` for the circular lobes (Eq. 5: the smaller k, the rounder and
    larger the lobe), on ``machine.Cr`` for the limaçon lobe (whose clearance volume is H Cr (pi L - 4 r - pi Cr / 2),
    positive for 0 < Cr < 2 L - 8 r / pi). The other pressure sources do not use the volumes.
    """
    if p.source not in GAS_SOURCES or m.embodiment != "limacon-to-limacon" and m.Cr >= m.L:
        return []  # no gas model, or a lobe clearance already refused by check_machine
    V, th, chamber = smallest_chamber_volume(m.embodiment, r=m.r, L=m.L, H=m.H, Cr=m.Cr, k=m.k)
    if V > 0:
        return []
    where = (f"chamber {chamber}'s volume reaches {V * 1e6:.4g} cm^3 (<= 0) at theta = {math.degrees(th):.4g} deg "
             f"(Eqs. 1-8): the rotor lobe reaches the housing, and pressure.source = \"{p.source}\" needs a "
             "positive volume all the revolution")
    if m.embodiment == "limacon-to-limacon":
        return [Problem("machine.Cr", raw_at(raw, ["machine", "Cr"]),
                        f"{where}; allowed: 0 < Cr < 2 L - 8 r / pi = {_mm(2 * m.L - 8 * m.r / math.pi)}")]
    k_min = smallest_lobe_offset(m.embodiment, r=m.r, L=m.L, H=m.H, Cr=m.Cr)
    return [Problem("machine.k", raw_at(raw, ["machine", "k"]),
                    f"{where}; allowed: k > {_mm(k_min)} for machine.r = {_mm(m.r)}, machine.L = {_mm(m.L)}, "
                    f"machine.Cr = {_mm(m.Cr)} (Eq. 5; or a larger Cr)")]


def tip_numbers(s: SealSection) -> tuple[float, float]:
    """Half-angle of the tip arc and the start of the arc: ``beta_o = asin(Ws / (2 ro))`` (Fig. 5;
    Eq. 24 places the arc's end c1 at ds0; :func:`~apexseal.derive.numbers.tip_half_angle`, as the model's
    parameter) and ``ds0 = ds1 - ro (1 - cos beta_o)`` (Eqs. 24, 27). Called with ro >= Ws/2 only."""
    beta_o = tip_half_angle(s.Ws, s.ro)
    return beta_o, tip_arc_start(ds1=s.ds1, ro=s.ro, beta_o=beta_o)


def check_seal(s: SealSection, raw: dict[str, Any]) -> list[Problem]:
    """Seal and groove sizes (Eqs. 17, 24, 27, 31), and what the mass and inertia need."""
    out = []
    if s.Wg <= s.Ws:
        out.append(
            Problem(
                "seal.Wg",
                raw_at(raw, ["seal", "Wg"]),
                f"the groove must be wider than the seal (Eq. 17); allowed: Wg > seal.Ws = {_mm(s.Ws)}",
            )
        )
    if s.ro < s.Ws / 2:
        out.append(
            Problem(
                "seal.ro",
                raw_at(raw, ["seal", "ro"]),
                f"the tip arc cannot span the seal width (Fig. 5, Eq. 24: beta_o = asin(Ws / (2 ro))); "
                f"allowed: ro >= Ws/2 = {_mm(s.Ws / 2)}",
            )
        )
    else:
        beta_o, ds0 = tip_numbers(s)
        if ds0 <= -s.ds2:
            out.append(
                Problem(
                    "seal.ds1",
                    raw_at(raw, ["seal", "ds1"]),
                    f"the tip arc does not fit on the seal: ds0 = ds1 - ro (1 - cos beta_o) = {_mm(ds0)} "
                    f"(beta_o = {math.degrees(beta_o):.4g} deg) must be > -ds2 = {_mm(-s.ds2)} "
                    f"(Eqs. 24, 27); allowed: ds1 > {_mm(s.ro * (1 - math.cos(beta_o)) - s.ds2)}",
                )
            )
    if s.zeta0 is not None and s.zeta0 >= s.ds1 + s.ds2:
        out.append(
            Problem(
                "seal.zeta0",
                raw_at(raw, ["seal", "zeta0"]),
                f"the seal would leave its groove (Eq. 17); allowed: {zeta0_range(s)}",
            )
        )
    if s.density is None and s.ms is None:  # Icg follows from ms (Eq. 80): ms (Ws^2 + (ds1 + ds2)^2) / 12
        out.append(
            Problem(
                "seal.density",
                MISSING,
                'required to compute seal.ms (Eq. 80); give a density in kg/m^3 (e.g. "7200 kg/m^3") or seal.ms',
            )
        )
    return out


def check_mass(s: SealSection, raw: dict[str, Any]) -> list[Problem]:
    """The seal's mass and inertia (Eq. 80) a body within its outline can have: the outline (a rectangle Ws by
    ds1 + ds2, Bs long, holds the tip arc) filled with the densest material (:data:`DENSEST`) is the heaviest seal,
    and no part of it lies farther from its centre of gravity than the farthest corner, so Icg <= ms (max(ds1,
    ds2)^2 + Ws^2/4). Above them a value is no seal, whatever the material (the run took them, and 1e300 kg failed
    only as a right-hand side that is not finite, or ran silently with an Icg that stops the seal turning)."""
    out = []

    def of_density(density: float) -> float:
        return outline_mass(density, Ws=s.Ws, ds1=s.ds1, ds2=s.ds2, Bs=s.Bs)

    heaviest = of_density(DENSEST)
    if s.ms is not None and s.ms > heaviest:
        written = raw_at(raw, ["seal", "ms"])
        out.append(Problem("seal.ms", written,
                           f"{s.ms * 1e3:.6g} g is heavier than the seal's outline Ws (ds1 + ds2) Bs = "
                           f"{of_density(1.0) * 1e6:.6g} cm^3 filled with the densest material "
                           f"({DENSEST:g} kg/m^3, osmium; Eq. 80); allowed: ms <= {heaviest * 1e3:.6g} g"
                           + bare_hint(plausible_ranges()["seal.ms"], s.ms, written)))
        return out
    ms = s.ms if s.ms is not None else (of_density(s.density) if s.density is not None else None)
    if ms is not None and s.Icg is not None:
        largest = ms * (max(s.ds1, s.ds2) ** 2 + s.Ws**2 / 4)
        if s.Icg > largest:
            out.append(Problem("seal.Icg", raw_at(raw, ["seal", "Icg"]),
                               f"{s.Icg:.6g} kg*m^2 would put mass farther from the centre of gravity than the seal's "
                               f"farthest corner (Eq. 80: ms = {ms * 1e3:.6g} g within Ws = {_mm(s.Ws)} by ds1 + ds2 = "
                               f"{_mm(s.ds1 + s.ds2)}); allowed: Icg <= ms (max(ds1, ds2)^2 + Ws^2/4) = "
                               f"{largest:.6g} kg*m^2"))
    return out


def check_friction_width(m: MachineSection, o: OperationSection, f: Section, raw: dict[str, Any]) -> list[Problem]:
    """The width v_eps of the regularised Coulomb law mu N tanh(v / v_eps) (Algorithm 1, Eq. 73) must lie below
    the fastest sliding speed of the tip on the housing, (L + 2 r) omega (the tip slides at (L - 2 r) omega to
    (L + 2 r) omega; the seal in its groove slides far slower): above it tanh stays on its linear part at every
    contact, so the law is a viscous damper, no Coulomb friction at all (a width of 1e300 m/s ran silently
    without friction). Not checked below the rotor speeds of engineering practice, where the rotor is the value
    questioned."""
    v_eps = getattr(f, "v_eps", None)
    fastest = (m.L + 2 * m.r) * o.omega
    if v_eps is None or v_eps < fastest or o.rpm < SETTINGS_PLAUSIBLE["operation.rpm"].lo:
        return []  # a rotor slower than engineering practice is questioned itself (and by the start's speed check)
    return [Problem("friction.v_eps", raw_at(raw, ["friction", "v_eps"]),
                    f"{v_eps:.6g} m/s is not below the tip's fastest sliding speed (L + 2 r) omega = {fastest:.6g} m/s "
                    f"(machine.L = {_mm(m.L)}, machine.r = {_mm(m.r)}, operation.rpm = {o.rpm:g}): tanh(v / v_eps) "
                    f"would make the friction law a viscous damper (Eq. 73); allowed: 0 < v_eps < {fastest:.6g} m/s")]


def wall_deflection_problem(values: dict[str, float]) -> str | None:
    """The spring's preload, if it deflects the housing wall by more than :data:`MAX_START_PENETRATION` Ws at rest.

    The scene places the housing wall delta_w into the seal's tip at rest, the deflection whose force balances the
    spring's force at rest (Eq. 9: delta_w = ks delta_s / kw, ``SealBody.rest_wall_deflection``), so the seal
    starts delta_w deep in the housing contact. Deeper than a tenth of the seal's width the penalty contact has no
    meaningful force there, and the run could only be refused at its start, whatever else it computes: a scene's
    values alone decide it. delta_w is proportional to the force at rest over kw under either
    ``assumptions.housing_stiffness``, and the force to delta_s (Eq. 39), so the allowed kw and delta_s follow by
    proportion. ``values``: the model's parameters by name, SI (a scene's derived values, a run's parameter
    vector). None when it is within the bound, or nothing presses the seal on the housing (delta_w = 0). The one
    check of it: the scene refuses it on loading (:func:`check_wall_deflection`), a run's start check on a
    parameter vector that did not come from a scene (runtime/solving/preflight.start_problem)."""
    from apexseal.derive.submodels.registry import parameter
    from apexseal.derive.submodels.spring import SpringContact

    delta_w, limit = abs(values.get("delta_w", 0.0)), MAX_START_PENETRATION * values["Ws"]
    if not delta_w > limit:
        return None
    ks, delta_s, kw, ws = (parameter(n).key for n in ("ks", "delta_s", "kw", "Ws"))
    force = SpringContact.rest_force(values)
    return (f"the spring's preload deflects the housing wall by delta_w = {delta_w * 1e6:.4g} µm at rest (Eq. 9: its "
            f"force at rest ks delta_s = {force:.4g} N against {kw} = {values['kw']:.6g} N/m; {ks} = "
            f"{values['ks']:.6g} N/m, {delta_s} = {_mm(values['delta_s'])}), which starts the seal that deep inside "
            f"the housing wall; allowed: delta_w <= {MAX_START_PENETRATION:g} Ws = {limit * 1e6:.4g} µm ({ws} = "
            f"{_mm(values['Ws'])}): {kw} >= {values['kw'] * delta_w / limit:.4g} N/m (a metal housing: about 1e9 "
            f"N/m), or {delta_s} <= {_mm(values['delta_s'] * limit / delta_w)} at this {ks}")


def check_wall_deflection(values: dict[str, float], raw: dict[str, Any]) -> list[Problem]:
    """The preload's wall deflection beyond its bound (:func:`wall_deflection_problem`), against the housing's
    stiffness ``contacts.kw``, whose bound holds whatever the spring's law (the message names the preload's keys
    and their bound too): a housing soft enough for it is the usual slip, since a metal one (about 1e9 N/m) needs
    some 3e5 N of preload. ``values``: the scene's parameters by name, SI."""
    why = wall_deflection_problem(values)
    return [] if why is None else [Problem("contacts.kw", raw_at(raw, ["contacts", "kw"]), why)]


def check_seal_in_rotor(m: MachineSection, s: SealSection, raw: dict[str, Any]) -> list[Problem]:
    """The groove bottom must lie inside the rotor: ds1 + ds2 < L, i.e. Li = L - ds1 > ds2 (Eq. 12); the seal
    fits in the machine's depth: Bs <= H (the default scene's estimates: Bs = 99.9 mm in H = 100 mm)."""
    out = []
    if s.ds1 + s.ds2 >= m.L:
        out.append(Problem(
            "seal.ds2",
            raw_at(raw, ["seal", "ds2"]),
            f"seal.ds1 + seal.ds2 = {_mm(s.ds1 + s.ds2)} reaches past the chord centre (Eq. 12: the groove "
            f"bottom must lie inside the rotor); allowed: ds1 + ds2 < machine.L = {_mm(m.L)}",
        ))
    if s.Bs > m.H:
        out.append(Problem(
            "seal.Bs",
            raw_at(raw, ["seal", "Bs"]),
            f"a seal cannot be longer than the machine is deep; allowed: <= machine.H = {_mm(m.H)}",
        ))
    return out


def _mouth_bound(s: SealSection) -> tuple[float, float] | None:
    """(ro (1 - cos beta_o), beta_o): how far the tip arc reaches down the seal, below which the groove's mouth must
    lie (:func:`mouth_on_flank`); None without a valid tip arc (check_seal reports it)."""
    if not s.ro >= s.Ws / 2:
        return None
    beta_o, ds0 = tip_numbers(s)
    return None if ds0 <= -s.ds2 else (s.ds1 - ds0, beta_o)


def zeta0_range(s: SealSection) -> str:
    """The allowed protrusion, as messages show it: the groove's mouth below the tip arc (:func:`mouth_on_flank`)
    and the seal in its groove (Eq. 17)."""
    top = f"zeta0 < ds1 + ds2 = {_mm(s.ds1 + s.ds2)}"
    bound = _mouth_bound(s)
    return f"0 <= {top}" if bound is None else f"ro (1 - cos beta_o) = {_mm(bound[0])} < {top}"


def mouth_on_flank(s: SealSection, zeta0: float, key_value) -> list[Problem]:
    """The groove's mouth corners must face the seal's flat sides, not its tip arc: the contacts i1 and i2 and the
    side faces of Eqs. 20-21 and 44-47 lie between the arc's ends c1, c3 (at ds0 from C, Eq. 24) and the back face,
    and at rest i1 is l1 = ds0 + zeta0 + delta_w - ds1 below c1 (delta_w >= 0, a few nanometres). With l1 < 0 the
    model measured the side gap against the flank produced past the arc, and the side face's area l1 Bs (Eq. 76)
    and the pressure force on it turned negative, silently. ``key_value``: the raw value, or MISSING when zeta0
    is the groove truncation of Eqs. 6-8."""
    bound = _mouth_bound(s)
    if bound is None or zeta0 > bound[0]:
        return []
    need, beta_o = bound
    given = "" if key_value is not MISSING else f"not given, and the groove truncation z of Eqs. 6-8 is {_mm(zeta0)}: "
    return [Problem("seal.zeta0", key_value,
                    f"{given}the groove's mouth would lie on the seal's tip arc, where the contact model has no flat "
                    f"side (Eqs. 20, 44-47: its corner is l1 = ds0 + zeta0 - ds1 = {_mm(zeta0 - need)} from the arc's "
                    f"end c1); allowed: zeta0 > ro (1 - cos beta_o) = {_mm(need)} for seal.ro = {_mm(s.ro)}, "
                    f"seal.Ws = {_mm(s.Ws)} (beta_o = {math.degrees(beta_o):.4g} deg; or a larger seal.ro)")]


def zeta0_of(m: MachineSection, s: SealSection) -> tuple[float | None, str | None]:
    """``seal.zeta0`` if given, else the groove truncation z of Eqs. 6-8; or (None, why not)."""
    if s.zeta0 is not None:
        return s.zeta0, None
    try:
        z = machine_numbers(m.embodiment, r=m.r, L=m.L, Wg=s.Wg, Cr=m.Cr, k=m.k).truncation
    except (ValueError, ZeroDivisionError):
        return None, "the groove truncation z of Eqs. 6-8 is undefined for this geometry"
    if not z > 0:
        return None, f"the groove truncation z of Eqs. 6-8 for this geometry is {_mm(z)} (<= 0)"
    if z >= s.ds1 + s.ds2:
        return (
            None,
            f"the groove truncation z of Eqs. 6-8 is {_mm(z)}, not below ds1 + ds2 = {_mm(s.ds1 + s.ds2)}",
        )
    return z, None


def check_zeta0(m: MachineSection, s: SealSection) -> list[Problem]:
    """A zeta0 the scene leaves out: the groove truncation of Eqs. 6-8 must exist, keep the seal in its groove and
    put the groove's mouth below the tip arc (:func:`mouth_on_flank`)."""
    z, why = zeta0_of(m, s)
    if why is None:
        return mouth_on_flank(s, z, MISSING)
    return [
        Problem(
            "seal.zeta0",
            MISSING,
            f"not given, and {why}; give seal.zeta0 explicitly; allowed: {zeta0_range(s)}",
        )
    ]


def check_pressure(p: PressureSection, raw: dict[str, Any]) -> list[Problem]:
    """What each source needs, and no keys that the chosen source would ignore."""
    needs = PRESSURE_SOURCES
    out = []
    for key in ("Pa", "Pb", "file"):
        given = getattr(p, key) is not None
        if key in needs[p.source] and not given:
            what = "a file name" if key == "file" else 'a pressure in Pa (e.g. "6 bar")'
            out.append(
                Problem(f"pressure.{key}", MISSING, f'required with source = "{p.source}"; give {what}')
            )
        elif given and key not in needs[p.source]:
            users = " or ".join(f'"{s}"' for s, n in needs.items() if key in n)
            out.append(
                Problem(
                    f"pressure.{key}",
                    raw_at(raw, ["pressure", key]),
                    f'not used with source = "{p.source}"; only with source = {users} '
                    "(remove it, or change the source)",
                )
            )
    if p.source != "table" and raw_at(raw, ["pressure", "unit"]) is not MISSING:
        out.append(
            Problem(
                "pressure.unit",
                raw_at(raw, ["pressure", "unit"]),
                f'not used with source = "{p.source}"; only with source = "table"',
            )
        )
    return out


def resolve_effects(
    given: Section, pressure_source: str | None, raw: dict[str, Any]
) -> tuple[Effects | None, list[Problem]]:
    """Effects from the [effects] keys that are set (Effects.from_mapping fills in the rest).

    A child that is switched on under a parent that is off is an error; with
    ``[pressure] source = "none"`` the chamber_pressure effect is off (an
    explicit ``chamber_pressure = true`` is then an error).
    """
    values = {k: v for k, v in given.model_dump().items() if v is not None}
    out = [Problem(f"effects.{name}", True, f"needs effects.{parent} = true {without_parent(name, parent)}; allowed: "
                   f"false, or set effects.{parent} = true") for name, parent in orphans(values)]
    if values.get("housing_contact") is False and values.get("groove_contact") is False:
        out.append(
            Problem(
                "effects.groove_contact",
                False,
                "with effects.housing_contact = false too, nothing holds the seal (it would leave its groove with "
                "no contact force to say where); allowed: true, or set effects.housing_contact = true",
            )
        )
    if pressure_source == "none":
        if values.get("chamber_pressure") is True:
            out.append(
                Problem(
                    "effects.chamber_pressure",
                    True,
                    'pressure.source = "none" gives no chamber pressure; allowed: false, or choose '
                    'pressure.source = "constant" or "table"',
                )
            )
        values["chamber_pressure"] = False
    if out:
        return None, out
    return Effects.from_mapping(values), []


def resolve_assumptions(given: Section, pressure_source: str | None = None) -> Assumptions:
    """The assumptions of [assumptions]; ``pressure_model`` follows ``pressure.source`` (the chamber gas model)."""
    values = given.model_dump()
    if pressure_source is not None and "pressure_model" in values:
        values["pressure_model"] = pressure_source if pressure_source in GAS_SOURCES else "input"
    return Assumptions.from_mapping(values)


def check_alternatives(raw: dict[str, Any]) -> list[Problem]:
    """A scene states a damping coefficient or its damping ratio, never both (the submodels' ``alternatives``; the
    pairs one of which supersedes the other, the seal's mass and its density, are :func:`check_superseded`'s)."""
    from apexseal.derive.submodels.registry import alternatives, submodels, superseding

    damping = {pair for cls in submodels() for pair in cls.damping_alternatives()}
    meaning = {p.key: p.meaning.split(";")[0] for cls in submodels() for p in cls.parameters if p.key}
    out = []
    pairs = [pair for pair in alternatives() if pair not in superseding()]
    for first, second, a, b in _given_together(raw, pairs):
        same = "the same damping as a ratio of critical damping" if (first, second) in damping else \
            f"the {meaning[first]} another way"
        out.append(Problem(first, a, f"given together with {second} = {b!r}, which states {same}; allowed: one "
                                     f"of {first} or {second}"))
    return out


def _given_together(raw: dict[str, Any], pairs) -> list[tuple[str, str, Any, Any]]:
    """(first key, second key, their values) of the ``pairs`` of scene keys of which ``raw`` gives both."""
    out = []
    for first, second in pairs:
        a, b = raw_at(raw, first.split(".")), raw_at(raw, second.split("."))
        if a is not MISSING and b is not MISSING:
            out.append((first, second, a, b))
    return out


def check_superseded(raw: dict[str, Any]) -> list[Problem]:
    """The keys a scene gives beside the key that supersedes them (``seal.density`` beside ``seal.ms``): not read,
    for the scene's warning."""
    from apexseal.derive.submodels.registry import superseding

    return [Problem(second, b, f"not read: {first} = {show_value(a)} is given, and {second} only computes it; give "
                               f"one of {first} or {second}") for first, second, a, b in _given_together(raw, superseding())]


def check_set_by(raw: dict[str, Any], assumptions: Assumptions) -> list[Problem]:
    """The modelling choices a scene writes in [assumptions] that another key decides (``Option.set_by``:
    ``pressure_model`` follows ``pressure.source``), where the scene's value is not the one that key makes: not
    read, for the scene's warning."""
    from apexseal.derive.submodels.registry import slots

    out, chosen = [], assumptions.as_dict()
    for slot, option in slots("assumptions").items():
        given = raw_at(raw, ["assumptions", slot])
        made = chosen.get(slot)
        if option.set_by and given is not MISSING and given != made:
            by = raw_at(raw, option.set_by.split("."))
            out.append(Problem(f"assumptions.{slot}", given, f"not read: {option.set_by} = {show_value(by)} makes "
                                                             f"it {made!r}; change {option.set_by} instead"))
    return out


def check_consistency(sections: dict[str, Section], raw: dict[str, Any]) -> list[Problem]:
    """Every cross-key check whose sections are valid."""
    from .schedule import schedule_problems

    out: list[Problem] = check_alternatives(raw) + schedule_problems(sections, raw)
    m, s = sections.get("machine"), sections.get("seal")
    if m is not None:
        out += check_machine(m, raw)
    if s is not None:
        out += check_seal(s, raw)
    if s is not None and s.zeta0 is not None:
        out += mouth_on_flank(s, s.zeta0, raw_at(raw, ["seal", "zeta0"]))
    if s is not None:
        out += check_mass(s, raw)
    if m is not None and "operation" in sections and "friction" in sections:
        out += check_friction_width(m, sections["operation"], sections["friction"], raw)
    if m is not None and s is not None:
        out += check_seal_in_rotor(m, s, raw)
        if s.zeta0 is None:
            out += check_zeta0(m, s)
    if "pressure" in sections:
        out += check_pressure(sections["pressure"], raw)
        if m is not None:
            out += check_chamber_volumes(m, sections["pressure"], raw)
    return out


def check_needed(sections: dict[str, Section], effects: Effects, assumptions: Assumptions | None = None
                 ) -> list[Problem]:
    """The parameters that an effect switched on reads and the scene leaves out (a parameter without a default
    is required only while the effect that reads it is on: ``registry.needing``; ``assumptions``: the modelling
    choices, None: the defaults)."""
    from apexseal.derive.options import needed_effects
    from apexseal.derive.submodels.registry import is_read, omissible_while_off, parameters

    from .schedule import value_at_start

    out = []
    for p in parameters(all_inputs=True):
        need = omissible_while_off(p)
        model = sections.get(p.section) if need is not None else None
        if model is None or getattr(model, p.leaf) is not None or not is_read(p, effects, assumptions):
            continue
        if value_at_start(sections, p) is not None:  # given as a schedule
            continue
        spec = validator_of(type(model), p.leaf)
        names = needed_effects(need)
        scheduled = f", or a schedule ([{p.section}.schedule] {p.leaf})" if p.schedulable else ""
        out.append(Problem(p.key, MISSING, f"required while {' or '.join(f'effects.{n}' for n in names)} is on; "
                                           f"give {spec.expects()}{scheduled}, or set "
                                           f"{' and '.join(f'effects.{n} = false' for n in names)}"))
    return out


def unread_keys(effects: Effects, assumptions: Assumptions | None = None) -> frozenset[str]:
    """The scene keys of the parameters that no law of a model with ``effects`` and the modelling choices
    ``assumptions`` (None: the defaults) reads (their effect off or their choice not made, registry.is_read), and
    the scene inputs of the submodels out of that model (``Submodel.scene_inputs``: the constant chamber pressures,
    the gas model's ports): neither required (:func:`check_needed`), range-checked
    as an error (:func:`ignored_values`) nor questioned (:func:`check_plausible`). Remembered for each model and
    registry: a scene's build asks several times, and a sweep builds a scene per point."""
    from apexseal.derive.submodels.registry import submodels

    return _unread_keys(effects, assumptions, submodels())


@functools.lru_cache(maxsize=64)
def _unread_keys(effects: Effects, assumptions: Assumptions | None, classes: tuple) -> frozenset[str]:
    """:func:`unread_keys` for the registered submodels ``classes`` (the key: the classes themselves, kept alive by
    the cache, as :func:`.schema._sections`'s)."""
    from apexseal.derive.submodels.registry import is_read, need_holds, parameters, scene_inputs

    inputs = {key for table, need in scene_inputs().items() if not need_holds(need, effects, assumptions)
              for key in key_paths(table) if _within(key, table)}
    return frozenset(p.key for p in parameters(all_inputs=True)
                     if p.key is not None and not is_read(p, effects, assumptions)) | inputs


def _within(key: str, table: str) -> bool:
    """Scene key ``key`` is ``table`` or one of its keys (``machine.ports.inlet.width`` of ``machine.ports``)."""
    return key == table or key.startswith(f"{table}.")


def key_needing(key: str, effects: Effects | None = None, assumptions: Assumptions | None = None
                ) -> str | tuple[str, ...] | None:
    """What must hold for a law to read the value of scene key ``key``: the effects or choices of its parameter
    (registry.needing; with ``effects`` and ``assumptions``, what of it does not hold there), or that of the
    submodel whose scene input it is (registry.scene_inputs); None for a key read whatever the effects, or one that
    holds no parameter or input (a switch, a solver setting). The keys :func:`unread_keys` gives are those whose
    need does not hold."""
    from apexseal.derive.submodels.registry import needing, parameter_of_key, scene_inputs

    for table, need in scene_inputs().items():
        if _within(key, table):
            return need
    try:
        return needing(parameter_of_key(key), effects, assumptions)
    except KeyError:  # no parameter's key
        return None


def ignored_values(ignored: list[Problem], effects: Effects | None = None, assumptions: Assumptions | None = None) -> str:
    """The one warning of the out-of-range values a scene gives that no law of its model reads (``ignored``: their
    range problems, of keys of :func:`unread_keys`): each key with its value, the effects that are off, and the
    range that holds while they are on."""
    from apexseal.derive.options import needed_effects
    from apexseal.derive.submodels.registry import unmet

    shown, needs = [], []
    for p in ignored:
        need = key_needing(p.key, effects, assumptions)
        needs.extend(needed_effects(need))
        shown.append(f"{p.key} = {show_value(p.value)} (not read while {unmet(need)}; allowed: "
                     f"{p.message.partition('allowed: ')[2]})")
    remedy = {"on": "switching the effect on", "choice": "making the choice",
              "both": "switching the effect on or making the choice"}[_remedy(needs)]
    return f"ignored, out of range but read by no law of the scene's model: {', '.join(shown)}; {remedy} makes it an error"


def _remedy(needs) -> str:
    """What reads a key that no law reads: ``"on"`` (an effect switched on), ``"choice"`` (a modelling choice made:
    the entries of ``needs`` written ``slot=choice``) or ``"both"``."""
    choices = [n for n in needs if "=" in n]
    return "both" if choices and len(choices) < len(needs) else "choice" if choices else "on"


def check_unread_tables(raw: dict[str, Any], sections: dict[str, Section], effects: Effects,
                        assumptions: Assumptions | None, reported: set[str]) -> list[str]:
    """The tables of a user's or a package's submodel a scene gives of which no law of its model reads any key (a
    whole ``[damper]`` while ``effects.damper`` is off), for the scene's warning: one per table, naming it, its
    keys and what is off; and such a submodel's keys given in a table other laws read (``contacts.kwp`` in
    ``[contacts]``), one warning per key with its value. Keys at their defaults say nothing, nor values
    ``reported`` already (out of range: :func:`ignored_values`), nor a built-in submodel's keys (the default scene
    gives them all, so switching an effect off by an override would warn of values the user never wrote)."""
    from apexseal.derive.submodels.base import built_in
    from apexseal.derive.submodels.registry import parameter_of_key, submodels, unmet

    unread = unread_keys(effects, assumptions)
    builtin_keys = {p.key for cls in submodels() if built_in(cls) for p in cls.parameters}
    out = []
    for table, given in raw.items():
        keys = [f"{table}.{k}" for k, v in given.items() if not isinstance(v, dict)] if isinstance(given, dict) \
            else []
        own = [k for k in keys if k in unread and k not in reported and k not in builtin_keys]
        if not own or table not in sections:
            continue
        try:
            declared = {k: parameter_of_key(k) for k in own}
        except KeyError:  # a key of no parameter (an input of a submodel's own: machine.ports)
            continue
        changed = [k for k, p in declared.items()
                   if p.default is None or getattr(sections[table], p.leaf, None) != p.default]
        if not changed:
            continue
        if len(own) == len(keys):
            off = " and ".join(dict.fromkeys(unmet(key_needing(k, effects, assumptions)) for k in keys))
            out.append(f"[{table}] is not read: no law reads {', '.join(keys)} while {off} "
                       f"({_to_use(keys, 'them', effects, assumptions)}, or leave the table out)")
            continue
        for k in changed:  # a user's or a package's key in a table other laws read ([contacts])
            out.append(f"{k} = {show_value(given[declared[k].leaf])} is not read: no law reads it while "
                       f"{unmet(key_needing(k, effects, assumptions))} ({_to_use([k], 'it', effects, assumptions)}, "
                       "or leave the key out)")
    return out


def _to_use(keys, pronoun: str, effects: Effects, assumptions: Assumptions | None) -> str:
    """The advice of :func:`check_unread_tables` for ``keys`` no law reads: switch their effect on, make their
    modelling choice, or either."""
    from apexseal.derive.options import needed_effects

    remedy = _remedy([n for k in keys for n in needed_effects(key_needing(k, effects, assumptions))])
    return {"on": f"switch it on to use {pronoun}", "choice": f"make that choice to use {pronoun}",
            "both": f"switch the effect on or make the choice to use {pronoun}"}[remedy]


def check_plausible(sections: dict[str, Section], raw: dict[str, Any], pressure: Any,
                    effects: Effects | None = None, assumptions: Assumptions | None = None) -> list[Problem]:
    """Values far outside engineering practice (:func:`.units.plausible_ranges`), each against the key the user
    wrote, and a pressure table whose absolute pressures leave :data:`.units.TABLE_PRESSURES`. With ``effects``
    (and ``assumptions``), a value no law of the model reads (its effect off: :func:`unread_keys`) is not
    questioned."""
    unread = unread_keys(effects, assumptions) if effects is not None else frozenset()
    values = {}
    for key in plausible_ranges():
        section, name = key.split(".")
        written = raw_at(raw, [section, name])
        if section in sections and written is not MISSING and key not in unread:
            values[key] = getattr(sections[section], name, None), written
    out = [Problem(key, raw_at(raw, key.split(".")), message) for key, _, message in implausible(values)]
    machine, source = sections.get("machine"), getattr(sections.get("pressure"), "source", None)
    if source in GAS_SOURCES and machine is not None and machine.ports is None:
        out.append(Problem("machine.ports", MISSING, f"pressure.source = \"{source}\" with no ports: both chambers "
                           "are sealed (no inlet, no outlet), their gas only compressed and expanded; give "
                           "[machine.ports.inlet] and [machine.ports.outlet] for a machine's cycle (docs/scenes.md)"))
    if source in GAS_SOURCES and machine is not None and machine.ports is not None:
        out += _ports_overlap(machine, raw)
    table = isinstance(pressure, TablePressure)
    why = table_pressures_implausible(pressure.pa, pressure.pb, pressure.unit) if table else None
    if why:
        out.append(Problem("pressure.unit", raw_at(raw, ["pressure", "unit"]) if "unit" in raw.get("pressure", {})
                           else "Pa", why))
    if table and (why := pressure.angles_in_radians()):
        out.append(Problem("pressure.file", raw_at(raw, ["pressure", "file"]), why))
    return out


def _ports_overlap(m: MachineSection, raw: dict[str, Any]) -> list[Problem]:
    """The inlet and the outlet overlapping on the housing (Table 1's ports, derive/ports.py): a chamber over both
    joins the supply to the exhaust, which no machine does."""
    inlet, outlet = m.ports.inlet, m.ports.outlet
    apart = abs((inlet.angle - outlet.angle + math.pi) % (2 * math.pi) - math.pi)
    overlap = (inlet.width + outlet.width) / 2 - apart
    if overlap <= 0:
        return []

    def arc(p) -> str:
        return f"{p.angle_deg:.4g} +- {p.width_deg / 2:.4g} deg"

    return [Problem("machine.ports.outlet.angle", raw_at(raw, ["machine", "ports", "outlet", "angle"]),
                    f"the outlet ({arc(outlet)}) overlaps the inlet ({arc(inlet)}) by {math.degrees(overlap):.4g} deg: "
                    "a chamber over both joins the supply to the exhaust (Table 1's ports are apart)")]


def check_damping(values: dict[str, float], raw: dict[str, Any]) -> list[Problem]:
    """Each contact damped above critical (:data:`.damping.MAX_DAMPING_RATIO`), where its approach-only damping
    makes it chatter (:mod:`.damping`), against the key the scene gives (the coefficient, else its ratio), with the
    value and the plausible range. ``values``: the scene's parameters (SI, by name; a damping that is off has none,
    so it is not questioned, nor one the damping law "penetration" makes continuous at the touch)."""
    out = []
    for d in contact_dampings(values).values():
        if not d.too_high:
            continue
        c_key, ratio_key = d.keys
        given = raw_at(raw, c_key.split("."))
        if given is not MISSING:
            out.append(Problem(c_key, given, f"{d.c:.4g} N*s/m is {d.zeta:.3g} times critical damping "
                                             f"({d.critical:.4g} N*s/m): {d.why}; plausible: 0 <= {d.coefficient} <= "
                                             f"{d.critical:.4g} N*s/m ({ratio_key} <= {MAX_DAMPING_RATIO:g})"))
        else:
            out.append(Problem(ratio_key, raw_at(raw, ratio_key.split(".")),
                               f"a damping ratio above critical damping ({MAX_DAMPING_RATIO:g}; {d.coefficient} = "
                               f"{d.c:.4g} N*s/m here): {d.why}; plausible: 0 <= {d.ratio_name} <= "
                               f"{MAX_DAMPING_RATIO:g}"))
    return out
