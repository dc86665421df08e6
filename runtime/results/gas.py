"""What the chamber gas model gives a designer: leaked mass, inducted mass, indicated work (its figures:
:mod:`.gas_figures`).

Every number is over the last whole revolution of the run (the periodic one when the run went until periodic),
by the trapezoidal rule over the output samples.
"""

from __future__ import annotations

import numpy as np

from .result import SimulationResult


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
            "pressure_Pa": {c: {"min": float(o["P" + c][k].min()), "max": float(o["P" + c][k].max())} for c in "ab"}}
