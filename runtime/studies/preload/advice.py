"""What the preload study tells a spring designer beside its numbers: where the force falls short (an impact
transient, which an ``--exclude`` window may rightly free, or a smooth minimum of the tip force, where the lift-off
is real), when the spring itself cannot give the force asked, and whether a constant optimum is robust (more
preload keeps it feasible) or a knife-edge point of a feasible set that is not monotone in the preload.
"""

from __future__ import annotations

import numpy as np

from ...results.chamber_switches import chamber_switches
from .problem import MM

#: crank angle (deg) on each side of where the force falls short in which a chamber switch or the tip's ringing
#: marks it as an impact transient, at :data:`REFERENCE_RPM`; at other speeds it is the same time (:func:`margin_deg`)
MARGIN_DEG = 5.0
#: rpm at which :data:`MARGIN_DEG` holds: the default scene's speed, at which it was set
REFERENCE_RPM = 1500.0
#: relative steps above a constant optimum re-simulated to check that more preload stays feasible
#: (:func:`.study._polish_constant`): a spring loses or gains that much preload in its tolerances
ROBUST_STEPS = (0.01, 0.05)


def margin_deg(rpm: float) -> float:
    """The crank angle (deg) on each side of a shortfall within which a chamber switch or ringing marks it as an
    impact transient, at ``rpm``: the time :data:`MARGIN_DEG` takes at :data:`REFERENCE_RPM` (0.556 ms), never less
    than :data:`MARGIN_DEG`.

    The transient after a switch is a time, not an angle: the seal is thrown across its groove and rattles (impacts
    and flights, each impact losing energy to the contacts' dampers) until it settles on the housing. Its duration
    is set by the flights, which do not depend on the speed, and not by the decay of a contact mode's linear ringing
    (runtime/solving/ringing.py, ``mode_damping``): 1/(zeta w) of the tip contact is 0.08 ms on the default scene
    (zeta 0.05 at w = sqrt(kw/ms) = 2.4e5 rad/s: zeta_w = 0.1 acting in half of each period, as
    runtime/solving/contact_stability.py counts it), while the tip force leaves its smooth course for up to 3.7 deg
    after a switch at 1500 rpm and 8.7 deg at 3000 rpm, 0.41 and 0.48 ms, and twice the tip's damping (zeta_w 0.2)
    leaves it as long (9.5 deg at 3000 rpm): tests/runtime/test_preload_advice.py,
    ``test_the_transient_after_a_switch_lasts_a_time``. So the margin is the same time at every speed; a seal whose
    contacts are damped far less than the default's (zeta 0.1), or stiffer, may rattle longer than it."""
    return MARGIN_DEG * max(1.0, float(rpm) / REFERENCE_RPM)


def _near(deg, start: float, end: float, margin: float):
    """Whether ``deg`` (mod 360) lies within ``margin`` deg of the span [start, end] (deg mod 360, may cross 0)."""
    width = (end - start) % 360.0
    return (np.asarray(deg) - (start - margin)) % 360.0 <= width + 2 * margin


def shortfall_kind(thetas, measure, pressures, start: float, end: float, *, rpm: float) -> tuple[str, str]:
    """("transient", why) where the tip force falls short at [start, end] deg next to a chamber switch
    (runtime/results/chamber_switches.py, at an angle within :func:`margin_deg` of the span at the scene's ``rpm``) or while
    the tip rings (two or more local minima of the force at the samples within that margin of it); else ("smooth",
    why): a single smooth minimum of the force (the seal's inertial or gas load), where the lift-off is real.
    ``thetas`` (rad), ``measure`` (N) and ``pressures`` (2 x samples, Pa) at the samples of a re-simulated
    revolution."""
    margin = margin_deg(rpm)
    switches = [s for s in chamber_switches(thetas, pressures) if _near(s.angle_deg, start, end, margin)]
    if switches:
        s = max(switches, key=lambda s: abs(s.change))
        return "transient", (f"a chamber switch at {s.angle_deg:.1f} deg (Pa - Pb changes by {s.change / 1e5:+.3g} "
                             f"bar within {s.width_deg:.3g} deg)")
    deg = np.degrees(np.asarray(thetas, float)) % 360.0
    near = _near(deg, start, end, margin)
    m = np.asarray(measure, float)
    minima = near & (m < np.roll(m, 1)) & (m <= np.roll(m, -1))
    if np.count_nonzero(minima) >= 2:
        return "transient", f"the tip rings there ({np.count_nonzero(minima)} dips of its force within " \
                            f"{margin:.3g} deg)"
    return "smooth", ("a single smooth minimum of the tip force (the seal's inertial and gas load), no chamber switch "
                      f"within {margin:.3g} deg")


def shortfall_advice(kind: str, why: str) -> str:
    """What to do about a force that falls short, by :func:`shortfall_kind`."""
    if kind == "transient":
        return (f"an impact transient ({why}): an --exclude window there frees the preload from it, where the "
                "seal may leave the housing that briefly")
    return (f"{why}: the lift-off there is real and it sets the preload; do not exclude it (that hides the failure "
            "the study guards against)")


def spring_capacity(setup, max_preload: float, min_force: float) -> str:
    """The limit of the spring where its force at rest at ``max_preload`` (Eq. 39) is below ``min_force``: no preload
    searched can press the tip with the force asked; "" where it can."""
    force = setup.pmap.spring_force(max_preload)
    if force >= min_force:
        return ""
    return (f"the spring cannot give it: its force at max_preload = {max_preload / MM:g} mm is ks x delta_s = "
            f"{force:.4g} N < {min_force:g} N asked; use a stiffer spring (--set 'spring.ks=...') or a larger "
            "max_preload (--max-preload)")


def robustness(result) -> list[str]:
    """The lines saying that a constant optimum is not robust (:attr:`.result.PreloadResult.robust` False): what it
    means and what to do; [] otherwise."""
    if result.robust is not False:
        return []
    failed = [p for p in result.robust_probes if not p[1]]
    probes = "; ".join(f"{d / MM:.4f} mm fails (force deficit {deficit / result.deficit_tol:.3g} x its bound, at "
                       f"{a:.1f}...{b:.1f} deg)" for d, _ok, deficit, (a, b) in failed)
    return [f"  NOT ROBUST: {result.delta_s / MM:.4f} mm is a knife-edge point: a little more preload violates the "
            f"force requirement again ({probes}). The feasible set is not monotone in the preload, and no spring "
            "can be made to such a narrow pocket of preload.",
            "  likely cause: an impact transient (the ringing after a chamber switch) that the excluded windows "
            "do not cover at this speed; widen or add an --exclude window around the failing angles, or take "
            "the derivative-free bisection's answer (--check), the smallest preload above which every preload "
            "probed passes"]


def bisection_caveat(b) -> str:
    """The line saying that the bisection found the feasible set not monotone in the preload; "" where it is."""
    if b is None or b.monotone:
        return ""
    islands = [p for p in b.probes if p.passed and b.lower is not None and p.delta_s < b.lower]
    return ("the feasible set is not monotone in the preload: "
            + (f"{len(islands)} probe{'s' * (len(islands) != 1)} below the bracket passed "
               f"({', '.join(f'{p.delta_s / MM:.4f}' for p in islands[:4])} mm), islands not taken"
               if islands else "probes below the bracket passed")
            + ". The bracket is the robust answer (every preload probed above it passes); a lower optimum is a "
            "knife-edge point. Likely cause: an excluded window too short at this speed (the failing probes' "
            "deficits lie between the samples: bisection.probes in preload.json).")


def caveats(results: dict, bisection=None) -> list[str]:
    """Every warning of a study's results, as the console, the top of preload.md and preload.json's ``warnings``
    state them: a constant optimum that is not robust, a bisection that found the feasible set not monotone."""
    out = []
    c = results.get("constant")
    if c is not None and c.ok:
        out += robustness(c)
    if line := bisection_caveat(bisection):
        out.append(line)
    return [w.strip() for w in out]
