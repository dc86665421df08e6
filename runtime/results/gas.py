"""What the chamber gas model gives a designer: leaked mass, inducted mass, indicated work (its figures:
:mod:`.gas_figures`).

Every number is over the last whole revolution of the run (the periodic one when the run went until periodic),
by the trapezoidal rule over the output samples.

The gas model's ports are fixed openings with no valves (derive/submodels/gas.py): supply, chamber and exhaust
make an expander's cycle, gas in at the inlet and work out on the rotor. A compressor's design (a supply below the
exhaust: suction at the inlet, delivery at the outlet) runs all the same, as gas pushed back out of the inlet and
work done on the gas, numbers of no compressor (a compressor needs valves, or port timing, that this model does not
have). :func:`expander_cycle` tells the two apart, ``summary.json`` carries it in ``gas`` as ``expander_cycle``,
and :func:`apexseal.simulate` warns once with :class:`GasCycleWarning` when the cycle is not an expander's.
"""

from __future__ import annotations

import numpy as np

from ..scenes.units import PlausibilityWarning
from .result import SimulationResult


class GasCycleWarning(PlausibilityWarning):
    """A run of the chamber gas model whose cycle is not an expander's: the model has no valves, so its numbers
    are not a compressor's (a kind of the scene's :class:`~apexseal.runtime.scenes.units.PlausibilityWarning`:
    filtering that one filters this one too, and a sweep point's row records it)."""


def has_gas(result: SimulationResult) -> bool:
    return "Va" in result.outputs


def last_revolution(result: SimulationResult) -> slice:
    """The samples of the last whole revolution (all of them if the run is shorter)."""
    n = result.n
    if n < 2:
        return slice(0, n)
    per_rev = int(round(2 * np.pi / float(np.mean(np.diff(result.theta)))))
    return slice(max(0, n - 1 - per_rev), n)


def gas_summary(result: SimulationResult) -> dict:
    """Leaked mass per revolution (each path, kg and fraction of the inducted mass), inducted mass, indicated
    work per cycle of each chamber (the p-V loop integral, J; positive: the gas does work on the rotor)."""
    o, k = result.outputs, last_revolution(result)
    t = result.time[k]

    def integral(v):
        return float(np.trapezoid(v[k], t))

    inducted = integral(o["mdot_in_a"]) + integral(o["mdot_in_b"])
    groove, tip = integral(np.abs(o["mdot_leak_groove"])), integral(np.abs(o["mdot_leak_tip"]))
    leaked = groove + tip
    work = {c: float(np.trapezoid(o["P" + c][k], o["V" + c][k])) for c in "ab"}
    return {"revolution_from_deg": float(np.degrees(result.theta[k][0])),
            "inducted_mass_kg": inducted, "exhausted_mass_kg": integral(o["mdot_out_a"]) + integral(o["mdot_out_b"]),
            "leaked_mass_kg": {"groove": groove, "tip": tip, "total": leaked},
            "leaked_fraction_of_inducted": leaked / inducted if inducted > 0 else float("nan"),
            "indicated_work_J": {"a": work["a"], "b": work["b"], "total": work["a"] + work["b"]},
            "indicated_power_W": (work["a"] + work["b"]) / float(t[-1] - t[0]) if t.size > 1 else 0.0,
            "pressure_Pa": {c: {"min": float(o["P" + c][k].min()), "max": float(o["P" + c][k].max())} for c in "ab"},
            "expander_cycle": expander_cycle(inducted, work["a"] + work["b"], ported=_ported(result, k))}


def _ported(result: SimulationResult, k: slice) -> bool:
    """Whether any gas passed a port over the samples ``k`` (false with the ports closed, ``gas.Cd_port = 0``)."""
    return any(np.any(result.outputs[f"mdot_{p}_{c}"][k] != 0) for p in ("in", "out") for c in "ab")


def expander_cycle(inducted: float, work: float, *, ported: bool = True) -> dict:
    """Whether a revolution of the gas model is an expander's cycle (``ok``): gas not pushed back out through the
    inlet on balance (``negative_inducted_mass``: the inducted mass < 0) and no net work done on the gas by the rotor
    (``work_into_gas``: the indicated work of both chambers < 0). Closed ports (no port flow, ``ported`` false) are
    no cycle of either kind: their work is the leakage's loss alone, and they are not flagged."""
    negative, into = bool(inducted < 0), bool(ported and work < 0)
    return {"ok": not (negative or into), "negative_inducted_mass": negative, "work_into_gas": into}


def describe_cycle(gas: dict) -> str:
    """One line for a :class:`GasCycleWarning`: the numbers of the cycle, why it is not an expander's, the remedy."""
    check = gas["expander_cycle"]
    signs = [text for flag, text in (("negative_inducted_mass", "gas pushed back out through the inlet"),
                                     ("work_into_gas", "the rotor does work on the gas")) if check[flag]]
    return (f"the chamber gas model ran a cycle that is not an expander's: over the last revolution the inducted mass "
            f"is {gas['inducted_mass_kg'] * 1e3:.4g} g and the indicated work {gas['indicated_work_J']['total']:.4g} J "
            f"({' and '.join(signs)}). The gas model has fixed ports and no valves: it models expanders only, and "
            "these are not a compressor's numbers. For a compressor give the chamber pressures as a table "
            "(pressure.source = \"table\" with pressure.file, a CSV theta_deg,Pa,Pb such as "
            "runtime/scenes/expander-pressure.csv; docs/gas.md, \"Scope\")")
