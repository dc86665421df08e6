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
* **Decision variables**: the knot values in mm and the scaled continuous states (the hybrid state's ``x``
  part, generated/layout.py: the seal's six) at ``nodes`` shooting nodes, each divided by the largest
  magnitude that component reaches on the start trajectory.
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
* **A start without gradient**: where the start's force deficit (and groove-force excess) is 0, so is its
  gradient, and IPOPT's first step follows the objective alone. Where IPOPT then ends at its iteration limit, or
  stays beyond the bounded filter's reach for nlp.STUCK_ITERATIONS iterations in a row (the lift-off scene: its
  first step landed deep in lift-off, which IPOPT's filter accepted, and it stayed there), it is solved again
  from the same start with its filter bounded (no iterate whose constraint violation exceeds 10,
  nlp.THETA_MAX_FACT), which shortens that step (``_solve_with_the_filter_bounded``).
* **Tolerances**: IPOPT's tol and constr_viol_tol 1e-3; the constraint function is noisy at the erk
  rtol (the rattle's impacts), so IPOPT also stops ("acceptable") once the objective changes by less
  than 1e-4 relative over 3 iterations with the constraints within 2e-2 of their bounds (the deficit
  within 2 % of its bound). IPOPT with MUMPS and the limited-memory Hessian.
"""

from __future__ import annotations

import time

import numpy as np

from ....cores import parallel_threads
from ....progress import announce, stage
from ....signals import StopSignals
from ...scenes.errors import show_repr
from .advice import ROBUST_STEPS, shortfall_kind, spring_capacity
from .nlp import STUCK_ITERATIONS, THETA_MAX_FACT, ShootingNlp
from .options import DEFAULTS, UNITS
from .periodic import periodic, periodic_many
from .problem import (
    MAX_FORCE,
    MAX_PRELOAD,
    MM,
    PreloadSetup,
    PreloadStudyError,
    check_grid,
    max_rate_of,
    max_rate_unbinding,
    option_problems,
    quantity_of,
    study_quantities,
    windows,
)
from .result import (
    ALLOWANCE,
    DEFICIT_TOL,
    PreloadResult,
    contact_powers,
    deficit_span,
    fill_result,
    knot_angles,
    squares_text,
)
from .schedule import SegmentGrid, simulate_schedule, simulate_schedules
from .shooting import study_functions


def check_option(name: str, value, knots: int | None = None):
    """One option of :func:`optimise_preload` (``min_force``, ``max_groove_force``, ``max_preload``, ``max_rate``,
    ``knots``, ``nodes``, ``samples``, ``max_iter``, ``objective``, ``deficit_tol``, ``rounds``) converted as the
    study converts it (quantities to N and m) and checked as it checks it: the value, or a
    :class:`PreloadStudyError` with the study's own message (the option, its value, the allowed range). What the
    command line checks its options with, so that both say the same; ``knots``: the schedule's, for ``max_rate``."""
    given = value
    if name in ("min_force", "max_groove_force", "max_preload"):
        value = quantity_of(name, value, UNITS[name], MAX_PRELOAD if name == "max_preload" else MAX_FORCE)
    elif name == "max_rate":
        value = max_rate_of(value)
    if problem := option_problems(**{name: value}, **({"knots": knots} if name == "max_rate" else {})).get(name):
        if isinstance(given, str) and not isinstance(value, str):  # as given ("-1 mm/deg"), then as checked
            shown = show_repr(value)
            problem = problem.replace(f"{name} = {shown}", f"{name} = {given!r} (= {shown} in SI units)", 1)
        raise PreloadStudyError(problem)
    return value


def _kept_on_interrupt(study):
    """``study`` (which appends its result to ``_holder`` as soon as it makes one) as a library call: a Ctrl-C,
    SIGTERM or SIGHUP abandons its stage in progress (IPOPT's iterations included) and the result as far as it got
    is returned, marked stopped; then :func:`~apexseal.runtime.api.after_an_interrupt` (in a script a Ctrl-C
    raises :class:`~apexseal.signals.RunInterrupted` carrying it, a SIGTERM ends the process). Under a command's own
    signal handling (the command line's report) the interruption is the command's."""
    import functools
    import inspect

    @functools.wraps(study)
    def call(*args, **kwargs):
        from ...api import after_an_interrupt

        holder: list[PreloadResult] = []
        stop = StopSignals(raising=True, redeliver_term=True)
        with stop as signals:
            try:
                res = study(*args, _holder=holder, **kwargs)
            except BaseException as err:  # the interruption, or the CasADi error it became inside a call (signals.py)
                if signals is not stop and signals.requested and holder:
                    # under a command's own signal handling: what the study holds goes with the interruption, for
                    # the command's report (a re-simulated solution, IPOPT's answer, its best feasible iterate, or
                    # nothing solved: PreloadResult.has_answer)
                    err.preload_result = _stopped(holder[0], signals)
                if signals is not stop or not stop.requested or not holder:
                    raise
                res = _stopped(holder[0], stop)
            finally:
                stop.raising = False  # a further signal while the result is reported is only noted
            got = ("a solution" if res.knots is not None else "IPOPT's answer, not re-simulated" if res.ipopt_knots
                   else "IPOPT's best feasible iterate, not optimal" if res.best_feasible else "none solved")
            kept = f"the study's result so far ({got}), returned in memory"
            return after_an_interrupt(res, stop, signals, stop.requested, "the preload study", kept,
                                      "its result so far, in memory only, lost with the process "
                                      "(apexseal.save_preload_report writes its report; the command line, "
                                      "apexseal optimise-preload, writes it as it goes)")

    sig = inspect.signature(study)
    call.__signature__ = sig.replace(parameters=[p for n, p in sig.parameters.items() if n != "_holder"])
    return call


def _stopped(res: PreloadResult, signals) -> PreloadResult:
    """``res`` marked as stopped by the signal ``signals`` noted, saying what it keeps."""
    res.ok, res.interrupted_by = False, signals.sender()
    res.message = f"interrupted by {res.interrupted_by} before the study ended: {_what_is_kept(res)}"
    return res


def _what_is_kept(res: PreloadResult) -> str:
    """What a study interrupted before it ended keeps: its last re-simulated solution, IPOPT's answer before its
    re-simulation ended (``ipopt_knots``), the best feasible iterate IPOPT had visited when the signal stopped its
    iterations (``best_feasible``: not optimal, not re-simulated, which a signal would stop too), or nothing."""
    if res.knots is not None:
        return "the last solution found is kept"
    if res.ipopt_knots:
        return ("IPOPT's answer is kept, not re-simulated (ipopt_knots: "
                + ", ".join(f"{v / MM:.4f}" for v in res.ipopt_knots) + " mm; the force between the samples is "
                "not checked there: run the study again, or start from it)")
    if (best := res.best_feasible) is not None:
        value = (f"friction power {best['objective']:.6g} W" if res.objective == "friction" else
                 f"mean preload {best['objective']:.6g} mm")
        return ("IPOPT's best feasible iterate so far is kept, NOT OPTIMAL and not re-simulated (best_feasible: "
                f"iteration {best['iteration']}, knots " + ", ".join(f"{v / MM:.4f}" for v in best["knots"])
                + f" mm, {value}, force deficit {squares_text(best['deficit'])} N^2 rad, largest node defect "
                f"{best['max_defect']:.2g}, as the NLP has them; the force between the samples is not checked there: "
                "run the study again, or start from it)")
    return "nothing solved yet"


@_kept_on_interrupt
def optimise_preload(scene, *, min_force: float = DEFAULTS["min_force"], exclude=(), knots: int = 1,
                     nodes: int = DEFAULTS["nodes"], samples: int | None = None, rtol: float | None = None,
                     objective: str = DEFAULTS["objective"], deficit_tol: float = DEFICIT_TOL,
                     max_rate: float | None = None, functions=None, max_iter: int = DEFAULTS["max_iter"],
                     revolutions: int = 3, max_preload: float = DEFAULTS["max_preload"], flags: str = "quick",
                     rounds: int = 3, start: PreloadResult | None = None, verbose: bool = False,
                     ipopt_options: dict | None = None, setup: PreloadSetup | None = None,
                     max_groove_force: float | None = None, _holder: list | None = None) -> PreloadResult:
    """The preload design (constant for ``knots = 1``, else a periodic piecewise-linear schedule).

    ``exclude``: crank-angle windows ``(start_deg, end_deg)`` where the force is not required;
    ``samples``: output samples per revolution (default the scene's); ``nodes``: shooting nodes;
    ``max_rate``: bound on |d delta_s / d theta| in m per degree, or a quantity ("0.01 mm/deg"; schedules only);
    ``start``: a previous result (e.g. the constant optimum) to start a schedule from; ``max_groove_force`` (N): bound every
    seal-groove contact force between samples too (the excess quadrature within ``deficit_tol``; with a
    ``setup``, its own bound is used). See the module docstring.

    A Ctrl-C (or SIGTERM) abandons the stage in progress, IPOPT's iterations included; in a script
    :class:`~apexseal.signals.RunInterrupted` then carries the result as far as it got (``ok`` False, ``message``
    saying so), in an interactive session it is returned with a warning, and a SIGTERM ends the process.
    """
    from ...api import model_functions, scene_of

    scene = scene_of(scene)
    for name, given in (("min_force", min_force), ("max_groove_force", max_groove_force),
                        ("max_preload", max_preload), ("max_rate", max_rate)):
        if isinstance(given, str):  # a quantity's text: refused naming it as given, as the command line does
            check_option(name, given, knots=knots)
    min_force, max_groove_force, max_preload = study_quantities(min_force, max_groove_force, max_preload)
    max_rate = max_rate_of(max_rate)
    _check(knots, nodes, objective, deficit_tol, max_rate, rounds, min_force, max_iter, max_preload, start)
    knots, nodes = int(knots), int(nodes)
    if unbound := max_rate_unbinding(max_rate, knots, max_preload):
        import warnings

        from ....stacklevel import user_stacklevel

        warnings.warn(unbound, UserWarning, stacklevel=user_stacklevel())
    exclude = windows(exclude)
    setup = setup or PreloadSetup(scene, functions or model_functions(scene), float(min_force), exclude, samples,
                                  rtol, revolutions, flags, max_groove_force)
    S = check_grid(setup.samples, nodes, knots)
    keep = setup.mask(setup.theta_start + setup.dth * np.arange(1, setup.samples + 1))
    if not keep.any():
        raise PreloadStudyError(f"exclude = {list(exclude)}: the windows cover every sample; nothing left to check")
    scene_ds = float(scene.parameters["delta_s"])
    grid0 = SegmentGrid(setup.samples, nodes, knots, setup.theta_start, setup.dth)
    res = PreloadResult(False, "", float(min_force), [list(w) for w in exclude], objective=objective,
                        knot_angles_deg=knot_angles(grid0),
                        scene_delta_s=scene_ds, deficit_tol=float(deficit_tol), nodes=nodes, samples=setup.samples,
                        revolutions=setup.revolutions,
                        rtol=setup.rtol, max_groove_force=setup.max_groove_force)
    res.__dict__["scene"] = scene  # for the report (save_preload_report)
    if _holder is not None:  # what an interruption from here on returns (_kept_on_interrupt)
        _holder.append(res)

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
    sim = simulate_schedule(setup, sf, grid0, knots0, min_force, exclude)
    x_knots = knots0
    for r in range(rounds):
        res.rounds = r + 1
        # a round's NLP starts from the re-simulation of the last one's answer, which violated a bound: neither
        # that answer nor the feasible iterates of that NLP are an answer any longer
        res.ipopt_knots, res.best_feasible = None, None
        nlp = ShootingNlp(setup, sf, sim, nodes, knots, min_force, exclude, deficit_tol, objective)
        with stage(f"IPOPT (round {r + 1}: {knots} knot{'s' if knots > 1 else ''}, {nodes} shooting nodes, "
                   f"{setup.samples} samples)"):
            gradless = sim.deficit == sim.groove_excess == 0
            ok = nlp.solve(x_knots, res, upper=upper, max_rate=max_rate, max_iter=max_iter,
                           verbose=verbose, ipopt_options=ipopt_options, give_up=gradless)
            # IPOPT turns an interruption in its callbacks into a return status: under the CLI's StopSignals the
            # signal it caught abandons the stage here (logged "abandoned", not "done"), and the study with it
            StopSignals.raise_pending()
            if not ok and gradless and (nlp.gave_up or res.ipopt_status == "Maximum_Iterations_Exceeded"):
                ok = _solve_with_the_filter_bounded(nlp, x_knots, res, upper=upper, max_rate=max_rate,
                                                    max_iter=max_iter, verbose=verbose, ipopt_options=ipopt_options)
        if not ok:
            return res
        x_knots = nlp.knots_m
        res.ipopt_knots = [float(v) for v in x_knots]  # kept if a signal stops the re-simulation
        sim = periodic(setup, sf, nlp.grid, x_knots, min_force, exclude)
        if sim.deficit <= deficit_tol * ALLOWANCE and sim.groove_excess <= deficit_tol * ALLOWANCE:
            break
        announce(f"re-simulation: deficit {squares_text(sim.deficit)}, groove excess "
                 f"{squares_text(sim.groove_excess)} (bound {deficit_tol:.3g}): solving again from the re-simulated "
                 "revolution")
    else:
        res.message = (f"after {rounds} rounds the re-simulated optimum still violates a bound: force deficit "
                       f"{squares_text(sim.deficit)}, groove-force excess {squares_text(sim.groove_excess)} (bound "
                       f"{deficit_tol:.3g} N^2 rad): raise rounds, use more samples or a smaller rtol")
        fill_result(res, setup, nlp.grid, x_knots, sim)
        res.ok = False
        return res
    if knots == 1:
        x_knots, sim = _polish_constant(setup, sf, nlp.grid, x_knots, sim, min_force, exclude, deficit_tol, res)
    fill_result(res, setup, nlp.grid, x_knots, sim)
    res.ok, res.message = True, "solved"
    return res


def _solve_with_the_filter_bounded(nlp, x_knots, res, **solve) -> bool:
    """Solve ``nlp`` again from its start with IPOPT's filter bounded (nlp.THETA_MAX_FACT): IPOPT ended at its
    iteration limit from a start where the force deficit (and the groove-force excess) is 0, and so is its gradient.
    Its first step then follows the objective alone, and IPOPT's filter, which by default accepts constraint
    violations up to 1e4, let it land deep in lift-off (the lift-off scene: 6980 x the deficit bound), where it
    stayed. Bounded, the line search shortens that step. Not the first solve: a long first step can also cross an
    infeasible band to a better optimum (the small study's scene at a 0.1 N minimum: no preload at all, across a
    lift-off band at 0.02-0.09 mm; bounded, IPOPT stops above the band at 0.095 mm, measured). Where this solve
    fails too, the first one's message is kept, and this one's status added to it."""
    first, before = res.message, res.ipopt_iterations
    how = (f"stayed above {THETA_MAX_FACT:g} x the bound for {STUCK_ITERATIONS} iterations" if nlp.gave_up else
           "ended at its iteration limit")
    announce(f"IPOPT {how} from a start where the force deficit and its gradient are 0: "
             f"solving again from that start with its filter bounded (theta_max_fact {THETA_MAX_FACT:g})")
    options = {"theta_max_fact": THETA_MAX_FACT} | (solve.pop("ipopt_options") or {})
    ok = nlp.solve(x_knots, res, ipopt_options=options, **solve)
    StopSignals.raise_pending()
    res.filter_bounded = True
    if not ok:
        res.message = (f"{first} Solved again from the start with IPOPT's filter bounded (theta_max_fact "
                       f"{THETA_MAX_FACT:g}): {res.ipopt_status} after {res.ipopt_iterations - before} iterations.")
    return ok


#: a constant optimum is accepted when this much less preload violates the deficit bound (relative)
POLISH_STEP = 5e-3


def _polish_constant(setup, sf, grid, knots_m, sim, min_force, exclude, deficit_tol, res):
    """Check a constant optimum against its monotone structure, lower it to the constraint or bound that holds it
    if it can be, and record which one does in ``res.active``.

    Both objectives grow with a constant preload (the friction power through the spring force, Eqs. 38-39), so the
    constant optimum is the smallest preload whose re-simulation meets every constraint: the boundary of the force
    deficit ("deficit") or of the groove-force excess ("groove") that ``POLISH_STEP`` less preload violates, or
    the bound delta_s >= 0 ("zero") where no preload is needed. When ``POLISH_STEP`` less preload is still
    feasible, IPOPT stopped early: its gradient, forward sensitivities through the contact events, can be inexact
    where events come close together (measured on the default scene with linear pressures: 14.1 against 3.7 W/mm
    by central differences at 0.487 mm). Then the preload is halved until a re-simulation violates a constraint
    and the boundary found by bisection (feasible above, infeasible below) to 1e-4 relative; where every halving
    down to 1e-7 m is feasible and so is no preload at all, the optimum is the bound (no bisection runs). IPOPT's
    point is kept in ``res.ipopt_delta_s``. Returns the knots and the re-simulation to report."""

    def run(d):
        return periodic(setup, sf, grid, np.array([d]), min_force, exclude)

    def broken(s) -> str:  # the constraint a re-simulation violates ("" for none)
        return "deficit" if s.deficit > deficit_tol else "groove" if s.groove_excess > deficit_tol else ""

    d_hi = float(knots_m[0])
    if d_hi <= 0.0:  # IPOPT on the bound itself
        res.active = "zero"
        return knots_m, sim
    probe = run(d_hi * (1 - POLISH_STEP))
    if broken(probe):
        res.active = broken(probe)
        _check_robust(setup, sf, grid, d_hi, min_force, exclude, broken, res)
        return knots_m, sim
    with stage(f"IPOPT stopped at {d_hi / MM:.4f} mm with less preload still feasible: lowering it to the boundary "
               "of a constraint, or to delta_s = 0"):
        best, d_ok, d_lo = probe, d_hi * (1 - POLISH_STEP), None
        d = d_ok
        while d_lo is None and d > 1e-7:  # an infeasible preload below: halve
            d *= 0.5
            trial = run(d)
            if broken(trial):
                d_lo, res.active = d, broken(trial)
            else:
                best, d_ok = trial, d
        if d_lo is None:  # feasible down to 0.1 um: does the seal need a preload at all?
            zero = run(0.0)
            if broken(zero):
                d_lo, res.active = 0.0, broken(zero)
            else:
                best, d_ok, res.active = zero, 0.0, "zero"
        while d_lo is not None and d_ok - d_lo > max(1e-4 * d_ok, 1e-12):  # bisection to the boundary
            mid = 0.5 * (d_ok + d_lo)
            trial = run(mid)
            if broken(trial):
                d_lo, res.active = mid, broken(trial)
            else:
                best, d_ok = trial, mid
    res.ipopt_delta_s = d_hi
    if res.active != "zero":
        _check_robust(setup, sf, grid, d_ok, min_force, exclude, broken, res)
    return np.array([d_ok]), best


def _check_robust(setup, sf, grid, d, min_force, exclude, broken, res) -> None:
    """Re-simulate the preloads advice.ROBUST_STEPS above a constant optimum ``d`` held by a bound (together, on
    every core) and record in ``res.robust`` whether they all meet every constraint. The optimum is the smallest
    feasible preload only where the feasible set is monotone in the preload; where the ringing after a chamber
    switch is checked (an excluded window too short at that speed), feasible preloads can be isolated pockets: at
    3000 rpm with ks = 1e4 N/m and a 10 deg window the optimum was 2.9338 mm, with 2.9337 mm and 3.0 mm failing. A spring
    cannot be made to such a pocket, so the report says so (:func:`.advice.robustness`)."""
    ds = [d * (1 + step) for step in ROBUST_STEPS]
    sims = periodic_many(setup, sf, grid, [np.array([x]) for x in ds], min_force, exclude)
    res.robust_probes = [[float(x), not broken(s), float(s.deficit), _where(s, setup)]
                         for x, s in zip(ds, sims, strict=True)]
    res.robust = all(p[1] for p in res.robust_probes)


def _where(sim, setup) -> list:
    """[start, end] deg where a re-simulation's force deficit builds up (:func:`.result.deficit_span`), else where its
    smallest force at the samples is ([angle, angle])."""
    span = deficit_span(sim.thetas, sim.deficit_at, setup.dth)
    if span is not None:
        return [span[0], span[1]]
    angle = setup.smallest(sim)[1]
    return [angle, angle]


def _check(knots, nodes, objective, deficit_tol, max_rate, rounds, min_force, max_iter, max_preload, start) -> None:
    problems = list(option_problems(nodes=nodes, knots=knots, min_force=min_force, max_iter=max_iter,
                                     objective=objective, deficit_tol=deficit_tol, max_rate=max_rate, rounds=rounds,
                                     max_preload=max_preload).values())
    if start is not None and not isinstance(start, PreloadResult):
        problems.append(f"start = {start!r}: must be a PreloadResult (the constant optimum to start a schedule "
                        "from), or None")
    if problems:
        raise PreloadStudyError("; ".join(problems))


def _feasible_start(setup, sf, grid, scene_ds: float, max_preload: float, deficit_tol: float, res: PreloadResult):
    """The smallest scene_ds * 1.5^k (k >= 0, up to max_preload) whose periodic revolution keeps the force deficit
    within its bound, and the groove-force excess too where the study bounds the groove forces (re-simulations from
    the scene's initial state). A start that met the deficit but not the groove bound was taken before, and IPOPT
    then spent its iterations on a bound no preload met (29 at 10.5 N on the small study, docs/preload.md)."""
    base = scene_ds if scene_ds > 0 else MM
    batch = parallel_threads(60)  # candidates simulated together, a thread per core; the first passing one is kept
    below = 0.0  # the largest preload tried that did not keep the force (0: none)

    def tried(ds):
        return simulate_schedules(setup, sf, grid, [np.array([d]) for d in ds], setup.min_force, setup.exclude)

    with stage("searching a feasible constant start (scene's preload x 1.5^k)"):
        for k0 in range(0, 60, batch):
            ds = [min(base * 1.5**k, max_preload) for k in range(k0, min(k0 + batch, 60))]
            ds = ds[:next((i + 1 for i, d in enumerate(ds) if d >= max_preload), len(ds))]
            for d, sim in zip(ds, tried(ds), strict=True):
                force, angle = setup.smallest(sim)
                res.history.append((float(d), force, float(sim.deficit)))
                if sim.deficit <= deficit_tol:
                    if sim.groove_excess <= deficit_tol:
                        return d
                    # the force is kept but a groove force exceeds its bound: the groove forces grow with the
                    # preload, so the best chance is the least preload that keeps the force, between the last
                    # preload that did not and this one (bisected to 1 %)
                    return _least_groove_start(setup, tried, below, float(d), sim, deficit_tol, res)
                below = float(d)
            if ds[-1] >= max_preload:
                break
    # the measure is kw xs5 < 0 while the tip is off the housing (problem.py): a lift-off only where it is negative
    where = (f"the tip lifts off there, by {-force / setup.pmap.at('kw') * 1e6:.3g} um" if force < 0 else
             f"the tip presses on the housing there, with less than the {setup.min_force:g} N asked"
             if force < setup.min_force else "at least the force asked at every sample: the deficit lies between them")
    res.message = (f"infeasible: no constant preload up to max_preload = {max_preload / MM:g} mm keeps the contact "
                   f"force >= {setup.min_force:g} N between samples: at {d / MM:.4g} mm the force deficit is "
                   f"{sim.deficit:.3g} N^2 rad (bound {deficit_tol:.3g}); the smallest force at the samples is "
                   f"{force:.3g} N at crank angle {angle:.1f} deg ({where}). " + _infeasible_advice(setup, sim, angle,
                                                                                                 max_preload))
    return None


def _least_groove_start(setup, tried, below: float, above: float, sim, deficit_tol: float,
                        res: PreloadResult) -> float | None:
    """A start for a study with a groove-force bound where the first preload that keeps the contact force,
    ``above`` (its revolution ``sim``), exceeds that bound: the least preload that keeps the force, bisected between
    ``below`` (the largest that did not; 0: none tried) and ``above`` to 1 %, if its groove forces meet the bound;
    else None, with the study's message naming max_groove_force, that preload and its excess. The search took the
    first preload that kept the force before, whatever its groove forces, and IPOPT then spent its iterations on a
    bound no preload met."""
    lo, hi, at = below, above, sim
    while hi - lo > 0.01 * hi:
        probes = [lo + (hi - lo) * (i + 1) / 3 for i in range(2)]  # two at a time, a thread per core
        sims = tried(probes)
        res.history.extend((float(d), setup.smallest(s)[0], float(s.deficit)) for d, s in zip(probes, sims, strict=True))
        for d, s in zip(probes, sims, strict=True):
            if s.deficit <= deficit_tol:
                hi, at = d, s
                break
            lo = d
    if at.groove_excess <= deficit_tol:
        return hi
    close = at.groove_peak is not None and at.groove_peak <= setup.max_groove_force
    res.message = (f"infeasible: at the least constant preload that keeps the contact force >= {setup.min_force:g} "
                   f"N, {hi / MM:.4g} mm (to 1 %), the seal-groove contact forces exceed max_groove_force = "
                   f"{setup.max_groove_force:g} N: excess {at.groove_excess:.3g} N^2 rad (bound {deficit_tol:.3g}), "
                   f"the largest groove force at the samples {at.groove_peak:.3g} N"
                   + (" (the excess counts the forces between the samples too)" if close else "")
                   + "; more preload presses the seal harder into its groove, so no constant preload meets both. "
                   "Raise max_groove_force (--max-groove-force) above the groove forces the force asked needs, or "
                   "lower min_force.")
    return None


def _infeasible_advice(setup, sim, angle: float, max_preload: float) -> str:
    """What to do where no preload is feasible: the spring's own limit where it binds (advice.spring_capacity), else
    by what the shortfall at ``angle`` is (advice.shortfall_kind): a window for an impact transient, not for a smooth
    minimum."""
    if limit := spring_capacity(setup, max_preload, setup.min_force):
        return f"The {limit[4:]}, or lower min_force."
    kind, why = shortfall_kind(sim.thetas, sim.measure, sim.pressures, angle, angle, rpm=setup.scene.operation.rpm)
    if kind == "transient":
        return (f"It is an impact transient ({why}): exclude a window around that angle (exclude=[(start, end)] / "
                "--exclude START:END), lower min_force, or raise max_preload (--max-preload).")
    return (f"It is {why}, where the lift-off is real (do not exclude it): raise max_preload (--max-preload), use a "
            "stiffer spring (spring.ks) or lower min_force.")
