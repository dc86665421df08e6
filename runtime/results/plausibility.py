"""Is a run physically plausible? Each contact's deepest penetration against the seal's side clearance.

A penalty contact (Eqs. 34, 39, Algorithm 1) lets the seal sink into a wall by force / stiffness. With metal
stiffnesses that is a fraction of a micrometre; a penetration that is a large part of the clearance means the
stiffness is not a metal's (or the load is not a machine's), and the kinematics of the contacts (which corner
touches which wall, Algorithm 3) are then no longer those of the real seal.

The check compares the deepest penetration of every contact that a guard opens and closes (as the submodels
declare them: the housing contact's ``xs5``, Eq. 33, minus the seal-groove gaps ``b1..b4`` of Eqs. 40-43, and a
user's contact's guard output), the deepest at the output samples (not between them: a denser
``solver.samples_per_revolution`` can find deeper impacts of a few microseconds), with ``PENETRATION_FRACTION``
of the side clearance ``(Wg - Ws) / 2`` (Eq. 17), the smallest fit of the seal, and never less than
``PENETRATION_FLOOR``: a quarter of a clearance of a micrometre is below what a metal contact sinks under the
loads every seal carries, so the clearance alone made ordinary contacts implausible (the default scene with the
groove 1 µm wider than the seal: 0.17 µm under 172 N at 1e9 N/m, flagged as loads beyond what the seal takes). The
floor is the deflection of the softest metal contact (``METAL_STIFFNESS``) under ``FLOOR_LOAD``; a contact softer
than metal still sinks far deeper under those loads and is flagged at any clearance. A contact closed at rest by
design (the preloaded spring) is left out. :func:`apexseal.simulate` records the clearance in the result, warns
with :class:`PenetrationWarning` when the check fails, and ``summary.json`` carries the check as ``plausibility``.

The seal-groove contacts also hold only while the groove's mouth corners g1, g3 face the seal's flat sides
(Eqs. 20-23): a seal that sinks into its groove until a corner lies on its tip arc, or rises until its back face
passes the mouth, has no flat side there for the contact laws to act on. The start is refused there
(runtime/solving/preflight.py); :func:`flank_check` looks at every sample of a run (the groove submodel's outputs
l1..l4, each > 0 while its corner faces a flat side), and :func:`apexseal.simulate` warns with
:class:`FlankWarning` when one left it; ``summary.json`` carries it as ``flank``.
"""

from __future__ import annotations

import numpy as np

from ..scenes.units import PlausibilityWarning
from .spectra import contact_force

#: a contact whose penetration exceeds this fraction of the side clearance (Wg - Ws)/2 is implausible
PENETRATION_FRACTION = 0.25
#: N/m: the softest a metal contact of the seal's size is (docs/scene-estimates.md: 1e9-6e9 N/m; the calibration's
#: lower bound, runtime/studies/calibration/fit.py): a contact at least this stiff that sinks too deep is overloaded
METAL_STIFFNESS = 3e8


#: N: a load every seal's contacts carry: above the 88-172 N with which the default scene's pressures and inertia
#: press the seal on its walls where the clearance leaves no room for impacts (side clearances of 0.1 and 0.5 µm: groove
#: contacts 0.09-0.17 µm deep at 1e9 N/m, ``apexseal simulate -n 1 --set "seal.Wg=3.0002 mm"`` and ``3.001 mm``;
#: docs/scene-estimates.md)
FLOOR_LOAD = 300.0
#: m: the least penetration limit whatever the clearance, the softest metal contact's deflection under FLOOR_LOAD
#: (1 µm): a shallower penetration is a metal contact's under ordinary loads, not a soft contact or an overload
PENETRATION_FLOOR = FLOOR_LOAD / METAL_STIFFNESS


class PenetrationWarning(PlausibilityWarning):
    """A run whose contacts sink further into their walls than a metal contact can (a kind of the scene's
    :class:`~apexseal.runtime.scenes.units.PlausibilityWarning`: filtering that one filters this one too)."""


class FlankWarning(PlausibilityWarning):
    """A run in which a groove mouth corner left the seal's flat sides (its results there are outside the contact
    model of Eqs. 20-23)."""


#: the groove submodel's outputs that are > 0 while its mouth corners face the seal's flat sides (Eqs. 20-23)
FLANK_LENGTHS = ("l1", "l2", "l3", "l4")


def side_clearance(Ws: float, Wg: float) -> float:
    """(Wg - Ws) / 2: the seal's clearance on each side of its groove (Eq. 17), m."""
    return (Wg - Ws) / 2


def penetrations() -> dict[str, tuple[tuple[str, float], ...]]:
    """contact -> (the output of each of its guards, the sign that turns it into a penetration) for every contact
    that is open at rest (a preloaded spring, closed by design, is left out): what the plausibility check
    measures, the deepest over a contact's guards."""
    from ...derive.submodels.registry import guard_contacts, guards

    contact, out = guard_contacts(), {}
    for g in guards():
        if not g.closed_at_rest:
            out.setdefault(contact[g.name], []).append((g.output, -float(g.sign)))
    return {c: tuple(v) for c, v in out.items()}


def penetration_check(result, clearance: float | None = None, fraction: float = PENETRATION_FRACTION,
                      floor: float = PENETRATION_FLOOR) -> dict:
    """Deepest penetration of each contact (µm) and its largest force (N), the limit (``fraction`` of the side
    clearance, at least ``floor``, m: see the module docstring), and the contacts beyond it.

    Depths and forces are the largest at the output samples: an impact of a few microseconds between two samples
    is not seen, so a denser ``solver.samples_per_revolution`` can find a deeper one (a failed check stays failed;
    a passed one holds for the samples).

    ``clearance`` (m) defaults to the side clearance :func:`apexseal.simulate` recorded in ``result.info``.
    """
    if clearance is None:
        clearance = result.info.get("side_clearance_m")
    if clearance is None:
        raise ValueError("the result records no side clearance (run it with apexseal.simulate, or pass clearance)")
    limit = max(fraction * clearance, floor)
    depths, forces, at_start = {}, {}, []
    for contact, guards in penetrations().items():
        series = [sign * np.asarray(result.outputs[name], float) for name, sign in guards
                  if name in result.outputs and result.n]
        deepest = [float(np.max(g)) for g in series]
        if deepest:
            depths[contact] = max(0.0, *deepest)
            if depths[contact] > 0 and any(g[0] >= depths[contact] for g in series):  # its deepest: the first sample
                at_start.append(contact)
        force = contact_force(result.outputs, contact)
        if force is not None and result.n:
            forces[contact] = float(np.max(force))
    beyond = sorted(c for c, d in depths.items() if d > limit)
    return {"side_clearance_um": clearance * 1e6, "fraction": fraction, "floor_um": floor * 1e6,
            "limit_um": limit * 1e6,
            "penetration_um": {c: d * 1e6 for c, d in depths.items()}, "peak_force_N": forces,
            "beyond_limit": beyond, "deepest_at_start": [c for c in beyond if c in at_start], "ok": not beyond}


def describe(check: dict) -> str:
    """One line for a warning: which contacts, how deep, against what, and the likely cause: the initial state where
    every contact beyond the limit is deepest at the run's first sample, a contact softer than metal, or, where the
    peak force over the depth is a metal's stiffness, loads beyond the seal's (a check of a summary.json written
    before the forces were recorded names both)."""
    worst = ", ".join(f"{c} {check['penetration_um'][c]:.3g} µm" for c in check["beyond_limit"])
    side = f"{check['fraction']:g} of the side clearance (Wg - Ws)/2 = {check['side_clearance_um']:.3g} µm"
    bound = f"{side} (limit {check['limit_um']:.3g} µm)"
    if check.get("floor_um") is not None and check["limit_um"] <= check["floor_um"]:  # the clearance's is smaller
        bound = (f"{check['floor_um']:.3g} µm, the least limit at any clearance (a metal contact's deflection under "
                 f"{FLOOR_LOAD:g} N; {side} is {check['fraction'] * check['side_clearance_um']:.3g} µm)")
    head = f"implausible penetration: {worst} into the wall at the output samples, more than {bound}"
    soft = "the contact stiffness is far below a metal contact's (docs/scene-estimates.md gives plausible values)"
    loads = ("the loads are beyond what the seal takes (rotor speed, chamber pressures and their unit, preload, "
             "mass: the scene's plausibility warnings name doubtful keys)")
    if check["beyond_limit"] and check.get("deepest_at_start") == check["beyond_limit"]:
        # deepest at the run's first sample: the seal started inside the wall, whatever the loads and stiffness
        return (f"{head}, deepest at the run's first sample: the initial state puts the seal into the wall (check "
                "operation.initial_state; the start check lets a start this deep through: docs/scenes.md)")
    forces = check.get("peak_force_N", {})
    if not all(c in forces for c in check["beyond_limit"]):
        return f"{head}; either {soft}, or {loads}"
    stiff = {c: forces[c] / (check["penetration_um"][c] * 1e-6) for c in check["beyond_limit"]}
    peaks = ", ".join(f"{c} {forces[c] / 1e3:.3g} kN (about {stiff[c]:.2g} N/m)" for c in check["beyond_limit"])
    if min(stiff.values()) >= METAL_STIFFNESS:
        return f"{head}, under peak forces of {peaks}: the contacts are as stiff as metal, so {loads}"
    return f"{head}, under peak forces of {peaks}: {soft}"


def flank_check(result) -> dict | None:
    """The least of each mouth-corner length l1..l4 over the run (mm; Eqs. 20-23), whether all stayed > 0, and the
    crank angle (deg) of the first sample where one did not; None for a model without the groove contacts, and for a
    run refused at its start (its one sample is the initial state, which the refusal explains)."""
    names = [n for n in FLANK_LENGTHS if n in result.outputs]
    if not names or result.n < 2:
        return None
    lengths = np.stack([np.asarray(result.outputs[n], float) for n in names])
    off = np.flatnonzero((lengths <= 0).any(axis=0))
    return {"least_mm": {n: float(v) * 1e3 for n, v in zip(names, lengths.min(axis=1), strict=True)},
            "ok": not off.size, "first_off_deg": float(np.degrees(result.theta[off[0]])) if off.size else None}


def describe_flank(check: dict) -> str:
    """One line for a :class:`FlankWarning`: which lengths went negative, how far, and from where."""
    least = check["least_mm"]
    off = ", ".join(f"{n} = {v:.4g} mm" for n, v in least.items() if v <= 0)
    where = ("sank into its groove until a mouth corner lay on its tip arc" if min(least.get("l1", 1), least.get(
        "l3", 1)) <= 0 else "rose until its back face passed the groove's mouth")
    return (f"the seal {where} (least {off}; first at {check['first_off_deg']:.4g} deg): the seal-groove contacts "
            "of Eqs. 20-23 need both mouth corners on the seal's flat sides, so the results from there on are "
            "outside the model; check the initial state and the loads that drive the seal so far")
