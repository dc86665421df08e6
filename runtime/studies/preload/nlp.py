"""The spring-preload study: the preload (constant, or a schedule delta_s(theta)) that costs least friction
while the seal tip stays pressed on the housing everywhere on the trajectory.

``optimise_preload(scene, min_force=5.0, knots=1)`` solves, with IPOPT,

    minimise    cycle-mean friction power of all contacts (objective="friction"), or the mean preload
                (objective="preload")
    subject to  the seal's motion over one revolution is periodic (the machine's steady state),
                the squared force deficit  int max(0, min_force - F)^2 dtheta  <= deficit_tol
                (outside the excluded windows; F the tip's contact measure, problem.py),
                optionally the groove-force excess  int sum_c max(0, |F_c| - max_groove_force)^2 dtheta
                <= deficit_tol  (every seal-groove contact c, Eq. 63; shooting.py),
                0 <= delta_s <= max_preload and |d delta_s / d theta| <= max_rate (schedules),

where delta_s(theta) is periodic and piecewise linear through ``knots`` values (1 knot: the constant
preload; schedule.py) and the motion is the simulator's hybrid model integrated by CasADi's ``erk``
with events (shooting.py). Every formulation choice below was measured (docs/preload.md):

* **Grid independence.** The constraint is a quadrature inside the integrator, so the adaptive steps
  and located events resolve every dip between samples; the output grid enters only through the
  chamber-pressure means (the simulator's). With checks at samples the answer moved from 6.08 to
  8.95 mm between 0.5 and 0.1 deg grids; with the quadrature and the same pressures, 360 and 720 samples
  give the same answer (slow test). The pressure means are a model input the answer does depend on
  (8.47 mm with 1 deg means, 8.89 mm with 0.5 deg means on the soft-contacts scene).
  ``deficit_tol`` (default (0.2 N)^2 x 0.1 deg) keeps the constraint's gradient non-zero at the
  optimum (a zero tolerance makes LICQ fail) and bounds what it allows: e.g. a 0.2 N shortfall
  lasting 0.1 deg, or a 2 N one lasting 0.001 deg.
* **Decision variables**: the knot values in mm and the 6 scaled states at ``nodes`` shooting nodes,
  each divided by the largest magnitude that component reaches on the start trajectory.
* **Shooting**: each shooting interval is a chain of segments (one per knot stretch, schedule.py),
  each one call of the compiled interval integrator; the intervals are mapped over the nodes, a
  thread per core (apexseal.cores.parallel_threads). Sensitivities (forward, including the event times)
  come from the compiled forward derivative of that integrator, called in chunks of directions,
  assembled into the NLP Jacobian by hand (a ``custom_jacobian``): the NLP is never generated to C
  as a whole, so the cold build is the two small C units of shooting.py (tens of seconds, instead
  of one ~65 MB file that took gcc about 2 minutes).
* **Modes at the nodes** follow from the node's gaps (closed where negative), with no derivative:
  exact while no gap is zero at a node, so the nodes are placed at the sample offset that keeps them
  farthest from every contact switch of the start trajectory. 4 nodes by default: a node inside the
  rattle after a chamber switch carries a state that depends on rtol-level details of every impact,
  and its continuity defect could not be closed (measured with 8 nodes on the soft-contacts scene).
* **Non-smooth strategy**: events inside the intervals are located by the integrator, and their
  sensitivities enter the Jacobian, so IPOPT sees the mode sequence of the current iterate. The optimum
  is re-simulated from the scene's initial state (3 revolutions, more until periodic: PERIODIC_TOL, the
  same integrator); when that revolution violates the deficit bound, the NLP is solved again from the
  re-simulated trajectory with the nodes re-placed (``rounds``), until the re-simulation satisfies
  every constraint.
* **Start**: a feasible periodic trajectory at a constant preload: the scene's times 1.5^k for the
  smallest k whose re-simulated revolution meets the deficit bound; the preload is bounded above by it.
  A schedule starts from the constant optimum (the constant is a feasible schedule, so the schedule's
  friction power can only be lower).
* **Tolerances**: IPOPT's tol and constr_viol_tol 1e-3; the constraint function is noisy at the erk
  rtol (the rattle's impacts), so IPOPT also stops ("acceptable") once the objective changes by less
  than 1e-4 relative over 3 iterations with the constraints within 2e-2 of their bounds (the deficit
  within 2 % of its bound). IPOPT with MUMPS and the limited-memory Hessian.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import asdict, dataclass, field

import casadi as ca
import numpy as np

from ....cores import parallel_threads
from ....derive.symbols import PARAMETER_NAMES
from ....progress import announce, stage
from ...solving.scaling import state_scale
from .problem import KW, MM, PreloadSetup, PreloadStudyError
from .schedule import Schedule, SegmentGrid, chain_function, simulate_schedule, simulate_schedules
from .shooting import CHUNK, TWO_PI, study_functions

_DS = PARAMETER_NAMES.index("delta_s")
_KS = PARAMETER_NAMES.index("ks")

#: default bound of the squared force deficit: (0.2 N)^2 over 0.1 deg of crank angle (N^2 rad); at (0.1 N)^2 over
#: 0.05 deg the deficit of the iterates near the optimum was noisy at ~10 % of the bound (the rattle's impacts at
#: the erk rtol) and IPOPT wandered for 100 iterations within 1e-4 of the answer without stopping (measured)
DEFICIT_TOL = 0.2**2 * np.radians(0.1)
#: IPOPT statuses taken as a solution
SOLVED = ("Solve_Succeeded", "Solved_To_Acceptable_Level")
OBJECTIVES = ("friction", "preload")


class PreloadStudyFailed(RuntimeError):
    """The study could not give an answer; the message says what failed, where and why."""


@dataclass
class PreloadResult:
    """What the study found. ``knots`` is None when it failed (``message`` says why)."""

    ok: bool
    message: str
    min_force: float  # N, the requirement
    exclude_deg: list  # excluded crank-angle windows [(start, end), ...] in degrees
    objective: str = "friction"
    knot_angles_deg: list = field(default_factory=list)
    knots: list | None = None  # m, the optimal delta_s at the knots (one value: the constant preload)
    delta_s: float | None = None  # m, the mean preload over the revolution (the constant preload for 1 knot)
    spring_force: float | None = None  # N, ks * mean delta_s (the spring's force at rest, Eq. 39)
    scene_delta_s: float = 0.0  # m
    friction_power: float | None = None  # W, cycle mean at the optimum (re-simulation)
    scene_friction_power: float | None = None  # W, at the scene's preload
    nlp_friction_power: float | None = None  # W, the NLP's own
    contact_friction_power: dict = field(default_factory=dict)  # W, cycle mean of each contact (re-simulation)
    scene_contact_friction_power: dict = field(default_factory=dict)  # W, the same at the scene's preload
    deficit: float | None = None  # N^2 rad, the force-deficit quadrature of the re-simulation
    deficit_tol: float = DEFICIT_TOL
    max_groove_force: float | None = None  # N, the bound on every seal-groove contact force (None: none)
    groove_excess: float | None = None  # N^2 rad, the groove-force excess quadrature of the re-simulation
    groove_peak: float | None = None  # N, the largest seal-groove contact force at the samples (re-simulation)
    min_measure: float | None = None  # N, the smallest contact force at the samples (re-simulation)
    min_measure_angle: float | None = None  # deg, where
    periodic_change: float | None = None  # change of the scaled state over the re-simulation's last revolution
    ipopt_status: str = ""
    ipopt_iterations: int = 0
    ipopt_time_s: float = 0.0
    build_time_s: float = 0.0  # generation + compilation of the study's C (0 when cached)
    rounds: int = 0  # NLP solves (re-simulate and repeat)
    start_delta_s: float | None = None  # m, the feasible constant start
    nodes: int = 0
    samples: int = 0
    rtol: float = 0.0
    max_defect: float | None = None  # largest continuity/periodicity defect at the solution (scaled state)
    history: list = field(default_factory=list)  # [(delta_s m, min force at samples N, deficit), ...] start search
    #: m, where IPOPT stopped when a constant preload below it was found feasible (:func:`_polish_constant`)
    ipopt_delta_s: float | None = None

    def to_dict(self) -> dict:
        return asdict(self)

    @property
    def schedule(self) -> Schedule | None:
        return Schedule(tuple(self.knot_angles_deg), tuple(self.knots)) if self.knots else None

    def describe(self) -> str:
        if not self.ok:
            return f"preload study failed: {self.message}"
        what = ("constant preload delta_s*" if len(self.knots) == 1 else
                f"preload schedule ({len(self.knots)} knots), mean delta_s")
        lines = [
            f"{what} = {self.delta_s / MM:.4f} mm (spring force ks*delta_s = {self.spring_force:.3f} N; "
            f"scene: {self.scene_delta_s / MM:.4g} mm)",
        ]
        if len(self.knots) > 1:
            lines.append("  knots: " + ", ".join(f"{a:.1f} deg: {v / MM:.3f} mm"
                                                  for a, v in zip(self.knot_angles_deg, self.knots, strict=True)))
        lines += [
            f"  force deficit int max(0, {self.min_force:g} N - F)^2 dtheta = {self.deficit:.3g} N^2 rad "
            f"(bound {self.deficit_tol:.3g})" + (
                f", excluded: {', '.join(f'{a:g}..{b:g} deg' for a, b in self.exclude_deg)}" if self.exclude_deg else ""),
            *([f"  groove forces: excess int sum max(0, |F| - {self.max_groove_force:g} N)^2 dtheta = "
               f"{self.groove_excess:.3g} N^2 rad (bound {self.deficit_tol:.3g}); largest at the samples "
               f"{self.groove_peak:.4g} N"] if self.max_groove_force is not None else []),
            f"  smallest contact force at the samples: {self.min_measure:.4f} N at {self.min_measure_angle:.1f} deg "
            f"(re-simulation, {self.samples} samples)",
            f"  friction power {self.friction_power:.3f} W vs {self.scene_friction_power:.3f} W at the scene's preload "
            f"({self.friction_power - self.scene_friction_power:+.3f} W)",
            *([f"  IPOPT stopped at {self.ipopt_delta_s / MM:.4f} mm, above the feasible boundary: lowered by "
               "bisection on the re-simulated force deficit (its gradient through the events was inexact)"]
              if self.ipopt_delta_s is not None else []),
            f"  IPOPT: {self.ipopt_status}, {self.ipopt_iterations} iterations, {self.ipopt_time_s:.1f} s "
            f"({self.rounds} round{'s' if self.rounds != 1 else ''}); build {self.build_time_s:.1f} s; "
            f"{self.nodes} shooting nodes, erk rtol {self.rtol:g}",
        ]
        return "\n".join(lines)


def optimise_preload(scene, *, min_force: float = 5.0, exclude=(), knots: int = 1, nodes: int = 4,
                     samples: int | None = None, rtol: float | None = None, objective: str = "friction",
                     deficit_tol: float = DEFICIT_TOL, max_rate: float | None = None, functions=None,
                     max_iter: int = 100, revolutions: int = 3, max_preload: float = 0.1, flags: str = "quick",
                     rounds: int = 3, start: PreloadResult | None = None, verbose: bool = False,
                     ipopt_options: dict | None = None, setup: PreloadSetup | None = None,
                     max_groove_force: float | None = None) -> PreloadResult:
    """The preload design (constant for ``knots = 1``, else a periodic piecewise-linear schedule).

    ``exclude``: crank-angle windows ``(start_deg, end_deg)`` where the force is not required;
    ``samples``: output samples per revolution (default the scene's); ``nodes``: shooting nodes;
    ``max_rate``: bound on |d delta_s / d theta| in m per degree (schedules); ``start``: a previous
    result (e.g. the constant optimum) to start a schedule from; ``max_groove_force`` (N): bound every
    seal-groove contact force between samples too (the excess quadrature within ``deficit_tol``; with a
    ``setup``, its own bound is used). See the module docstring.
    """
    from ...api import model_functions

    _check(knots, nodes, objective, deficit_tol, max_rate, rounds)
    exclude = tuple((float(a), float(b)) for a, b in exclude)
    setup = setup or PreloadSetup(scene, functions or model_functions(scene), float(min_force), exclude, samples,
                                  rtol, revolutions, flags, max_groove_force)
    S = np.lcm(nodes, knots)
    if setup.samples % S:
        raise PreloadStudyError(f"nodes = {nodes}, knots = {knots}: their least common multiple {S} must divide the "
                                f"{setup.samples} samples per revolution")
    if not (isinstance(max_preload, int | float) and max_preload > 0):
        raise PreloadStudyError(f"max_preload = {max_preload!r}: must be a length > 0 m")
    keep = setup.mask(setup.theta_start + setup.dth * np.arange(1, setup.samples + 1))
    if not keep.any():
        raise PreloadStudyError(f"exclude = {list(exclude)}: the windows cover every sample; nothing left to check")
    scene_ds = float(scene.parameter_vector()[_DS])
    res = PreloadResult(False, "", float(min_force), [list(w) for w in exclude], objective=objective,
                        scene_delta_s=scene_ds, deficit_tol=float(deficit_tol), nodes=nodes, samples=setup.samples,
                        rtol=setup.rtol, max_groove_force=setup.max_groove_force)

    # 1. the compiled pieces (cached by content: another min_force, windows or knots reuse them)
    t = time.perf_counter()
    sf = study_functions(setup, setup.samples // S)
    res.build_time_s = time.perf_counter() - t if sf.compile_s > 2.0 else 0.0
    scene_grid = SegmentGrid(setup.samples, int(S), 1, setup.theta_start, setup.dth)  # same segment length
    scene_sim = simulate_schedule(setup, sf, scene_grid, np.array([scene_ds]), min_force, exclude)
    res.scene_friction_power = scene_sim.friction_power
    res.scene_contact_friction_power = contact_powers(setup, scene_sim)
    res.__dict__["scene_simulation"] = scene_sim

    # 2. a start: the constant optimum given, or the smallest feasible constant preload scene's x 1.5^k
    if start is not None and start.ok:
        d0 = float(start.delta_s)
        knots0 = np.array(start.schedule(np.degrees(setup.theta_start) + 360.0 * np.arange(knots) / knots))
    else:
        d0 = _feasible_start(setup, sf, scene_grid, scene_ds, float(max_preload), deficit_tol, res)
        if d0 is None:
            return res
        knots0 = np.full(knots, d0)
    res.start_delta_s = d0
    # the friction power grows with the preload, so a constant optimum lies below the feasible start: bounding
    # the preload there keeps IPOPT's first steps (pushed by the steep deficit in lift-off) from leaping to large
    # preloads (measured: 205 W iterates from a 55 W start); a schedule may rise above its constant start
    upper = min(max_preload, d0 if knots == 1 and start is None else 1.5 * max(knots0))

    # 3. solve, re-simulate, repeat while the re-simulation violates a constraint
    grid0 = SegmentGrid(setup.samples, nodes, knots, setup.theta_start, setup.dth)
    sim = simulate_schedule(setup, sf, grid0, knots0, min_force, exclude)
    x_knots = knots0
    for r in range(rounds):
        res.rounds = r + 1
        nlp = _ShootingNlp(setup, sf, sim, nodes, knots, min_force, exclude, deficit_tol, objective)
        with stage(f"IPOPT (round {r + 1}: {knots} knot{'s' if knots > 1 else ''}, {nodes} shooting nodes, "
                   f"{setup.samples} samples)"):
            ok = nlp.solve(x_knots, res, upper=upper, max_rate=max_rate, max_iter=max_iter,
                           verbose=verbose, ipopt_options=ipopt_options)
        if not ok:
            return res
        x_knots = nlp.knots_m
        sim = _periodic(setup, sf, nlp.grid, x_knots, min_force, exclude)
        if sim.deficit <= deficit_tol * 1.05 and sim.groove_excess <= deficit_tol * 1.05:
            break
        announce(f"re-simulation: deficit {sim.deficit:.3g}, groove excess {sim.groove_excess:.3g} (bound "
                 f"{deficit_tol:.3g}): solving again from the re-simulated revolution")
    else:
        res.message = (f"after {rounds} rounds the re-simulated optimum still violates a bound: force deficit "
                       f"{sim.deficit:.3g}, groove-force excess {sim.groove_excess:.3g} (bound {deficit_tol:.3g} "
                       "N^2 rad): raise rounds, use more samples or a smaller rtol")
        _fill(res, setup, nlp.grid, x_knots, sim)
        res.ok = False
        return res
    if knots == 1:
        x_knots, sim = _polish_constant(setup, sf, nlp.grid, x_knots, sim, min_force, exclude, deficit_tol, res)
    _fill(res, setup, nlp.grid, x_knots, sim)
    res.ok, res.message = True, "solved"
    return res


#: a constant optimum is accepted when this much less preload violates the deficit bound (relative)
POLISH_STEP = 5e-3


def _polish_constant(setup, sf, grid, knots_m, sim, min_force, exclude, deficit_tol, res):
    """Check a constant optimum against its monotone structure, and lower it to the constraint if it can be.

    Both objectives grow with a constant preload (the friction power through the spring force, Eqs. 38-39), so the
    constant optimum is the smallest preload whose re-simulated force deficit is within its bound. When
    ``POLISH_STEP`` less preload is still feasible, IPOPT stopped early: its gradient, forward sensitivities
    through the contact events, can be inexact where events come close together (measured on the default scene
    with linear pressures: 14.1 against 3.7 W/mm by central differences at 0.487 mm). Then the boundary is found
    by bisection on re-simulations (feasible above, infeasible below) to 1e-4 relative, and IPOPT's point is kept
    in ``res.ipopt_delta_s``. Returns the knots and the re-simulation to report."""
    d_hi = float(knots_m[0])
    probe = _periodic(setup, sf, grid, np.array([d_hi * (1 - POLISH_STEP)]), min_force, exclude)
    if probe.deficit > deficit_tol or probe.groove_excess > deficit_tol:
        return knots_m, sim
    with stage(f"IPOPT stopped at {d_hi / MM:.4f} mm with less preload still feasible: bisection to the boundary"):
        best, d_ok, d_lo = probe, d_hi * (1 - POLISH_STEP), None
        d = d_ok
        while d_lo is None and d > 1e-7:  # an infeasible preload below: halve
            d *= 0.5
            trial = _periodic(setup, sf, grid, np.array([d]), min_force, exclude)
            if trial.deficit > deficit_tol or trial.groove_excess > deficit_tol:
                d_lo = d
            else:
                best, d_ok = trial, d
        while d_lo is not None and d_ok - d_lo > 1e-4 * d_ok:
            mid = 0.5 * (d_ok + d_lo)
            trial = _periodic(setup, sf, grid, np.array([mid]), min_force, exclude)
            if trial.deficit > deficit_tol or trial.groove_excess > deficit_tol:
                d_lo = mid
            else:
                best, d_ok = trial, mid
    res.ipopt_delta_s = d_hi
    return np.array([d_ok]), best


#: the re-simulation continues, 2 revolutions at a time (up to 12 in all), until the state at the start of a
#: revolution changes by less than this (scaled state; the metal-contact default scene changed by 2e-4 over its
#: third revolution, the soft-contacts scene by 3e-10)
PERIODIC_TOL = 1e-5


def _periodic(setup, sf, grid, knots_m, min_force, exclude):
    """Re-simulate from the scene's initial state until the revolution is periodic (see PERIODIC_TOL)."""
    return periodic_many(setup, sf, grid, [knots_m], min_force, exclude)[0]


def periodic_many(setup, sf, grid, knots_list, min_force, exclude) -> list:
    """:func:`_periodic` for several schedules at once (:func:`.schedule.simulate_schedules`, on every core): those
    not yet periodic go on together, 2 revolutions at a time."""
    sims = simulate_schedules(setup, sf, grid, knots_list, min_force, exclude)
    done = setup.revolutions
    while done < 12:
        todo = [i for i, sim in enumerate(sims) if sim.change > PERIODIC_TOL]
        if not todo:
            break
        starts = []
        for i in todo:
            z = sims[i].z[:, -1].copy()
            z[6 + setup.n_guards:] = 0.0
            starts.append(z)
        again = simulate_schedules(setup, sf, grid, [knots_list[i] for i in todo], min_force, exclude, revolutions=2,
                                   z_starts=starts)
        for i, sim in zip(todo, again, strict=True):
            sims[i] = sim
        done += 2
    return sims


def _fill(res, setup, grid, knots_m, sim) -> None:
    keep = setup.mask(sim.thetas)
    m = np.where(keep, sim.measure, np.inf)
    j = int(np.argmin(m))
    res.knot_angles_deg = [float(a) % 360.0 for a in grid.knot_angles_deg]
    res.knots = [float(v) for v in knots_m]
    res.delta_s = float(np.mean(Schedule(tuple(res.knot_angles_deg), tuple(res.knots))(
        np.degrees(sim.thetas))))
    res.spring_force = float(setup.pmap.p0[_KS] * res.delta_s)
    res.friction_power = sim.friction_power
    res.deficit = sim.deficit
    res.min_measure, res.min_measure_angle = float(m[j]), float(np.degrees(sim.thetas[j]) % 360.0)
    res.periodic_change = sim.change
    if setup.max_groove_force is not None:
        res.groove_excess, res.groove_peak = sim.groove_excess, sim.groove_peak
    res.contact_friction_power = contact_powers(setup, sim)
    res.__dict__["simulation"] = sim  # not a field: kept for the figures, not written to JSON


def contact_powers(setup, sim) -> dict:
    """Cycle-mean friction power of each contact (W) at the samples of a re-simulated revolution."""
    names = tuple(setup.functions.output_names)
    ng, n = setup.n_guards, sim.thetas.size
    P = setup.pmap.p0[:, None] + setup.pmap.dp[:, None] * sim.delta_s[None, :]
    from .problem import _scale

    X = sim.z[:6, 1:] * _scale(setup.pmap.p0)[:, None]
    Y = np.array(setup.functions.outputs.map(n)(sim.thetas[None, :], X, sim.z[6:6 + ng, 1:], P, sim.pressures))
    return {k[3:]: float(Y[i].mean()) for i, k in enumerate(names) if k.startswith("Pf_") and k != "Pf_total"}


def _check(knots, nodes, objective, deficit_tol, max_rate, rounds) -> None:
    problems = []
    if not (isinstance(nodes, int) and 2 <= nodes <= 64):
        problems.append(f"nodes = {nodes!r}: must be an integer in 2..64")
    if not (isinstance(knots, int) and 1 <= knots <= 72):
        problems.append(f"knots = {knots!r}: must be an integer in 1..72 (1: a constant preload)")
    if objective not in OBJECTIVES:
        problems.append(f"objective = {objective!r}: must be one of {', '.join(OBJECTIVES)}")
    if not (isinstance(deficit_tol, int | float) and 0 < deficit_tol < 1e3):
        problems.append(f"deficit_tol = {deficit_tol!r}: must be in (0, 1000) N^2 rad")
    if max_rate is not None and not (isinstance(max_rate, int | float) and max_rate > 0):
        problems.append(f"max_rate = {max_rate!r}: must be > 0 m per degree (or None: no bound)")
    if not (isinstance(rounds, int) and 1 <= rounds <= 10):
        problems.append(f"rounds = {rounds!r}: must be an integer in 1..10")
    if problems:
        raise PreloadStudyError("; ".join(problems))


def _advice(status: str, groove: bool = False) -> str:
    if status == "Infeasible_Problem_Detected" and groove:
        return ("No preload in the allowed range keeps the force deficit and the groove-force excess within their "
                "bound with a periodic motion: raise max_groove_force (the groove forces between samples can exceed "
                "those at the samples), lower min_force, or try a schedule (--schedule).")
    return {
        "Infeasible_Problem_Detected": "No preload in the allowed range keeps the force deficit within its bound with a "
                                       "periodic motion: lower min_force, exclude the crank-angle windows where the tip "
                                       "lifts off, raise deficit_tol or max_preload.",
        "Maximum_Iterations_Exceeded": "Raise max_iter, or start closer (the start is the feasible simulation).",
        "Restoration_Failed": "The constraints are noisy at the integrator's tolerance: use a smaller rtol.",
        "Error_In_Step_Computation": "The constraints are noisy at the integrator's tolerance: use a smaller rtol.",
    }.get(status, "See IPOPT's documentation of this status.")


def _feasible_start(setup, sf, grid, scene_ds: float, max_preload: float, deficit_tol: float, res: PreloadResult):
    """The smallest scene_ds * 1.5^k (k >= 0, up to max_preload) whose periodic revolution keeps the force deficit
    within its bound (re-simulations from the scene's initial state)."""
    base = scene_ds if scene_ds > 0 else MM
    batch = parallel_threads(60)  # candidates simulated together, a thread per core; the first passing one is kept
    with stage("searching a feasible constant start (scene's preload x 1.5^k)"):
        for k0 in range(0, 60, batch):
            ds = [min(base * 1.5**k, max_preload) for k in range(k0, min(k0 + batch, 60))]
            ds = ds[:next((i + 1 for i, d in enumerate(ds) if d >= max_preload), len(ds))]
            for d, sim in zip(ds, simulate_schedules(setup, sf, grid, [np.array([d]) for d in ds], setup.min_force,
                                                     setup.exclude), strict=True):
                keep = setup.mask(sim.thetas)
                j = int(np.argmin(np.where(keep, sim.measure, np.inf)))
                res.history.append((float(d), float(sim.measure[j]), float(sim.deficit)))
                if sim.deficit <= deficit_tol:
                    return d
            if ds[-1] >= max_preload:
                break
    res.message = (f"infeasible: no constant preload up to max_preload = {max_preload / MM:g} mm keeps the contact "
                   f"force >= {setup.min_force:g} N between samples: at {d / MM:.4g} mm the force deficit is "
                   f"{sim.deficit:.3g} N^2 rad (bound {deficit_tol:.3g}); the smallest force at the samples is "
                   f"{sim.measure[j]:.3g} N at crank angle {np.degrees(sim.thetas[j]) % 360:.1f} deg (negative: the "
                   f"tip lifts off there, by {-sim.measure[j] / setup.pmap.p0[KW] * 1e6:.3g} um). Exclude a window "
                   "around that angle (exclude=[(start, end)] / --exclude START:END), lower min_force, or raise "
                   "max_preload.")
    return None


class _Progress(ca.Callback):
    """IPOPT's iterations as progress lines (objective, constraint violation)."""

    def __init__(self, nx: int, ng: int, n_def: int, groove: bool = False):
        ca.Callback.__init__(self)
        self.nx, self.ng, self.k, self.n_def, self.groove = nx, ng, 0, n_def, groove
        self.construct("preload_progress", {})

    def get_n_in(self):
        return ca.nlpsol_n_out()

    def get_n_out(self):
        return 1

    def get_name_in(self, i):
        return ca.nlpsol_out(i)

    def get_name_out(self, i):
        return "ret"

    def get_sparsity_in(self, i):
        n = ca.nlpsol_out(i)
        if n in ("f",):
            return ca.Sparsity.dense(1)
        if n in ("lam_p",):
            return ca.Sparsity.dense(0)
        if n in ("g", "lam_g"):
            return ca.Sparsity.dense(self.ng)
        return ca.Sparsity.dense(self.nx)

    def eval(self, arg):
        self.k += 1
        g = np.array(arg[2]).ravel()
        groove = f", groove-force excess {g[self.n_def + 1]:.3g} x its bound" if self.groove else ""
        announce(f"  IPOPT iteration {self.k}: objective {float(arg[1]):.6g}, force deficit {g[self.n_def]:.3g} x its "
                 f"bound{groove}, largest node defect {np.abs(g[:self.n_def]).max():.2g}")
        return [0]


class _ShootingNlp:
    """The multiple-shooting NLP with a hand-assembled Jacobian (see the module docstring)."""

    def __init__(self, setup, sf, sim, nodes, knots, min_force, exclude, deficit_tol, objective):
        self.setup, self.N, self.K = setup, nodes, knots
        n, ng = setup.samples, setup.n_guards
        Z0 = sim.z  # (n_z, n + 1) from the first node of the previous grid
        first = float(sim.thetas[0] - setup.dth)
        act0 = Z0[6:6 + ng]
        offset = _node_offset(act0, nodes, n // nodes)
        self.grid = SegmentGrid(n, nodes, knots, first + setup.dth * offset, setup.dth)
        g = self.grid
        idx = (offset + (n // nodes) * np.arange(nodes)) % n  # columns of Z0 at the new nodes
        self.S = np.maximum(1.0, np.max(np.abs(Z0[:6]), axis=1))
        S = self.S
        nz = Z0.shape[0]
        self.nz = nz
        per = g.per_node
        U = setup.controls(g.edges(), g.m)  # (4, n): each segment's call from its start
        omega = float(setup.pmap.p0[PARAMETER_NAMES.index("omega")])
        sc = state_scale(omega)
        nd = -(-(6 + knots) // CHUNK) * CHUNK  # the directions, padded to whole chunks
        self.nd = nd
        self.deficit_tol, self.objective = float(deficit_tol), objective

        V = ca.MX.sym("V", knots + 6 * nodes)
        kn = V[:knots] * MM
        W = ca.reshape(V[knots:], 6, nodes)
        Z = W * ca.repmat(ca.DM(S), 1, nodes)
        Q = g.q_columns(setup, kn, min_force, exclude)  # (n_q, S)
        node_seg = [k * per for k in range(nodes)]
        act = []
        for k in range(nodes):
            p_k = Q[:setup.pmap.p0.size, node_seg[k]]
            X_k = Z[:, k] * ca.DM(sc)
            act.append(setup.functions.guards(g.psi[node_seg[k]], X_k, p_k, ca.DM(U[:2, node_seg[k] * g.m])) < 0)
        x0 = ca.vertcat(Z, ca.horzcat(*act), ca.MX.zeros(ng, nodes))
        nq = Q.size1()
        Un = ca.DM(U)  # node k takes the columns of its segments, in order
        nominal = chain_function(sf, g, nz, derivatives=False)
        Fn = nominal.map(nodes, "thread", parallel_threads(nodes))
        Qcols = Q
        zend, qs, _ = Fn(x0, Qcols, Un)
        nxt = ca.horzcat(*[Z[:, (k + 1) % nodes] for k in range(nodes)])
        defects = ca.vec((zend[:6, :] - nxt) / ca.repmat(ca.DM(S), 1, nodes))
        deficit = ca.sum2(qs[1, :]) / self.deficit_tol
        power = ca.sum2(qs[0, :]) / TWO_PI
        obj = power if objective == "friction" else ca.sum1(V[:knots]) / knots
        self.groove = sf.groove
        groove = [ca.sum2(qs[2, :]) / self.deficit_tol] if sf.groove else []  # the groove-force excess
        G_out = ca.vertcat(defects, deficit, *groove, obj)

        # the Jacobian, from the compiled forward derivative (seeds: node states, knot values)
        full = chain_function(sf, g, nz, derivatives=True, nd=nd)
        Ff = full.map(nodes, "thread", parallel_threads(nodes))
        seed_z = np.zeros((nz, nd))
        seed_z[:6, :6] = np.diag(S)
        L = setup.pmap.p0.size
        sl = L + 1  # the slope row of q
        seeds_q = []
        for k in range(nodes):
            for j in range(per):
                s = k * per + j
                blk = np.zeros((nq, nd))
                for i in range(knots):
                    blk[:L, 6 + i] = setup.pmap.dp * MM * g.Lseg[s, i]
                    blk[sl, 6 + i] = MM * g.Mseg[s, i]
                seeds_q.append(blk)
        dQ = ca.DM(np.concatenate(seeds_q, axis=1))  # (n_q, S nd), node-major
        _, _, dz, dq = Ff(x0, Qcols, Un, ca.DM(np.tile(seed_z, (1, nodes))), dQ)
        rows = []
        for k in range(nodes):
            Dk = dz[:6, k * nd:k * nd + 6 + knots] / ca.repmat(ca.DM(S), 1, 6 + knots)
            blocks = [Dk[:, 6:]]
            for j in range(nodes):
                if j == k:
                    blocks.append(Dk[:, :6])
                elif j == (k + 1) % nodes:
                    blocks.append(-ca.DM.eye(6))
                else:
                    blocks.append(ca.DM.zeros(6, 6))
            rows.append(ca.horzcat(*blocks))
        dqk = [dq[:, k * nd:k * nd + 6 + knots] for k in range(nodes)]
        dsum = sum(d[:, 6:] for d in dqk)
        row_def = ca.horzcat(dsum[1, :], *[d[1, :6] for d in dqk]) / self.deficit_tol
        row_groove = [ca.horzcat(dsum[2, :], *[d[2, :6] for d in dqk]) / self.deficit_tol] if sf.groove else []
        if objective == "friction":
            row_obj = ca.horzcat(dsum[0, :], *[d[0, :6] for d in dqk]) / TWO_PI
        else:
            row_obj = ca.DM(np.r_[np.full(knots, 1.0 / knots), np.zeros(6 * nodes)]).T
        J = ca.vertcat(*rows, row_def, *row_groove, row_obj)
        Vj, Oj = ca.MX.sym("V", V.numel()), ca.MX.sym("out", G_out.numel())
        jac = ca.Function("jac_preload_g", [Vj, Oj], [ca.substitute(J, V, Vj)])
        self.G = ca.Function("preload_g", [V], [G_out], {"custom_jacobian": jac, "jac_penalty": 0,
                                                          "never_inline": True})
        self.nominal = ca.Function("preload_nominal", [V], [zend, qs])
        self.n_def = 6 * nodes
        self.n_con = self.n_def + 1 + len(groove)  # defects, deficit (, groove excess): the objective follows
        W0 = Z0[:6, idx] / S[:, None]
        self.W0 = W0.ravel(order="F")
        self.V = V

    def solve(self, knots0_m, res, *, upper, max_rate, max_iter, verbose, ipopt_options) -> bool:
        K, N = self.K, self.N
        V = ca.MX.sym("V", K + 6 * N)
        out = self.G(V)
        g = [out[:self.n_con]]
        lbg = list(np.zeros(self.n_def)) + [-np.inf] * (self.n_con - self.n_def)
        ubg = list(np.zeros(self.n_def)) + [1.0] * (self.n_con - self.n_def)
        if K > 1 and max_rate is not None:
            span_deg = 360.0 / K
            diffs = ca.vertcat(*[V[(i + 1) % K] - V[i] for i in range(K)])
            g.append(diffs)
            lim = max_rate / MM * span_deg
            lbg += [-lim] * K
            ubg += [lim] * K
        prog = _Progress(V.numel(), int(sum(gi.numel() for gi in g)), self.n_def, self.groove)
        opts = {"ipopt.hessian_approximation": "limited-memory", "ipopt.tol": 1e-3, "ipopt.constr_viol_tol": 1e-3,
                "ipopt.acceptable_tol": 1e10, "ipopt.acceptable_constr_viol_tol": 2e-2, "ipopt.acceptable_iter": 3,
                "ipopt.acceptable_obj_change_tol": 1e-4,
                "ipopt.max_iter": int(max_iter), "ipopt.linear_solver": "mumps",
                "ipopt.print_level": 5 if verbose else 0, "print_time": False, "ipopt.sb": "yes",
                "iteration_callback": prog,
                **{f"ipopt.{k}": v for k, v in (ipopt_options or {}).items()}}
        t = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            solver = ca.nlpsol("preload", "ipopt", {"x": V, "f": out[-1], "g": ca.vertcat(*g)}, opts)
            lbx = np.r_[np.zeros(K), np.full(6 * N, -np.inf)]
            ubx = np.r_[np.full(K, upper / MM), np.full(6 * N, np.inf)]
            x0 = np.r_[np.asarray(knots0_m) / MM, self.W0]
            try:
                sol = solver(x0=x0, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg)
            except RuntimeError as err:
                res.ipopt_time_s += time.perf_counter() - t
                res.message = (f"IPOPT stopped with an error in the constraint evaluation ({err}); the shooting "
                               "integrator failed at an iterate (a step or event limit): try more nodes or a larger rtol")
                return False
        res.ipopt_time_s += time.perf_counter() - t
        st = solver.stats()
        res.ipopt_status, res.ipopt_iterations = str(st["return_status"]), res.ipopt_iterations + int(st["iter_count"])
        v = np.array(sol["x"]).ravel()
        gv = np.array(sol["g"]).ravel()
        res.max_defect = float(np.max(np.abs(gv[:self.n_def])))
        self.knots_m = v[:K] * MM
        qs = np.array(self.nominal(v)[1])
        res.nlp_friction_power = float(qs[0].sum() / TWO_PI)
        if res.ipopt_status not in SOLVED:
            groove = f", groove-force excess {gv[self.n_def + 1]:.3g} x its bound" if self.groove else ""
            res.message = (f"IPOPT returned {res.ipopt_status} after {res.ipopt_iterations} iterations at knots "
                           f"{', '.join(f'{x:.4g}' for x in v[:K])} mm; force deficit {gv[self.n_def]:.3g} x its bound"
                           f"{groove}, largest node defect {res.max_defect:.3g}. "
                           + _advice(res.ipopt_status, self.groove))
            return False
        return True


def _node_offset(act: np.ndarray, nodes: int, m: int) -> int:
    """The offset (in samples) of the node grid that keeps nodes farthest from every contact switch."""
    n = act.shape[1] - 1
    switches = np.nonzero(np.any(np.abs(np.diff(act, axis=1)) > 0.5, axis=0))[0]  # between sample j and j + 1
    if not switches.size:
        return 0
    best, best_d = 0, -1
    for o in range(m):
        nodes_at = (o + m * np.arange(nodes)) % n
        dist = np.abs(nodes_at[:, None] - switches[None, :] - 0.5)
        dist = np.minimum(dist, n - dist).min()
        if dist > best_d:
            best, best_d = o, dist
    return best
