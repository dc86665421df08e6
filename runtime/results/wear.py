"""Where and how fast the seal slides on its walls, and Archard's wear measure there: the ``wear`` block of a run's
summary.

Every contact a guard opens and closes (the tip on the housing, the groove's i1, c2, i2, c4, the spring) has the
model's output ``v_<contact>``: the seal's sliding velocity along the wall there, the velocity its friction law
takes (derive/submodels: the tip's absolute velocity on the housing tangent, Eqs. 64-66; the groove's contacts
relative to the groove, Eqs. 50-61; the back face across the spring, Eqs. 70-72). Its force ``F_<contact>`` is
N n + f t, the normal force N along the wall's normal n and the Coulomb friction f = -mu N tanh(v / v_eps) along
the tangent t (Algorithms 1 and 2, Eq. 73; derive/submodels/laws.py ``coulomb``), whose power is
Pf = -f v >= 0. So |F|^2 = N^2 + f^2 and the normal force times the sliding speed is
N |v| = sqrt((|F| v)^2 - Pf^2) (:func:`sliding_rate`), from the saved outputs, for any mu (Pf = 0 without
friction: N = |F|).

Archard's law makes the worn volume proportional to the sliding work, the integral of N |v| dt: per revolution
(``sliding_work_J_per_rev``, J) and its mean rate (``sliding_power_W``, W; friction dissipates mu times it while
the contact slides faster than v_eps). The seal's axial length Bs (``seal.Bs``, Eq. 76) is a scene parameter, so
the load per length N / Bs times the speed is given too (``pv_*_W_per_m``, W/m = N/m x m/s). The model has no
contact width (its contacts are lines: the tip arc of radius ro on the housing, the seal's corners on the groove
walls), so no contact pressure and no PV in Pa m/s: that would need a Hertz width the model does not compute.
"""

from __future__ import annotations

import math

import numpy as np

from .result import SimulationResult, run_mean
from .spectra import contact_force


def sliding_contacts() -> dict[str, str]:
    """contact -> the guard that opens and closes it, for every contact a guard opens and closes (where the seal
    slides on a wall), as the registered submodels declare them."""
    from ...derive.submodels.registry import guard_contacts

    return {contact: name for name, contact in guard_contacts().items()}


def sliding_rate(force: np.ndarray, velocity: np.ndarray, power: np.ndarray | None) -> np.ndarray:
    """N |v| (W): the normal force times the sliding speed of a Coulomb contact from the magnitude ``force`` of its
    force (N), its sliding ``velocity`` (m/s) and its friction ``power`` (W, None without friction): sqrt((|F| v)^2 -
    Pf^2), since |F|^2 = N^2 + f^2 and Pf = |f| |v| (the module's docstring). The difference is clipped at zero
    against round-off."""
    fv = np.asarray(force, float) * np.abs(np.asarray(velocity, float))
    pf = np.zeros_like(fv) if power is None else np.asarray(power, float)
    return np.sqrt(np.maximum(fv * fv - pf * pf, 0.0))


def seconds_per_revolution(result: SimulationResult) -> float:
    """The time of one revolution of the run's crank (s), from its samples; NaN without two of them."""
    if result.n < 2:
        return math.nan
    turned = float(result.theta[-1] - result.theta[0]) / (2 * math.pi)
    return float(result.time[-1] - result.time[0]) / turned if turned > 0 else math.nan


def contact_wear(result: SimulationResult, contact: str, guard_index: int, length: float | None) -> dict:
    """The ``wear`` numbers of one contact (see :func:`wear`) over the samples after the first (each the end of an
    output interval, as :func:`.result.run_mean` averages)."""
    o = result.outputs
    rate = sliding_rate(contact_force(o, contact), o[f"v_{contact}"], o.get(f"Pf_{contact}"))
    touching = np.asarray(result.closed[guard_index], bool)[1:]
    speed = np.abs(np.asarray(o[f"v_{contact}"], float))[1:][touching]
    power = run_mean(rate)
    load = rate[1:][touching] / length if length else None

    def _mean(v):
        return float(v.mean()) if v is not None and v.size else None

    def _max(v):
        return float(v.max()) if v is not None and v.size else None

    return {"contact_fraction": float(touching.mean()) if touching.size else None,
            "speed_mean_m_s": _mean(speed), "speed_max_m_s": _max(speed),
            "sliding_power_W": None if math.isnan(power) else power,
            "sliding_work_J_per_rev": None if math.isnan(power) else power * seconds_per_revolution(result),
            "pv_mean_W_per_m": _mean(load), "pv_max_W_per_m": _max(load)}


def wear(result: SimulationResult) -> dict | None:
    """Sliding and Archard's wear measure at each contact of the run, and the seal's mass and length as the scene
    gives them; None for a run without a sample after its start, or a model without sliding outputs (a result of a
    model generated before them).

    ``seal_mass_kg`` (ms, Eq. 80) and ``seal_length_m`` (Bs, Eq. 76) are the scene's (null for a result without
    its scene). ``contacts`` holds, by contact (``housing``: the tip on the housing), ``contact_fraction`` (of the
    samples with the contact closed), the sliding speed |v| while closed (``speed_mean_m_s``, ``speed_max_m_s``:
    null when it never closes), the mean of N |v| over the samples (``sliding_power_W``), its integral over a
    revolution (``sliding_work_J_per_rev``: Archard's sliding work, the mean times the seconds of a revolution)
    and, with the seal's length, N |v| / Bs while closed (``pv_mean_W_per_m``, ``pv_max_W_per_m``)."""
    if result.n < 2:
        return None
    params = result.scene.parameters if result.scene is not None else {}
    length = params.get("Bs")
    contacts = {c: contact_wear(result, c, result.guard_names.index(g), length)
                for c, g in sliding_contacts().items()
                if f"v_{c}" in result.outputs and f"F_{c}_X" in result.outputs and g in result.guard_names}
    if not contacts:
        return None
    return {"seal_mass_kg": params.get("ms"), "seal_length_m": length, "contacts": contacts}


def describe_wear(block: dict) -> str:
    """The console's line: the tip's sliding speed and sliding work, the other contact with the most sliding work
    (a groove contact or the spring), the seal's mass."""
    parts = []
    tip = block["contacts"].get("housing")
    touches = tip is not None and tip["speed_mean_m_s"] is not None
    if touches:
        parts.append(f"tip slides at {tip['speed_mean_m_s']:.3g} m/s (max {tip['speed_max_m_s']:.3g}), "
                     f"N·v {tip['sliding_work_J_per_rev']:.4g} J/rev")
    elif tip is not None:
        parts.append("the tip never touches the housing")
    others = {c: w for c, w in block["contacts"].items() if c != "housing" and w["sliding_work_J_per_rev"]}
    if others:
        c = max(others, key=lambda k: others[k]["sliding_work_J_per_rev"])
        parts.append(f"{'next most' if touches else 'most'} at {c} {others[c]['sliding_work_J_per_rev']:.3g} J/rev")
    if block["seal_mass_kg"] is not None:
        parts.append(f"seal {block['seal_mass_kg'] * 1e3:.3g} g")
    return "wear (Archard's N·v): " + ("; ".join(parts) if parts else "no sliding contact closed")
