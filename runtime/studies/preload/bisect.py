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
from .problem import MM, PreloadSetup, PreloadStudyError, max_preload_problem, nodes_problem, windows


@dataclass
class Probe:
    """One preload the bisection simulated (until periodic) and its verdict."""

    delta_s: float  # m
    passed: bool  # the force deficit (and, with a groove-force bound, its excess) within the study's bound
    deficit: float  # N^2 rad, the force-deficit quadrature of the last revolution
    groove_excess: float  # N^2 rad, the groove-force excess quadrature (0 without a groove-force bound)
    friction_power: float  # W, cycle mean
    min_measure: float  # N, smallest contact force at the checked samples
    min_measure_angle: float  # deg


@dataclass
class BisectionResult:
    """The bisection's answer; with ``complete = False``, how far it got (its rounds of probes so far: the study was
    stopped, or a round's ``progress`` report): the bracket those probes establish, ``lower`` None while no failing
    preload bounds it and ``delta_s`` None while none passed (the start search), the other numbers those of the
    probe at ``delta_s``."""

    delta_s: float | None  # m, the smallest passing preload found (upper end of the final bracket)
    lower: float | None  # m, the largest failing preload (lower end of the final bracket; 0 with delta_s = 0 when 0 passes)
    min_measure: float | None  # N, smallest contact force at the samples at delta_s
    min_measure_angle: float | None  # deg
    friction_power: float | None  # W at delta_s
    periodic_change: float  # change of the scaled state over the last revolution at delta_s
    deficit: float | None  # N^2 rad, the force-deficit quadrature at delta_s
    simulations: int  # the probes, then the answer's re-simulation
    wall_time_s: float
    monotone: bool  # False: a probe below the answer passed (a lower island, not taken)
    probes: list = field(default_factory=list)  # [Probe, ...] in increasing delta_s
    complete: bool = True  # False: the probes so far of a bisection that did not end (see the class docstring)

    def to_dict(self) -> dict:
        return asdict(self)

    def bracket(self) -> str:
        """The bracket in words, e.g. "[0.3840, 0.3846] mm", or what bounds the answer so far."""
        if self.delta_s is None:
            return "no preload passed yet" + (f" (up to {self.lower / MM:.4f} mm)" if self.lower is not None else "")
        if self.lower is None:
            return f"at most {self.delta_s / MM:.4f} mm (no failing preload below it yet)"
        return f"[{self.lower / MM:.4f}, {self.delta_s / MM:.4f}] mm"


def bisect_preload(scene, *, min_force: float = 5.0, exclude=(), upper: float | None = None,
                   scan_step: float = 0.05 * MM, tol: float = 1e-3 * MM, probes: int = 8, samples: int | None = None,
                   rtol: float | None = None, revolutions: int = 3, max_preload: float = 0.1, functions=None,
                   setup: PreloadSetup | None = None, deficit_tol: float | None = None,
                   nodes: int = 4, progress=None) -> BisectionResult:
    """The smallest delta_s (to ``tol``, m) such that every preload from it up to ``upper`` passes the checks.

    ``upper`` (default: the study's feasible start, the scene's preload times 1.5^k for the smallest
    k that passes) must pass. From it, preloads ``scan_step`` apart are simulated downwards
    (``probes`` at a time) until one fails; the crossing between that one and the next passing one
    above is then bisected. A failing stretch narrower than ``scan_step`` can be missed; passing
    preloads below the answer (islands) are kept in ``probes`` and flagged by ``monotone = False``.

    ``progress``: called after each round of probes with the :class:`BisectionResult` so far (``complete =
    False``), so that a caller keeps the probes of a bisection that is stopped (the command writes them into its
    report checkpoint).
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
    for problem in (nodes_problem(nodes), max_preload_problem(max_preload)):
        if problem:
            raise PreloadStudyError(problem)
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
    seen: list[Probe] = []
    n_sim = 0
    change = 0.0
    hi: float | None = None  # the smallest preload of the passing run down from upper, so far
    lo: float | None = None  # the failing preload below it that the scan found, then the bisection's lower end
    floor: float | None = None  # the largest failing preload below hi that the start search probed

    def so_far() -> BisectionResult:  # the bracket the probes establish so far, the numbers of the probe at hi
        at = next((p for p in seen if p.delta_s == hi), None)
        # the start search's failing preload bounds the scan's bracket while the scan has passed no preload below it
        lower = lo if lo is not None else floor if hi is None or floor is None or floor < hi else None
        measured = (at.min_measure, at.min_measure_angle, at.friction_power) if at else (None, None, None)
        return BisectionResult(hi, lower, *measured, change, at.deficit if at else None, n_sim, time.perf_counter() - t,
                               _monotone(seen, lower, deficit_tol), sorted(seen, key=lambda p: p.delta_s),
                               complete=False)

    def probe(ds):  # the probes of a round are integrated together, on every core
        nonlocal n_sim, change
        announce(f"  bisection: {len(ds)} preload{'s' if len(ds) != 1 else ''} from {min(ds) / MM:.4f} to "
                 f"{max(ds) / MM:.4f} mm, simulated until periodic ({n_sim} so far, {time.perf_counter() - t:.0f} s)")
        sims = periodic_many(setup, sf, grid, [np.array([d]) for d in ds], min_force, setup.exclude)
        n_sim += len(ds)
        change = max([change] + [s.change for s in sims])
        # with a groove-force bound (setup.max_groove_force) its excess must be within the same bound too
        ok = np.array([s.deficit <= deficit_tol and s.groove_excess <= deficit_tol for s in sims])
        seen.extend(Probe(float(d), bool(passed), s.deficit, s.groove_excess, s.friction_power, *setup.smallest(s))
                    for d, s, passed in zip(ds, sims, ok, strict=True))
        return ok

    def round_of(ds):  # a round of probes, the bracket updated, then reported
        nonlocal hi, lo, floor
        ok = probe(ds)
        failed = np.nonzero(~ok)[0]
        if hi is None:  # the start search (or the upper given): the first passing candidate is the upper end
            if ok.any():
                hi = float(ds[int(np.nonzero(ok)[0][0])])
            below = [float(d) for d, good in zip(ds, ok, strict=True) if not good and (hi is None or d < hi)]
            floor = max(below + ([floor] if floor is not None else [])) if below else floor
        elif lo is None:  # the scan down: the run of passing preloads goes on down to the first failing one
            i = int(failed[0]) if failed.size else len(ds)
            hi = float(ds[i - 1]) if i > 0 else hi
            lo = float(ds[i]) if failed.size else None
        else:  # the bisection of the crossing: between the highest failing probe and the passing one above it
            k = int(failed[-1]) if failed.size else -1
            lo = float(ds[k]) if k >= 0 else lo
            hi = float(ds[k + 1]) if k + 1 < len(ds) else hi
        if progress is not None:
            progress(so_far())
        return ok

    scene_ds = float(scene.parameters["delta_s"])
    if upper is None:
        base = scene_ds if scene_ds > 0 else MM
        for k in range(0, 60, probes):
            cands = [c for c in (base * 1.5 ** (k + i) for i in range(probes)) if c <= max_preload] or [max_preload]
            if round_of(cands).any():
                break
            if cands[-1] >= max_preload:
                raise PreloadStudyError(f"no preload up to max_preload = {max_preload / MM:g} mm passes the checks")
    elif not round_of([upper])[0]:
        raise PreloadStudyError(f"upper = {upper / MM:g} mm does not pass the checks: raise it")
    # scan down from the upper end until a preload fails
    while lo is None:
        ds = hi - scan_step * np.arange(1, probes + 1)
        ds = ds[ds > 0]
        if not ds.size:  # every preload scanned passes, down to the last above 0: 0 itself is probed
            lo = 0.0
            if probe([0.0])[0]:  # no preload needed: the answer is 0, and no failing preload bounds it
                hi = 0.0
            if progress is not None:
                progress(so_far())
            break
        round_of(list(ds))
    # bisect the crossing
    while hi - lo > tol:
        round_of(list(lo + (hi - lo) * np.arange(1, probes + 1) / (probes + 1)))
    sim = simulate(hi)
    n_sim += 1
    force, angle = setup.smallest(sim)
    return BisectionResult(hi, lo, force, angle, sim.friction_power, sim.change, sim.deficit, n_sim,
                           time.perf_counter() - t, _monotone(seen, lo, deficit_tol), sorted(seen, key=lambda p: p.delta_s))


def _monotone(seen: list, lo: float | None, deficit_tol: float) -> bool:
    """False when a probe below the bracket's lower end passed the force-deficit bound (a lower island)."""
    return lo is None or not any(p.deficit <= deficit_tol for p in seen if p.delta_s < lo)
