"""The derivative-free check of the preload study: bisection on a constant delta_s over full simulations.

Each probe is a full simulation of the scene from its initial state (``revolutions`` revolutions, the
study's compiled ``erk`` interval integrator chained over the revolution: the simulator's hybrid model
with the friction-power and force-deficit quadratures, runtime/studies/preload/shooting.py), at a
parameter vector in which only delta_s (and what the scene derives from it, problem.py) changes. A
preload passes when the last (periodic) revolution's force deficit (and, with a groove-force bound, its
groove-force excess) is within the study's bound: the same grid-independent question the IPOPT study
asks, with no derivative.

The checks need not be monotone in delta_s: after a chamber switch the tip rings on the housing, and
the lowest force of that ringing rises and falls with the preload (with checks at 3600 samples of the
soft-contacts scene they passed at 8.36-8.50 mm, failed at 8.50-8.64 mm, passed at 8.64-8.91 mm).
The answer is therefore the robust one: the smallest preload from which every preload up to the
feasible start passes, so a spring that loses some preload keeps sealing. It is found by a downward
scan then a bisection of the first crossing; lower passing islands are reported (``monotone =
False``), never taken.
"""

from __future__ import annotations

import numbers
import time
from dataclasses import asdict, dataclass, field

import numpy as np

from ....progress import announce
from .problem import MM, PreloadSetup, PreloadStudyError, is_integer, max_preload_problem, windows


@dataclass
class BisectionResult:
    delta_s: float  # m, the smallest passing preload found (upper end of the final bracket)
    lower: float  # m, the largest failing preload (lower end of the final bracket; 0 with delta_s = 0 when 0 passes)
    min_measure: float  # N, smallest contact force at the samples at delta_s
    min_measure_angle: float  # deg
    friction_power: float  # W at delta_s
    periodic_change: float  # change of the scaled state over the last revolution at delta_s
    deficit: float  # N^2 rad, the force-deficit quadrature at delta_s
    simulations: int  # the probes, then the answer's re-simulation
    wall_time_s: float
    monotone: bool  # False: a probe below the answer passed (a lower island, not taken)
    probes: list = field(default_factory=list)  # [(delta_s m, force deficit N^2 rad), ...]

    def to_dict(self) -> dict:
        return asdict(self)


def bisect_preload(scene, *, min_force: float = 5.0, exclude=(), upper: float | None = None,
                   scan_step: float = 0.05 * MM, tol: float = 1e-3 * MM, probes: int = 8, samples: int | None = None,
                   rtol: float | None = None, revolutions: int = 3, max_preload: float = 0.1, functions=None,
                   setup: PreloadSetup | None = None, deficit_tol: float | None = None,
                   nodes: int = 4) -> BisectionResult:
    """The smallest delta_s (to ``tol``, m) such that every preload from it up to ``upper`` passes the checks.

    ``upper`` (default: the study's feasible start, the scene's preload times 1.5^k for the smallest
    k that passes) must pass. From it, preloads ``scan_step`` apart are simulated downwards
    (``probes`` at a time) until one fails; the crossing between that one and the next passing one
    above is then bisected. A failing stretch narrower than ``scan_step`` can be missed; passing
    preloads below the answer (islands) are kept in ``probes`` and flagged by ``monotone = False``.
    """
    from ...api import model_functions, scene_of
    from .periodic import periodic, periodic_many
    from .result import DEFICIT_TOL
    from .schedule import SegmentGrid
    from .shooting import study_functions

    scene = scene_of(scene)

    deficit_tol = DEFICIT_TOL if deficit_tol is None else deficit_tol
    if not (isinstance(probes, int) and 1 <= probes <= 16):
        raise PreloadStudyError(f"probes = {probes!r}: must be an integer in 1..16")
    if not (tol > 0 and scan_step >= tol):
        raise PreloadStudyError(f"tol = {tol!r}, scan_step = {scan_step!r}: need 0 < tol <= scan_step (m)")
    if not (is_integer(nodes) and 2 <= nodes <= 64):
        raise PreloadStudyError(f"nodes = {nodes!r}: must be an integer in 2..64")
    if max_preload_problem(max_preload):
        raise PreloadStudyError(max_preload_problem(max_preload))
    if upper is not None and not (isinstance(upper, numbers.Real) and 0 < upper <= max_preload):
        raise PreloadStudyError(f"upper = {upper!r}: must be a length > 0 and <= max_preload = {max_preload:g} m, "
                                "or None (the study's feasible start)")
    setup = setup or PreloadSetup(scene, functions or model_functions(scene), float(min_force),
                                  windows(exclude), samples, rtol, revolutions)
    min_force = setup.min_force
    if setup.samples % nodes:
        raise PreloadStudyError(f"nodes = {nodes}: must divide the {setup.samples} samples per revolution")
    sf = study_functions(setup, setup.samples // nodes)  # the IPOPT study's (same cache entry)
    grid = SegmentGrid(setup.samples, nodes, 1, setup.theta_start, setup.dth)

    def simulate(d):  # until periodic, as the IPOPT study re-simulates its optimum
        return periodic(setup, sf, grid, np.array([d]), min_force, setup.exclude)

    t = time.perf_counter()
    seen: list[tuple[float, float]] = []
    n_sim = 0
    change = 0.0

    def probe(ds):  # the probes of a round are integrated together, on every core
        nonlocal n_sim, change
        announce(f"  bisection: {len(ds)} preload{'s' if len(ds) != 1 else ''} from {min(ds) / MM:.4f} to "
                 f"{max(ds) / MM:.4f} mm, simulated until periodic ({n_sim} so far, {time.perf_counter() - t:.0f} s)")
        sims = periodic_many(setup, sf, grid, [np.array([d]) for d in ds], min_force, setup.exclude)
        n_sim += len(ds)
        change = max([change] + [s.change for s in sims])
        seen.extend((float(d), s.deficit) for d, s in zip(ds, sims, strict=True))
        # with a groove-force bound (setup.max_groove_force) its excess must be within the same bound too
        return np.array([s.deficit <= deficit_tol and s.groove_excess <= deficit_tol for s in sims])

    scene_ds = float(scene.parameters["delta_s"])
    if upper is None:
        base = scene_ds if scene_ds > 0 else MM
        for k in range(0, 60, probes):
            cands = [c for c in (base * 1.5 ** (k + i) for i in range(probes)) if c <= max_preload] or [max_preload]
            ok = np.nonzero(probe(cands))[0]
            if ok.size:
                upper = cands[int(ok[0])]
                break
            if cands[-1] >= max_preload:
                raise PreloadStudyError(f"no preload up to max_preload = {max_preload / MM:g} mm passes the checks")
    elif not probe([upper])[0]:
        raise PreloadStudyError(f"upper = {upper / MM:g} mm does not pass the checks: raise it")
    # scan down from upper until a preload fails
    hi, lo = upper, None
    while lo is None:
        ds = hi - scan_step * np.arange(1, probes + 1)
        ds = ds[ds > 0]
        if not ds.size:  # every preload scanned passes, down to the last above 0: 0 itself is probed
            lo = 0.0
            if probe([0.0])[0]:  # no preload needed: the answer is 0, and no failing preload bounds it
                hi = 0.0
            break
        ok = probe(list(ds))
        failed = np.nonzero(~ok)[0]
        if failed.size:
            i = int(failed[0])
            lo, hi = float(ds[i]), float(ds[i - 1]) if i > 0 else hi
        else:
            hi = float(ds[-1])
    # bisect the crossing
    while hi - lo > tol:
        ds = lo + (hi - lo) * np.arange(1, probes + 1) / (probes + 1)
        ok = probe(list(ds))
        failed = np.nonzero(~ok)[0]
        k = int(failed[-1]) if failed.size else -1  # the highest failing probe
        lo = float(ds[k]) if k >= 0 else lo
        hi = float(ds[k + 1]) if k + 1 < probes else hi
    sim = simulate(hi)
    n_sim += 1
    keep = setup.mask(sim.thetas)
    j = int(np.argmin(np.where(keep, sim.measure, np.inf)))
    monotone = not any(v <= deficit_tol for d, v in seen if d < lo)
    return BisectionResult(hi, lo, float(sim.measure[j]), float(np.degrees(sim.thetas[j]) % 360.0),
                           sim.friction_power, sim.change, sim.deficit, n_sim, time.perf_counter() - t, monotone,
                           sorted(seen))

