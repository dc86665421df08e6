"""The seal's energy balance over a run's output samples: does the work of its loads, summed from the samples, account
for the change of its kinetic energy? The ``energy_balance`` block of a run's summary.

Eq. 80 is M u' = F - f_in with u = (x', y', phi'), M = diag(ms, ms, Icg), F the loads' generalised forces (each
load's groove-frame force and its moment about the centre of gravity, derive/eom.py) and f_in the inertia forces at
u' = 0 (centrifugal, Coriolis, the groove's own acceleration along the rotor chord). Multiplied by u it is exact at
every instant:

    d/dt (1/2 u' M u) = sum over loads of (F_X x' + F_Y y' + M phi') - u . f_in

The left side integrates to the change of the kinetic energy of the seal's motion in its groove, known exactly
from the first and last samples' states; the right side is known only at the samples, so its integral is a
quadrature (the trapezoidal rule here). The difference, ``residual_J``, is what the samples miss of the loads'
work: nothing where they resolve every load's power, and as much as the work itself where they fall between the
impacts' ringing (the groove's corners, whose impacts last microseconds). A load's power on the seal's motion in
its groove holds every part of its force: a contact's elastic and damping force and its friction (whose
dissipation ``Pf_<contact>`` the friction powers of the summary average; at the groove's contacts and the spring,
which slide relative to the groove, -Pf is the friction's share; at the tip, which slides on the fixed housing,
the rotor supplies most of the tip's friction power, which is why it hardly enters this balance).

Elastic energy needs no term of its own: it is a contact's force on the seal, integrated as work. The gas model's
states (a scene with the chamber gas) are not the seal's and do not enter.
"""

from __future__ import annotations

import math

import numpy as np

from .result import SimulationResult

#: a balance closes when its residual is at most this fraction of the sum of the magnitudes of its terms
CLOSES_WITHIN = 0.05
#: the scene's parameters the balance reads: the seal's mass and inertia (Eq. 80), the rotor's speed and its groove's
#: place on the chord (Eq. 12)
NEEDS = {"ms", "Icg", "omega", "r", "Li"}


def inertial_acceleration(theta, x, y, xd, yd, omega: float, r: float, Li: float) -> tuple[np.ndarray, np.ndarray]:
    """The absolute acceleration of the seal's centre of gravity at x'' = y'' = 0, in groove-frame components
    (X along the chord, Y across it; m/s^2): Eqs. 14-15 (X1'', Y1'') with the relative accelerations left out, for
    the rotor turning at a constant omega, its groove's origin at 2 r sin(theta) + Li along its chord (Eq. 12).
    ``theta`` is the crank angle (rad) of Eq. 12, from the scene's start angle on; the states are the seal's."""
    theta, x, y, xd, yd = (np.asarray(v, float) for v in (theta, x, y, xd, yd))
    w2 = omega * omega
    ax = -w2 * (Li + 4 * r * np.sin(theta) + x) - 2 * omega * yd
    ay = w2 * (4 * r * np.cos(theta) - y) + 2 * omega * xd
    return ax, ay


def load_powers(result: SimulationResult) -> dict[str, np.ndarray]:
    """Each load's power on the seal's motion in its groove (W) at every sample: F_X x' + F_Y y' + M phi' from its
    force ``F_<load>_X/_Y`` and moment ``M_<load>`` outputs (every contact, the spring, the chamber pressure)."""
    xd, yd, phid = (result.column(n) for n in ("xd", "yd", "phid"))
    loads = [k[2:-2] for k in result.outputs if k.startswith("F_") and k.endswith("_X")]
    return {c: (np.asarray(result.outputs[f"F_{c}_X"], float) * xd + np.asarray(result.outputs[f"F_{c}_Y"], float) * yd
                + np.asarray(result.outputs.get(f"M_{c}", np.zeros(result.n)), float) * phid) for c in loads}


def inertial_power(result: SimulationResult) -> np.ndarray:
    """The inertia forces' power on the seal's motion in its groove (W): -ms a0 . (x', y') with a0 of
    :func:`inertial_acceleration` (the Coriolis part does none); zero with the scene's ``inertia`` effect off (the
    groove frame then counts as inertial, derive/eom.py)."""
    sc = result.scene
    if not sc.effects.inertia:
        return np.zeros(result.n)
    p = sc.parameters
    x, y, xd, yd = (result.column(n) for n in ("x", "y", "xd", "yd"))
    ax, ay = inertial_acceleration(result.theta + sc.operation.start_angle, x, y, xd, yd, p["omega"], p["r"], p["Li"])
    return -p["ms"] * (ax * xd + ay * yd)


def kinetic_energy(result: SimulationResult) -> np.ndarray:
    """1/2 u' M u (J) at every sample: the kinetic energy of the seal's motion in its groove (Eq. 80's mass matrix)."""
    p = result.scene.parameters
    xd, yd, phid = (result.column(n) for n in ("xd", "yd", "phid"))
    return 0.5 * p["ms"] * (xd * xd + yd * yd) + 0.5 * p["Icg"] * phid * phid


def energy_balance(result: SimulationResult) -> dict | None:
    """The seal's energy balance over the samples of ``result`` (the module's docstring), per revolution; None for
    a run without a sample after its start, without its scene (the mass, inertia and rotor of :data:`NEEDS`) or
    without a load output.

    ``work_J_per_rev``: each load's work on the seal's motion in its groove, ``inertial_J_per_rev`` the inertia
    forces', ``kinetic_change_J_per_rev`` the change of the kinetic energy (exact: from the states at the ends),
    ``residual_J_per_rev`` that change minus all the work (what the samples miss), ``residual_fraction`` the
    residual over the sum of the terms' magnitudes, and ``closes``: whether it is at most ``CLOSES_WITHIN``."""
    params = getattr(result.scene, "parameters", None) or {}
    if result.n < 2 or not NEEDS <= set(params) or getattr(result.scene, "effects", None) is None:
        return None
    powers = load_powers(result)
    if not powers:
        return None
    turned = float(result.theta[-1] - result.theta[0]) / (2 * math.pi)
    if turned <= 0:
        return None
    work = {c: float(np.trapezoid(p, result.time)) / turned for c, p in powers.items()}
    inertial = float(np.trapezoid(inertial_power(result), result.time)) / turned
    energy = kinetic_energy(result)
    change = float(energy[-1] - energy[0]) / turned
    residual = change - sum(work.values()) - inertial
    scale = sum(abs(w) for w in work.values()) + abs(inertial) + abs(change)
    fraction = abs(residual) / scale if scale > 0 else 0.0
    return {"work_J_per_rev": work, "inertial_J_per_rev": inertial, "kinetic_change_J_per_rev": change,
            "residual_J_per_rev": residual, "residual_fraction": fraction, "closes": closes(fraction)}


def closes(fraction: float) -> bool:
    """Whether a balance whose residual is ``fraction`` of its terms' magnitudes closes (:data:`CLOSES_WITHIN`)."""
    return fraction <= CLOSES_WITHIN


def describe_balance(block: dict, samples_per_revolution: int | None) -> str:
    """The console's note for a balance that does not close: the residual, and what it makes unreliable."""
    at = f"{samples_per_revolution} output samples per revolution" if samples_per_revolution else "the output samples"
    return (f"the seal's energy balance over {at} misses {abs(block['residual_J_per_rev']):.3g} J per revolution "
            f"({block['residual_fraction']:.0%} of its terms): a contact's friction power and sliding work of that "
            "size or less are not resolved by the samples; a larger --set solver.samples_per_revolution=N makes it "
            "smaller")
