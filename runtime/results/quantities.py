"""A run's named scalars, with units, read from its summary: what a sweep collects and ``apexseal compare`` sets
side by side.

Every quantity comes from the summary a single run writes (``summary.json`` of ``apexseal simulate``), so a sweep
point, a comparison and a single run report the same numbers. A run that went until periodic
(``operation.until_periodic``) over two revolutions or more reports its last revolution (:func:`measured_part`):
the periodic regime it was asked for, not the start-up from rest. A quantity a model does not have (friction at a
contact whose effect is off, the housing force without the housing contact, the leakage gap without the groove's
contacts) is NaN.
"""

from __future__ import annotations

import math

from .energy import CLOSES_WITHIN
from .liftoff import fraction
from .plausibility import penetrations
from .summary import EXTREMES, summarise
from .wear import sliding_contacts


def friction_contacts() -> tuple[str, ...]:
    """"total", then every contact a guard opens and closes (where friction can act; the model names its power
    Pf_<contact>), as the registered submodels declare them."""
    from ...derive.submodels.registry import guard_contacts

    return ("total", *dict.fromkeys(guard_contacts().values()))


def guard_names() -> tuple[str, ...]:
    """"total", then every guard the registered submodels declare (their switches are counted by guard)."""
    from ...derive.submodels.registry import guards

    return ("total", *(g.name for g in guards()))


def quantity_help() -> dict[str, tuple[str, str]]:
    """Every quantity's name -> (unit, meaning), units as pint spells them ("1": a plain number or a count), for
    the registered submodels."""
    return {
        **{f"friction_power.{c}": ("W", f"mean friction power, {c} contact" if c != "total" else
                                   "mean friction power, all contacts") for c in friction_contacts()},
        "liftoff_fraction": ("1", "fraction of the samples with the seal tip off the housing (modes *_h0_*)"),
        "housing_force.mean": ("N", "mean seal-housing contact force |Fs5| (Eq. 68)"),
        "housing_force.max": ("N", "largest seal-housing contact force at the output samples (an impact between two "
                                   "samples is not seen: it grows with solver.samples_per_revolution)"),
        "housing_force.max_at": ("deg", "crank angle of the largest housing force, within its revolution"),
        **{f"{s}.{e}": (u, f"{e}imum of {s} at the output samples") for s, (u, _) in EXTREMES.items()
           for e in ("min", "max")},
        **{f"{s}.{e}_at": ("deg", f"crank angle of the {e}imum of {s}, within its revolution") for s in EXTREMES
           for e in ("min", "max")},
        "gap.open_fraction": ("1", "fraction of the samples with a seal-groove leakage gap (Algorithm 4)"),
        "gap.mean": ("um", "mean seal-groove leakage gap b_gap"),
        "gap.max": ("um", "largest seal-groove leakage gap b_gap at the output samples"),
        **{f"events.{g}": ("1", f"contact switches of guard {g}" if g != "total" else "contact switches, all guards")
           for g in guard_names()},
        **{f"penetration.{c}": ("um", f"deepest penetration of the {c} contact into its wall at the output samples "
                                      "(force / stiffness; the plausibility check; an impact between two samples is "
                                      "not seen: it grows with solver.samples_per_revolution)")
           for c in penetrations()},
        "flank.least": ("mm", "least of the groove mouth corners' lengths l1..l4 over the run (negative: a corner "
                              "left the seal's flat sides, outside the contact model of Eqs. 20-23)"),
        **{f"wear.{c}.{name}": (unit, f"{meaning}, {'seal tip on the housing' if c == 'housing' else c + ' contact'}")
           for c in sliding_contacts() for name, (unit, meaning, _) in WEAR_QUANTITIES.items()},
        "wear.seal_mass": ("g", "seal mass ms as the scene gives it (Eq. 80)"),
        **{f"energy.{name}": (unit, meaning) for name, (unit, meaning, _) in ENERGY_QUANTITIES.items()},
        "revolutions": ("rev", "revolutions computed (less than asked when a point stopped early)"),
        **{f"gas.{name}": (unit, f"{meaning}, last revolution (the chamber gas model; NaN without it)")
           for name, (unit, meaning, _) in GAS_QUANTITIES.items()},
    }


#: the chamber gas model's quantities: name -> (unit, meaning, its summary value in that unit)
GAS_QUANTITIES = {
    "inducted": ("g", "mass inducted through the inlet", lambda g: g["inducted_mass_kg"] * 1e3),
    "leaked": ("mg", "mass leaked past the seal (groove and tip)", lambda g: g["leaked_mass_kg"]["total"] * 1e6),
    "leaked_fraction": ("1", "leaked over inducted mass", lambda g: g["leaked_fraction_of_inducted"]),
    "work": ("J", "indicated work of both chambers (their p-V loops)", lambda g: g["indicated_work_J"]["total"]),
    "power": ("W", "indicated power", lambda g: g["indicated_power_W"]),
    "pressure.max": ("Pa", "highest chamber pressure", lambda g: max(g["pressure_Pa"][c]["max"] for c in "ab")),
}


#: the seal's energy balance over the samples (``energy_balance`` of summary.json, runtime/results/energy.py):
#: name -> (unit, meaning, its key)
ENERGY_QUANTITIES = {
    "residual": ("J", "the seal's energy balance over the output samples: the change of its kinetic energy minus the "
                      "work of its loads and inertia forces, per revolution (what the samples miss of the loads' work; "
                      "it shrinks with solver.samples_per_revolution)", "residual_J_per_rev"),
    "residual_fraction": ("1", "abs(energy.residual) over the sum of the balance's terms' magnitudes (the balance "
                               f"closes at {CLOSES_WITHIN} or less)", "residual_fraction"),
}


#: a contact's wear quantities (``wear`` of summary.json, runtime/results/wear.py): name -> (unit, meaning, its key)
WEAR_QUANTITIES = {
    "speed_mean": ("m/s", "mean sliding speed |v| while the contact is closed", "speed_mean_m_s"),
    "speed_max": ("m/s", "largest sliding speed |v| at the output samples while the contact is closed",
                  "speed_max_m_s"),
    "work": ("J", "Archard's sliding work per revolution, the integral of N |v| dt", "sliding_work_J_per_rev"),
    "power": ("W", "mean of N |v|, the rate of Archard's sliding work", "sliding_power_W"),
    "pv_max": ("W/m", "largest N / Bs |v| (load per seal length x speed) while the contact is closed",
               "pv_max_W_per_m"),
}


def quantity_unit(name: str) -> str | None:
    """The unit of a quantity, or None if there is no such quantity."""
    entry = quantity_help().get(name)
    return entry[0] if entry else None


def _number(value) -> float:
    """A summary's number, NaN for its null (a quantity of a contact the model does not have)."""
    return math.nan if value is None else float(value)


def measured_part(summary: dict) -> dict:
    """The part of a summary the quantities (except ``revolutions`` and ``gas.*``, the run's count and its gas cycle,
    already the last revolution's) are read from: its ``last_revolution`` for a run that went until periodic
    (``operation.until_periodic``: summary.json's ``run.periodic`` is recorded) over two revolutions or more, else
    the whole run. Asking until_periodic asks for the periodic regime, which the start-up from rest is not."""
    last = summary.get("last_revolution")
    return last if last is not None and (summary.get("run") or {}).get("periodic") is not None else summary


def _get(summary: dict, name: str) -> float:
    head, _, tail = name.partition(".")
    if name == "revolutions":
        return float(summary["revolutions"])
    if head == "gas":
        gas = summary.get("gas")
        return math.nan if gas is None else _number(GAS_QUANTITIES[tail][2](gas))
    summary = measured_part(summary)
    if name == "liftoff_fraction":
        return fraction(summary["liftoff"])  # NaN: no housing contact in this model
    if head == "friction_power":
        value = summary["mean_friction_power_W"].get(tail, math.nan)
        return math.nan if value is None else float(value)  # None: no output interval computed
    if head == "events":
        return float(summary["events_total"] if tail == "total" else summary["events"].get(tail, math.nan))
    if head == "housing_force":
        return _number(summary["housing_force_N"]["max_at_deg" if tail == "max_at" else tail])
    if head == "gap":
        return _number(summary["leakage_gap"]["open_fraction" if tail == "open_fraction" else f"{tail}_um"])
    if head == "penetration":
        return float((summary.get("plausibility") or {}).get("penetration_um", {}).get(tail, math.nan))
    if head == "flank":
        flank = summary.get("flank")
        return math.nan if flank is None else float(min(flank["least_mm"].values()))
    if head == "wear":
        block = summary.get("wear")
        if block is None:
            return math.nan
        if tail == "seal_mass":
            return _number(block["seal_mass_kg"]) * 1e3
        contact, _, what = tail.partition(".")
        entry = block["contacts"].get(contact)
        return math.nan if entry is None else _number(entry[WEAR_QUANTITIES[what][2]])
    if head == "energy":
        block = summary.get("energy_balance")
        return math.nan if block is None else _number(block[ENERGY_QUANTITIES[tail][2]])
    if head in EXTREMES:
        return float(summary["extremes"][head][tail.replace("_at", "_at_deg")])
    raise KeyError(name)  # pragma: no cover - names are checked when the study is loaded


def collect(result, names: tuple[str, ...]) -> dict[str, float]:
    """The named quantities of a run (NaN for all when the run has no samples to summarise)."""
    if result.n < 2:
        return dict.fromkeys(names, math.nan)
    summary = summarise(result)
    return {n: _get(summary, n) for n in names}
