"""The calibration's verdict on the crank angle of the largest x (the paper's "approximately at the 3 pi/2 (270 deg)
position", Section 4.5, Fig. 12a): where the best set puts it, relative to the nearest chamber switch of its run
(runtime/results/chamber_switches.py), and where the other sets completed put it. Each part of the reason is
measured on the evaluations, none assumed: on the default scene the best set's largest x lies at the switch near
182.5 deg, under ``assumptions.housing_stiffness = "tilted-wall"`` some 20 deg after it (docs/paper-findings.md,
"Calibration under the two choices").
"""

from __future__ import annotations

import numpy as np

from ...results.chamber_switches import PRESSURE_STEP, SWITCH_WIDTH_DEG
from .features import PAPER_X_ANGLE_DEG, angle_error_deg

#: where the switches of the verdict come from (its ``switches_from``): the best set's own run's chamber pressures,
#: or (a calibration that kept none) the scene's pressure source; in words
FROM_RUN, FROM_SCENE = "run", "scene"
SOURCES = {FROM_RUN: "the chamber pressures of the best set's run", FROM_SCENE: "the scene's chamber pressures"}


def after_deg(angle: float, switch: float) -> float:
    """Crank angle from ``switch`` to ``angle``, deg in (-180, 180]: > 0 after the switch, < 0 before it."""
    d = (angle - switch) % 360.0
    return d - 360.0 if d > 180.0 else d


def nearest_switch(angle: float, switches) -> tuple[float, float] | None:
    """(switch angle, :func:`after_deg`) of the switch of ``switches`` (angles, deg) nearest ``angle``; None without
    one."""
    if not len(switches):
        return None
    s = min(switches, key=lambda s: abs(after_deg(angle, s)))
    return float(s), after_deg(angle, s)


def relative_to_switches(angle: float, switches, source: str) -> str:
    """Where ``angle`` (deg) lies relative to the nearest of ``switches`` (angles, deg; None: unknown), in words,
    with where the switches were found (``source``: a key of :data:`SOURCES`)."""
    source = SOURCES.get(source, source)
    if switches is None:
        return "no chamber pressures to place it against (the calibration kept none, and has no scene)"
    if not len(switches):
        return (f"no chamber switch in {source} (Pa - Pb changes by no more than "
                f"{100 * PRESSURE_STEP:.0f} % of its range within {SWITCH_WIDTH_DEG:g} deg)")
    s, d = nearest_switch(angle, switches)
    where = (f"at the chamber switch at {s:.1f} deg, {abs(d):.1f} deg {'after' if d >= 0 else 'before'} it"
             if abs(d) <= SWITCH_WIDTH_DEG else
             f"{abs(d):.1f} deg {'after' if d >= 0 else 'before'} the nearest chamber switch, at {s:.1f} deg")
    return f"{where} (switches at {', '.join(f'{a:.1f}' for a in switches)} deg in {source})"


def angle_verdict(best: float, angles, switches, source: str, matched: bool, match_deg: float) -> dict:
    """The ``x_max_angle`` verdict: ``best``, the best set's angle of the largest x (deg); ``angles``, that of every
    set completed; ``switches`` (deg, None: unknown) and their ``source``; ``matched``: within ``match_deg`` of the
    paper's angle. Its reason says where the best set's largest x lies relative to the nearest switch, and the
    range of the angles over the sets with the nearest to the paper's."""
    angles = np.asarray(angles, float)
    errors = np.array([angle_error_deg(a, PAPER_X_ANGLE_DEG) for a in angles])
    closest = float(angles[np.argmin(errors)])
    off = float(errors.min())
    near = nearest_switch(best, switches) if switches is not None else None
    out = {"paper_deg": PAPER_X_ANGLE_DEG, "fit_deg": best, "matched": bool(matched),
           "range_over_evaluations_deg": [float(angles.min()), float(angles.max())],
           "closest_over_evaluations_deg": closest,
           "chamber_switches_deg": None if switches is None else [float(s) for s in switches],
           "switches_from": source if switches is not None else None,
           "nearest_switch_deg": near[0] if near else None, "after_nearest_switch_deg": near[1] if near else None}
    n = angles.size
    out["reason"] = "matched" if matched else (
        f"the best set's largest x is at {best:.1f} deg, {relative_to_switches(best, switches, source)}; the "
        f"{n} set{'s' if n != 1 else ''} completed put it at {angles.min():.1f}..{angles.max():.1f} deg, the "
        f"nearest to the paper's {PAPER_X_ANGLE_DEG:g} deg at {closest:.1f} deg, {off:.1f} deg away "
        f"(a match is within {match_deg:g} deg); the default scene's chamber pressures are an estimate (the "
        "paper's Fig. 11 is not tabulated; docs/paper-findings.md)")
    return out
