"""Fit the parameters the paper does not print to the features it reports (Section 4.5, Figs. 12-14).

The unknowns are the contact stiffnesses (kw; kg1..kg4 together as kg) and the damping ratios (zeta_w, zeta_g),
each within the range a metal contact of this size allows (:data:`PLAUSIBLE`, reasoned in
docs/scene-estimates.md). Each candidate is one :func:`apexseal.simulate` of ``revolutions`` revolutions with the
compiled integrator of the scene (compiled once; the parameters are inputs), and the features of its last
revolution (:mod:`.features`) are compared with the paper's:

    J = (ln(f_main / 6e4 rad/s))^2 + (angle error of the largest x / 180 deg)^2

over a coarse grid (``grid`` points per unknown, in log stiffness and log ratio), then polished by bounded
Nelder-Mead (scipy.optimize.minimize) from the best grid point. The report says the fit, its residuals, and, per
feature, whether a plausible parameter set reaches it and if not, why (the angle's: :mod:`.angle`), and what
identifies the study (its run id, the scene, its content hash, the model's hash, the versions, the keys replaced
and the options: :meth:`Calibration.to_dict`); :mod:`.report` writes it with the scene that ran as a report folder.
"""

from __future__ import annotations

import itertools
import math
import time
import uuid
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...results.chamber_switches import scene_switches
from .angle import FROM_RUN, FROM_SCENE, angle_verdict
from .features import PAPER_MAIN_PEAK, PAPER_X_ANGLE_DEG, Features, angle_error_deg, features, switches_of

#: unknown -> (low, high): plausible range (docs/scene-estimates.md)
PLAUSIBLE = {"kw": (3e8, 1e10), "kg": (3e8, 1e10), "zeta_w": (0.02, 0.5), "zeta_g": (0.02, 0.5)}
#: the study's counts and their ranges (low, high, why), the same for the API and the command line's options:
#: grid points per unknown (9^4 = 6561 simulations at most), Nelder-Mead simulations, revolutions per simulation
COUNTS = {"grid": (1, 9, ""), "polish": (0, 500, " (0: no polish)"),
          "revolutions": (2, 50, " (the first revolution is the start transient)")}
#: a feature within this of the paper counts as matched: 15 % in frequency, 20 deg in crank angle
FREQUENCY_MATCH = 0.15
ANGLE_MATCH_DEG = 20.0


class CalibrationError(ValueError):
    """A request the study cannot run (an unknown name, a range outside the plausible one)."""


class CalibrationInterrupted(CalibrationError):
    """SIGINT or SIGTERM before any candidate completed: nothing to report. ``exit_code``: 128 + the signal."""

    def __init__(self, message: str, exit_code: int) -> None:
        super().__init__(message)
        self.exit_code = exit_code


class _Stopped(Exception):
    """A signal arrived: the candidate in progress is dropped and the study ends with what it has."""


def contact_settings(values: dict[str, float]) -> dict[str, float]:
    """What the unknowns set, by name in the [contacts] section: kg sets kg1..kg4, the others themselves."""
    out = {}
    for name, v in values.items():
        if name == "kg":
            out.update({f"kg{i}": v for i in range(1, 5)})
        else:
            out[name] = v
    return out


def overrides(values: dict[str, float]) -> dict[str, float]:
    """Scene overrides of the unknowns (kg sets kg1..kg4; ratios go to contacts.zeta_*)."""
    return {f"contacts.{name}": v for name, v in contact_settings(values).items()}


def fastest_contact(scene, ranges: dict[str, tuple[float, float]], functions=None) -> float:
    """The fastest ringing of the seal on its contacts (rad/s) that a candidate can have: every unknown at the top of
    its range, the other parameters the scene's, the ringing that of ``ringing`` (runtime/solving/ringing.py: the
    modes of the model, the spring's contact included, linearised at the scene's initial state). ``functions``:
    the scene's model Functions (default: loaded)."""
    from ...api import initial_state, model_functions
    from ...solving.ringing import ringing

    functions = model_functions(scene) if functions is None else functions
    p = dict(zip(functions.parameter_names, scene.parameter_vector(functions.parameter_names), strict=True))
    p.update({n: v for n, v in contact_settings({n: hi for n, (_, hi) in ranges.items()}).items() if n in p})
    return ringing(functions, list(p.values()), scene.operation.start_angle, initial_state(scene, functions)).rad_s


@dataclass
class Evaluation:
    values: dict[str, float]
    features: Features | None
    cost: float
    status: str
    #: crank angles (deg) of the chamber switches in the analysed revolution of this candidate's run (its chamber
    #: pressures, :func:`.features.switches_of`); None where not measured
    switches_deg: tuple[float, ...] | None = None

    def to_dict(self) -> dict:
        return {"values": self.values, "cost": self.cost, "status": self.status,
                "features": None if self.features is None else self.features.to_dict(),
                "chamber_switches_deg": None if self.switches_deg is None else list(self.switches_deg)}


@dataclass
class Calibration:
    best: Evaluation
    evaluations: list[Evaluation] = field(default_factory=list)
    ranges: dict[str, tuple[float, float]] = field(default_factory=dict)
    revolutions: int = 2
    wall_time_s: float = 0.0
    samples_per_revolution: int = 0  # the output samples each simulation took (its spectrum's sampling)
    mass: float = float("nan")  # the seal's mass ms, kg (for the stiffness a feature would need)
    kw: float = float("nan")  # the scene's tip-housing stiffness, N/m (the housing mode where kw is no unknown)
    stopped: str = ""  # why the study ended early (a signal), or "" for a study that ran to its end
    exit_code: int = 0  # 128 + the signal that stopped it, or 0
    #: what identifies the study, as a report's record does (runtime/results/folder.py, ReportFolder): its run id
    run_id: str = ""
    #: the scene as given, its content hash, the generated model's hash and the package versions
    #: (:func:`apexseal.runtime.api.provenance`, as a result's info records them)
    provenance: dict = field(default_factory=dict)
    #: the study's options: grid, polish, revolutions
    options: dict = field(default_factory=dict)
    #: the scene the study ran (its ``overrides``: the keys replaced, ``--set``), or None; not in :meth:`to_dict`
    scene: Any = field(default=None, repr=False, compare=False)

    @property
    def status(self) -> str:
        """The report's status: "interrupted" for a study a signal stopped, else "completed"."""
        return "interrupted" if self.stopped else "completed"

    @property
    def scene_overrides(self) -> dict:
        """The scene keys replaced when the scene was built (--set), as given."""
        return dict(getattr(self.scene, "overrides", None) or {})

    def best_overrides(self) -> dict[str, float]:
        """The scene keys that make the scene the best set (:func:`overrides`: kg sets kg1..kg4)."""
        return overrides(self.best.values)

    def residuals(self) -> dict:
        f = self.best.features
        return {"main_peak_ln_ratio": math.log(f.main_peak_rad_s / PAPER_MAIN_PEAK),
                "x_max_angle_deg": angle_error_deg(f.x_max_deg, PAPER_X_ANGLE_DEG)}

    def verdicts(self) -> dict:
        """Per feature: matched by the best plausible set, or not, with the reason found in the evaluations."""
        ok = [e for e in self.evaluations if e.features is not None]
        peaks = np.array([e.features.main_peak_rad_s for e in ok])
        angles = np.array([e.features.x_max_deg for e in ok])
        f = self.best.features
        main_ok = abs(f.main_peak_rad_s / PAPER_MAIN_PEAK - 1) <= FREQUENCY_MATCH
        angle_ok = angle_error_deg(f.x_max_deg, PAPER_X_ANGLE_DEG) <= ANGLE_MATCH_DEG
        kw_needed = PAPER_MAIN_PEAK**2 * self.mass
        housing = math.sqrt(self.best.values.get("kw", self.kw) / self.mass)
        is_mode = abs(f.main_peak_rad_s / housing - 1) <= FREQUENCY_MATCH
        near = sorted(ok, key=lambda e: e.cost)[:5]
        near_peaks = [e.features.main_peak_rad_s for e in near]
        return {
            "main_peak": {
                "paper_rad_s": PAPER_MAIN_PEAK, "fit_rad_s": f.main_peak_rad_s, "matched": bool(main_ok),
                "housing_mode_rad_s": housing, "is_housing_mode": bool(is_mode),
                "range_over_evaluations_rad_s": [float(peaks.min()), float(peaks.max())],
                "reason": ("matched" if is_mode else
                           f"matched in value only: the paper's peak is the tip-housing mode, and the best set's, "
                           f"sqrt(kw/ms), is at {housing:.3g} rad/s; the peak found is a point of a broadband "
                           f"spectrum (the impacts at the chamber switches), which the {len(near)} best sets put at "
                           f"{min(near_peaks):.3g}..{max(near_peaks):.3g} rad/s (docs/paper-findings.md)")
                if main_ok else
                (f"the best of the {len(ok)} plausible set{'s' if len(ok) != 1 else ''} simulated puts it at "
                 f"{f.main_peak_rad_s:.3g} rad/s, {100 * (f.main_peak_rad_s / PAPER_MAIN_PEAK - 1):+.0f} % from the "
                 f"paper's (a match is within {100 * FREQUENCY_MATCH:.0f} %), the sets simulated "
                 f"{peaks.min():.3g}..{peaks.max():.3g} rad/s; the housing mode sqrt(kw/ms) is at 6e4 rad/s only for "
                 f"kw = {kw_needed:.3g} N/m, below the plausible {PLAUSIBLE['kw'][0]:.3g} N/m of a metal line "
                 "contact"),
            },
            "x_max_angle": angle_verdict(f.x_max_deg, angles, *self._switches(), bool(angle_ok), ANGLE_MATCH_DEG),
        }

    def _switches(self) -> tuple[tuple[float, ...] | None, str]:
        """The chamber switches the verdict places the largest x against, and where they come from: the best set's
        run, else (a calibration that kept none) the scene's pressure source, else none (None)."""
        if self.best.switches_deg is not None:
            return self.best.switches_deg, FROM_RUN
        if self.scene is not None:
            return tuple(s.angle_deg for s in scene_switches(self.scene)), FROM_SCENE
        return None, ""

    def to_dict(self) -> dict:
        """The study as calibration.json records it: first what identifies it (run id, status, scene, its content
        hash, the model's hash, the versions, the keys replaced and the options), then its results."""
        return {"run_id": self.run_id, "status": self.status, **self.provenance, "overrides": self.scene_overrides,
                "options": dict(self.options), "best": self.best.to_dict(), "best_overrides": self.best_overrides(),
                "residuals": self.residuals(), "verdicts": self.verdicts(),
                "ranges": {k: list(v) for k, v in self.ranges.items()}, "revolutions": self.revolutions,
                "samples_per_revolution": self.samples_per_revolution,
                "evaluations": [e.to_dict() for e in self.evaluations], "wall_time_s": self.wall_time_s,
                "stopped": self.stopped}

    def describe(self) -> str:
        b = self.best
        lines = ["best plausible set: " + ", ".join(f"{k} = {v:.3g}" for k, v in b.values.items())
                 + f" (cost {b.cost:.3g}, {len(self.evaluations)} simulations of {self.samples_per_revolution} samples per "
                 f"revolution, {self.wall_time_s:.1f} s)"]
        if self.stopped:
            lines.insert(0, f"{self.stopped}: the best of the {len(self.evaluations)} simulations completed")
        for name, v in self.verdicts().items():
            paper = v.get("paper_rad_s", v.get("paper_deg"))
            fit = v.get("fit_rad_s", v.get("fit_deg"))
            verdict = ("reproduced" if v["reason"] == "matched" else v["reason"] if v["matched"] else
                       f"not matched: {v['reason']}")
            lines.append(f"  {name}: paper {paper:.4g}, fit {fit:.4g}: {verdict}")
        return "\n".join(lines)


def cost_of(f: Features) -> float:
    """J: squared log frequency ratio of the main peak plus the squared angle error over 180 deg."""
    return math.log(f.main_peak_rad_s / PAPER_MAIN_PEAK) ** 2 + (angle_error_deg(f.x_max_deg, PAPER_X_ANGLE_DEG)
                                                                 / 180) ** 2


def count_range(name: str) -> tuple[int, int, str]:
    """(low, high, why) of the count ``name``: :data:`COUNTS`, or for ``samples`` a run's range of
    samples_per_revolution (runtime/solving/settings.py, read when asked: the command line imports this module)."""
    if name == "samples":
        from ...solving.settings import LIMITS

        rng = LIMITS["samples_per_revolution"][1]
        return rng.ge, rng.le, ", or None (the scene's, or more to resolve the fastest ringing of any candidate)"
    return COUNTS[name]


def check_counts(**given) -> None:
    """A :class:`CalibrationError` naming every count in ``given`` (:func:`count_range`) that is no integer in its
    range, with its value and the range."""
    import numbers

    problems = []
    for name, value in given.items():
        lo, hi, why = count_range(name)
        if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not lo <= value <= hi:
            problems.append(f"{name} = {value!r}: allowed: an integer {lo} <= n <= {hi}{why}")
    if problems:
        raise CalibrationError("; ".join(problems))


def unread_unknowns(scene) -> dict[str, str]:
    """The unknowns of :data:`PLAUSIBLE` that nothing reads in ``scene``, each with the effect that would read it: a
    damping ratio whose damping is off is not an unknown by default, and refused if asked for."""
    from ....derive.submodels.registry import is_read, needing, parameter, submodels

    ratios = {zeta for cls in submodels() for _, zeta in cls.damping_ratios}
    return {n: needing(parameter(n), scene.effects, scene.assumptions) for n in PLAUSIBLE
            if n in ratios and not is_read(n, scene.effects, scene.assumptions)}


def default_ranges(scene) -> dict[str, tuple[float, float]]:
    """The unknowns and ranges of a study of ``scene`` asked for none: :data:`PLAUSIBLE`, less what it does not
    read (:func:`unread_unknowns`)."""
    unread = unread_unknowns(scene)
    return {n: r for n, r in PLAUSIBLE.items() if n not in unread}


def calibrate(scene, *, ranges: dict[str, tuple[float, float]] | None = None, grid: int = 3, revolutions: int = 2,
              polish: int = 20, samples: int | None = None,
              progress: Callable[[str], None] | None = None, run_id: str | None = None) -> Calibration:
    """Fit the unknowns within ``ranges`` (default :data:`PLAUSIBLE`, less a damping ratio whose damping is off)
    to the paper's features (module docstring).

    ``grid``: points per unknown (log-spaced); ``polish``: Nelder-Mead evaluations after the grid (0: none);
    ``samples``: samples per revolution (default: the scene's, or where that is fewer the least multiple of 360
    with at least 2.4 samples per period of the fastest ringing any candidate can have, :func:`fastest_contact`,
    runtime/solving/ringing.py ``samples_resolving``).
    ``run_id``: the study's (default: a new one), as its report records it (``apexseal calibrate`` passes its report
    folder's). The result records what identifies the study (:meth:`Calibration.to_dict`: the scene, its content
    hash, the model's hash, the versions, the keys replaced, the options).
    A Ctrl-C stops the simulation in progress and keeps the others: in a script
    :class:`~apexseal.signals.RunInterrupted` then carries the study (``stopped`` says why), in an interactive
    session it is returned with a warning, and a SIGTERM ends the process.
    """
    from ....signals import StopSignals
    from ...api import after_an_interrupt, model_functions, provenance
    from ...solving.ringing import samples_resolving

    if ranges is None:
        ranges = default_ranges(scene)  # what the scene reads, by construction
    else:
        ranges, unread = dict(ranges), unread_unknowns(scene)
        for name in ranges:
            if name in unread:
                raise CalibrationError(f"unknown = {name!r}: effects.{unread[name]} is off, so nothing reads it; "
                                       f"allowed: leave it out, or set effects.{unread[name]} = true")
    for name, (lo, hi) in ranges.items():
        if name not in PLAUSIBLE:
            raise CalibrationError(f"unknown = {name!r}: not an unknown of the study; allowed: {', '.join(PLAUSIBLE)}")
        plo, phi = PLAUSIBLE[name]
        if not lo < hi:  # within the plausible range it was refused as not inside it
            raise CalibrationError(f"{name} = {lo:g}..{hi:g}: the low end is not below the high end; allowed: LOW..HIGH "
                                   f"with LOW < HIGH, inside the plausible {plo:g}..{phi:g}")
        if not (plo <= lo and hi <= phi):
            raise CalibrationError(f"{name} = {lo:g}..{hi:g}: allowed: a range inside the plausible {plo:g}..{phi:g}")
    check_counts(grid=grid, polish=polish, revolutions=revolutions, **({} if samples is None else {"samples": samples}))
    samples = None if samples is None else int(samples)
    off = [e for e in ("housing_contact", "groove_contact") if not getattr(scene.effects, e)]
    if off:  # their stiffnesses and damping are the unknowns
        raise CalibrationError(f"effects.{off[0]} = false: the calibration fits the contacts' stiffness and damping; "
                               f"allowed: {' and '.join(f'effects.{e} = true' for e in off)}")
    say = progress or (lambda _: None)
    names = list(ranges)
    lo = np.log([ranges[n][0] for n in names])
    hi = np.log([ranges[n][1] for n in names])
    functions = model_functions(scene)
    evaluations: list[Evaluation] = []
    start = time.perf_counter()
    if samples is None:  # Nyquist above the fastest ringing, so that no candidate's peak is aliased
        samples = max(scene.solver.samples_per_revolution,
                      samples_resolving(fastest_contact(scene, ranges, functions), scene.omega))
    stop = StopSignals(redeliver_term=True)  # a signal stops the candidate in progress; the others are kept
    with stop as signals:
        try:
            _search(scene, functions, names, lo, hi, grid, polish, revolutions, samples, evaluations, say, signals)
        except _Stopped:
            pass
        finite = [e for e in evaluations if math.isfinite(e.cost)]
        if not finite and signals.requested:
            raise CalibrationInterrupted(f"interrupted by {signals.sender()} before any candidate completed: "
                                         "nothing to report", signals.exit_code())
        if not finite:
            raise CalibrationError("no candidate completed; see the statuses of the evaluations")
        best = min(finite, key=lambda e: e.cost)
        stopped = f"interrupted by {signals.sender()}" if signals.requested else ""
        cal = Calibration(best, evaluations, ranges, revolutions, time.perf_counter() - start, samples,
                          mass=scene.parameters["ms"], kw=scene.parameters["kw"], stopped=stopped,
                          exit_code=signals.exit_code(), run_id=run_id or uuid.uuid4().hex,
                          provenance=provenance(scene, functions),
                          options={"grid": grid, "polish": polish, "revolutions": revolutions}, scene=scene)
        return after_an_interrupt(cal, stop, signals, bool(stopped), "the calibration",
                                  f"{len(evaluations)} simulations completed, in the returned result",
                                  f"{len(evaluations)} simulations completed in memory only, lost with the process")


def inward_simplex(u0: np.ndarray, lo, hi, share: float = 0.1) -> np.ndarray:
    """Nelder-Mead's first simplex: ``u0`` and, along each unknown, a step of ``share`` of its range towards the
    inside. Scipy's own steps 5 % beyond ``u0``, which from a grid's best on a bound it clips back onto ``u0``: a
    flat simplex whose first polish simulations repeated the start."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    step = share * (hi - lo)
    out = np.tile(u0, (len(u0) + 1, 1))
    for i in range(len(u0)):
        out[i + 1, i] += step[i] if u0[i] + step[i] <= hi[i] else -step[i]
    return out


def _search(scene, functions, names, lo, hi, grid, polish, revolutions, samples, evaluations, say, signals) -> None:
    """The grid, then Nelder-Mead from its best point; every completed simulation appended to ``evaluations``.
    Raises :class:`_Stopped` when a signal arrives (the simulation it stopped is not a candidate)."""
    from scipy.optimize import minimize

    from ...api import simulate
    from ...solving import engine_pool

    extra = {"samples_per_revolution": samples}
    known: dict[tuple[float, ...], float] = {}  # cost by candidate: Nelder-Mead starts at the grid's best, and
    # points it tries beyond the bounds are clipped onto ones it has tried

    def evaluate(u: np.ndarray) -> float:
        if signals.requested:
            raise _Stopped
        at = tuple(float(v) for v in np.clip(u, lo, hi))
        if at in known:
            return known[at]
        # 12 significant digits, as scenes keep them: the grid's 4e9 is 4e9, not exp(log(4e9)) = 3999999999.999998
        values = {n: float(f"{np.exp(v):.12g}") for n, v in zip(names, at, strict=True)}
        sc = scene.with_overrides(**overrides(values))
        with warnings.catch_warnings(), engine_pool.reusing():  # every candidate runs the same engine
            warnings.simplefilter("ignore")
            r = simulate(sc, revolutions=revolutions, functions=functions, **extra)
        if signals.requested:  # cut short: not a result of this candidate
            raise _Stopped
        if not r.ok:
            ev = Evaluation(values, None, float("inf"), r.status)
        else:
            f = features(r, sc.omega)
            ev = Evaluation(values, f, cost_of(f), r.status, switches_of(r))
        evaluations.append(ev)
        shown = ", ".join(f"{k} {v:.3g}" for k, v in values.items())
        tail = f"main peak {ev.features.main_peak_rad_s:.3g} rad/s, x largest at {ev.features.x_max_deg:.0f} deg" \
            if ev.features else ev.status
        say(f"[{len(evaluations)}] {shown}: {tail}; cost {ev.cost:.3g}")
        known[at] = ev.cost
        return ev.cost

    axes = [np.linspace(a, b, grid) if grid > 1 else np.array([(a + b) / 2]) for a, b in zip(lo, hi, strict=True)]
    for point in itertools.product(*axes):
        evaluate(np.array(point))
    finite = [e for e in evaluations if math.isfinite(e.cost)]
    if polish > 0 and finite:
        best = min(finite, key=lambda e: e.cost)
        u0 = np.array(next(at for at, cost in known.items() if cost == best.cost))
        minimize(evaluate, u0, method="Nelder-Mead", bounds=list(zip(lo, hi, strict=True)),
                 options={"maxfev": polish + 1, "xatol": 0.05, "fatol": 1e-3,  # + its start, simulated already
                          "initial_simplex": inward_simplex(u0, lo, hi)})
