"""The constant design over (delta_s, ks) together: the optimum is a curve, ks delta_s = the optimal spring force.

The spring presses the seal outward with ks times its compression, delta_s at rest less the outward travel s of
the seal's back face (Eqs. 38-39); s is micrometres while delta_s is millimetres, so the force is ks delta_s to
within ks s (a few mN at ks = 5e3 N/m). Everything else that follows ks is as small: the
housing contact's rest deflection delta_w = ks delta_s / kw (Eq. 9) depends on the product too, and only the
spring's damping cs = 2 zeta_s sqrt(ks ms) (when the scene gives its damping ratio) and the ks s term change
along the curve. So friction power and the force deficit are functions of the spring force F0 = ks delta_s alone,
to within what those terms move: the joint problem is degenerate (its optimum is the curve ks delta_s = F0*),
and IPOPT over (delta_s, ks) would wander along the valley. The study therefore optimises delta_s at the scene's
ks and shows the valley: :func:`stiffness_valley` re-simulates the optimum's spring force at other stiffnesses
(delta_s = F0* / ks), each a full periodic simulation with the study's integrator and both quadratures, so any
(delta_s, ks) pair on the curve can be chosen for other reasons (space, fatigue, tolerance of delta_s).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ....progress import announce
from .problem import MM, PreloadSetup, PreloadStudyError
from .result import ALLOWANCE

#: the stiffnesses tried, as factors of the scene's ks
FACTORS = (0.25, 0.5, 1.0, 2.0, 4.0)


@dataclass(frozen=True)
class ValleyPoint:
    ks: float  # N/m
    delta_s: float  # m, F0* / ks
    spring_force: float  # N, the spring's force at rest (Eq. 39; the same at every point)
    friction_power: float  # W, cycle mean of the periodic revolution
    deficit: float  # N^2 rad, the force-deficit quadrature
    groove_excess: float  # N^2 rad (0 without a groove-force bound)


def stiffness_valley(setup: PreloadSetup, result, *, nodes: int = 4, factors=FACTORS) -> list[ValleyPoint]:
    """Re-simulate the constant optimum's spring force at rest (Eq. 39) at the stiffnesses ``factors`` x the
    scene's: at each, the preload whose force at rest is the same.

    Uses the study's compiled interval integrator (the same cache entry as the study: for a constant preload the
    integrator's built-in d p / d delta_s multiplies a zero slope, so the scene's units serve every ks).
    """
    from .periodic import periodic
    from .schedule import SegmentGrid
    from .shooting import study_functions

    if result.knots is None or len(result.knots) != 1:
        raise PreloadStudyError("stiffness_valley: needs a solved constant-preload result (knots = 1)")
    if not all(isinstance(f, int | float) and 0 < f <= 100 for f in factors):
        raise PreloadStudyError(f"factors = {list(factors)!r}: each must be in (0, 100] (times the scene's ks)")
    ks0 = setup.pmap.at("ks")
    force = setup.pmap.spring_force(float(result.knots[0]))
    sf = study_functions(setup, setup.samples // nodes)
    grid = SegmentGrid(setup.samples, nodes, 1, setup.theta_start, setup.dth)
    points = []
    t = time.perf_counter()
    for i, f in enumerate(factors):
        scene = setup.scene.with_overrides(**{"spring.ks": ks0 * f})
        s = PreloadSetup(scene, setup.functions, setup.min_force, setup.exclude, setup.samples, setup.rtol,
                         setup.revolutions, setup.flags, setup.max_groove_force)
        # the law is linear in the preload (preload_parameters refuses a scene whose parameters are not affine in
        # it), so its force at 1 m is its slope at this stiffness
        d = force / setup.pmap.spring_force(1.0, ks=ks0 * f)
        announce(f"  stiffness valley: ks = {ks0 * f:.4g} N/m ({f:g} x the scene's), delta_s = {d / MM:.4f} mm, "
                 f"simulated until periodic ({i} of {len(factors)} done, {time.perf_counter() - t:.0f} s)")
        sim = periodic(s, sf, grid, np.array([d]), s.min_force, s.exclude)
        points.append(ValleyPoint(ks0 * f, d, force, sim.friction_power, sim.deficit, sim.groove_excess))
    return points


def feasible(p: ValleyPoint, deficit_tol: float) -> str:
    """Whether a point meets the bounds as the study accepts its own re-simulated optimum (within ``ALLOWANCE``)."""
    worst = max(p.deficit, p.groove_excess) / deficit_tol
    if worst > ALLOWANCE:
        which = "force deficit" if p.deficit >= p.groove_excess else "groove-force excess"
        return f"no: {which} above its bound"
    return "yes" if worst <= 1.0 else f"yes (within the {100 * (ALLOWANCE - 1):.0f} % the study allows its optimum)"


def describe(points: list[ValleyPoint], deficit_tol: float) -> str:
    """The valley as a table: the same spring force at each stiffness, feasible as the study's optimum is."""
    lines = [f"  the same spring force at rest (Eq. 39) = {points[0].spring_force:.3f} N at other stiffnesses (periodic "
             "re-simulations):",
             "    ks (N/m)   delta_s (mm)   friction power (W)   force deficit (x bound)   feasible"]
    lines += [f"    {p.ks:9.4g}   {p.delta_s / MM:12.4f}   {p.friction_power:18.3f}   {p.deficit / deficit_tol:23.3f}   "
              + feasible(p, deficit_tol) for p in points]
    return "\n".join(lines)
