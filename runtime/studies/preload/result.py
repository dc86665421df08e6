"""What the preload study returns: the design, its re-simulation and IPOPT's report (PreloadResult), and how a
re-simulated revolution fills it."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import ClassVar

import numpy as np

from .advice import robustness, shortfall_advice, shortfall_kind
from .options import DEFAULTS
from .problem import MM
from .schedule import Schedule

#: default bound of the squared force deficit: (0.2 N)^2 over 0.1 deg of crank angle (N^2 rad); at (0.1 N)^2 over
#: 0.05 deg the deficit of the iterates near the optimum was noisy at ~10 % of the bound (the rattle's impacts at
#: the erk rtol) and IPOPT wandered for 100 iterations within 1e-4 of the answer without stopping (measured)
DEFICIT_TOL = DEFAULTS["deficit_tol"]
#: a re-simulated optimum meets a bound (deficit_tol) when within this factor of it: IPOPT stops within 2 % of
#: the bound, and the re-simulation from the scene's initial state differs from the NLP's trajectory at the
#: rtol-level noise of the impacts (docs/preload.md, "The non-smooth strategy")
ALLOWANCE = 1.05


@dataclass(repr=False)
class PreloadResult:
    """What the study found. ``knots`` is None when it failed (``message`` says why).

    Two friction powers, measured differently on the same re-simulated revolution: ``friction_power`` (and
    ``scene_friction_power``, ``nlp_friction_power``) is the quadrature of ``Pf_total`` over crank angle divided by
    2 pi, between the samples too, while ``contact_friction_power`` (and ``scene_contact_friction_power``) is the
    mean of each contact's ``Pf_<contact>`` at the ``samples`` output samples, as a run's means are. The contacts'
    powers sum to the mean of ``Pf_total`` at the samples, which differs from the quadrature by the rectangle rule's
    error, at most the total variation of ``Pf_total`` over the revolution / ``samples`` (the impacts make it large
    on a coarse grid): on the small study's 72-sample 2-knot schedule a contact's mean can exceed the total
    (docs/preload.md, "The study's Functions from Python").

    ``simulation`` (and ``scene_simulation``, the scene's own preload) is the re-simulated revolution the numbers
    come from (a :class:`.schedule.Resimulation`: the hybrid states, the contact measure and the preload at the
    samples), kept for the figures and not written by :meth:`to_dict`; None where the study ended before
    re-simulating an optimum (it failed or was interrupted). ``==`` compares the fields (plain numbers, lists and
    dicts: the JSON of :meth:`to_dict`), not the simulations.
    """

    #: the re-simulated revolution of the optimum (not a field: see the class docstring); None until there is one
    simulation: ClassVar = None
    #: the re-simulated revolution at the scene's own preload (not a field); None until there is one
    scene_simulation: ClassVar = None
    #: the scene the study ran (not a field): what :func:`.report.save_report` writes as scene.toml
    scene: ClassVar = None

    ok: bool
    message: str
    min_force: float  # N, the requirement
    exclude_deg: list  # excluded crank-angle windows [(start, end), ...] in degrees
    objective: str = "friction"
    #: deg, the knots' crank angles: set as the study starts, so that a study that failed or was interrupted before
    #: it found a design still says how many knots it was asked (its report's schedule_knots)
    knot_angles_deg: list = field(default_factory=list)
    knots: list | None = None  # m, the optimal delta_s at the knots (one value: the constant preload)
    delta_s: float | None = None  # m, the mean preload over the revolution (the constant preload for 1 knot)
    spring_force: float | None = None  # N, the spring's force at rest at the mean delta_s (Eq. 39, PreloadMap.spring_force)
    scene_delta_s: float = 0.0  # m
    friction_power: float | None = None  # W, cycle mean at the optimum (re-simulation; quadrature, between samples)
    scene_friction_power: float | None = None  # W, at the scene's preload
    nlp_friction_power: float | None = None  # W, the NLP's own
    #: W, each contact's mean at the samples of the re-simulated revolution (not a quadrature: see the docstring)
    contact_friction_power: dict = field(default_factory=dict)
    scene_contact_friction_power: dict = field(default_factory=dict)  # W, the same at the scene's preload
    deficit: float | None = None  # N^2 rad, the force-deficit quadrature of the re-simulation
    #: where most of that deficit builds up: [start, end] deg (mod 360) of the span around its densest output
    #: interval, and the share of the deficit within it (:func:`deficit_span`); None without a deficit
    deficit_span_deg: list | None = None
    deficit_span_share: float | None = None
    #: what that span is (advice.shortfall_kind): "transient" (next to a chamber switch, or the tip rings) or
    #: "smooth" (a smooth minimum of the tip force, where the lift-off is real), and why; "" without a deficit
    deficit_span_kind: str = ""
    deficit_span_why: str = ""
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
    #: the revolutions the study's simulations run from the scene's initial state before the one it reports (the
    #: re-simulation of an optimum goes on, 2 at a time, until periodic: .periodic.PERIODIC_TOL)
    revolutions: int = 3
    rtol: float = 0.0
    max_defect: float | None = None  # largest continuity/periodicity defect at the solution (scaled state)
    history: list = field(default_factory=list)  # [(delta_s m, min force at samples N, deficit), ...] start search
    #: m, IPOPT's last answer at the knots, set as IPOPT ends, before its re-simulation: what a study interrupted
    #: then keeps (its ``knots`` are None: not re-simulated, the force between samples not checked)
    ipopt_knots: list | None = None
    #: the best feasible iterate IPOPT visited in its current round (the lowest objective among the iterates within
    #: IPOPT's constr_viol_tol of every constraint; nlp._Progress.keep_if_feasible), kept as IPOPT iterates: what a
    #: study interrupted during IPOPT's iterations keeps. {"iteration", "knots" (m), "objective" (W, or mm for the
    #: preload objective), "deficit" (N^2 rad, the NLP's), "max_defect"}; not optimal, not re-simulated
    best_feasible: dict | None = None
    #: m, where IPOPT stopped when a constant preload below it was found feasible (:func:`.study._polish_constant`)
    ipopt_delta_s: float | None = None
    #: what holds a constant optimum where it is (:func:`.study._polish_constant`): "deficit" or "groove" (less
    #: preload violates the force-deficit or the groove-force bound), "zero" (the bound delta_s >= 0: no preload
    #: is needed); "" for a schedule or a failed study
    active: str = ""
    #: IPOPT was solved again from its start with its filter bounded (:func:`.study._solve_with_the_filter_bounded`):
    #: the first solve, from a start where the force deficit and its gradient were 0, ended at its iteration limit or
    #: stayed beyond the bounded filter's reach for nlp.STUCK_ITERATIONS iterations
    filter_bounded: bool = False
    #: who stopped the study before it ended (a signal's sender, e.g. "the user (Ctrl-C, SIGINT)"), "" where it ended
    #: by itself: the report's status is then "interrupted" (:func:`.report.report_status`)
    interrupted_by: str = ""
    #: a constant optimum held by a bound: whether every preload advice.ROBUST_STEPS above it re-simulates feasibly
    #: too (:func:`.study._polish_constant`); False: a knife-edge point (:func:`.advice.robustness`); None: not checked
    robust: bool | None = None
    #: [[delta_s m, passed, force deficit N^2 rad, [start, end] deg where it builds up], ...] the robustness check's
    #: probes
    robust_probes: list = field(default_factory=list)

    def to_dict(self) -> dict:
        """The fields as plain data (numbers, strings, lists, dicts), as ``preload.json`` holds them; not the
        simulations."""
        return asdict(self)

    @classmethod
    def load(cls, folder, stage: str = "constant") -> PreloadResult:
        """A saved study's result, read back from the ``preload.json`` of its report ``folder`` (what the command
        or ``apexseal.save_preload_report`` wrote): ``stage`` "constant" (the constant optimum) or "schedule". What
        the JSON holds, not the simulations; with the folder's scene.toml as its ``scene``, so that it can start a
        schedule (``optimise_preload(scene, knots=4, start=PreloadResult.load(folder))``) or be reported again. A
        folder without a report, or a report without that stage, is a :class:`PreloadStudyError` saying so."""
        import json
        from dataclasses import fields
        from pathlib import Path

        from .problem import PreloadStudyError

        if stage not in ("constant", "schedule"):
            raise PreloadStudyError(f"stage = {stage!r}: must be 'constant' or 'schedule'")
        path = Path(folder) / "preload.json"
        try:
            data = json.loads(path.read_text())
        except (OSError, ValueError) as err:
            raise PreloadStudyError(f"folder = {str(folder)!r}: no readable preload study report there "
                                    f"(preload.json: {err})") from None
        saved = data.get(stage) if isinstance(data, dict) else None
        if not isinstance(saved, dict):
            raise PreloadStudyError(f"folder = {str(folder)!r}: its report holds no {stage} result "
                                    f"(its status: {data.get('status', '?') if isinstance(data, dict) else '?'})")
        names = {f.name for f in fields(cls)}
        try:
            res = cls(**{k: v for k, v in saved.items() if k in names})
        except TypeError as err:
            raise PreloadStudyError(f"folder = {str(folder)!r}: its {stage} result is not a study's ({err})") from None
        scene_file = Path(folder) / str(data.get("scene_file", "scene.toml"))
        if scene_file.is_file():
            from ...scenes.scene import load_scene

            res.__dict__["scene"] = load_scene(scene_file)
        return res

    @property
    def has_answer(self) -> bool:
        """Whether the result holds a preload: a re-simulated solution (``knots``), IPOPT's answer before its
        re-simulation (``ipopt_knots``) or the best feasible iterate IPOPT visited (``best_feasible``); False for a
        study stopped or failed before IPOPT reached a feasible iterate."""
        return self.knots is not None or bool(self.ipopt_knots) or self.best_feasible is not None

    @property
    def schedule(self) -> Schedule | None:
        """The optimum as a callable ``delta_s(theta_deg)`` (m; periodic, piecewise linear through the knots, constant
        for one knot), or None for a study that found none."""
        return Schedule(tuple(self.knot_angles_deg), tuple(self.knots)) if self.knots else None

    def __repr__(self) -> str:
        ipopt = f"IPOPT {self.ipopt_status or 'not run'}, {self.ipopt_iterations} iterations"
        if not self.ok or not self.knots:
            why = self.message if len(self.message) <= 60 else self.message[:59] + "…"  # the whole: .message
            return f"PreloadResult(failed ({why}), {ipopt})"
        what = (f"constant {self.knots[0] / MM:.4f} mm" if len(self.knots) == 1 else
                f"{len(self.knots)} knots, mean {self.delta_s / MM:.4f} mm")
        return f"PreloadResult(solved, {what}, friction power {self.friction_power:.3f} W, {ipopt})"

    def describe(self) -> str:
        """The report's lines: the optimum, the force deficit and where it builds up, the smallest force at the
        samples, the friction power against the scene's preload, what holds the optimum, IPOPT's run."""
        if not self.ok:
            return f"preload study {'interrupted' if self.interrupted_by else 'failed'}: {self.message}"
        what = ("constant preload delta_s*" if len(self.knots) == 1 else
                f"preload schedule ({len(self.knots)} knots), mean delta_s")
        lines = [
            f"{what} = {self.delta_s / MM:.4f} mm (the spring's force at rest (Eq. 39) = {self.spring_force:.3f} N; "
            f"scene: {self.scene_delta_s / MM:.4g} mm)",
        ]
        if len(self.knots) > 1:
            lines.append("  knots: " + ", ".join(f"{a:.1f} deg: {v / MM:.3f} mm"
                                                  for a, v in zip(self.knot_angles_deg, self.knots, strict=True)))
        lines += [
            *self._headline_force(),
            f"  force deficit int max(0, {self.min_force:g} N - F)^2 dtheta = {squares_text(self.deficit)} N^2 rad "
            f"(bound {self.deficit_tol:.3g})" + (
                f", excluded: {', '.join(f'{a:g}..{b:g} deg' for a, b in self.exclude_deg)}" if self.exclude_deg else ""),
            *self._deficit_where(),
            *([f"  groove forces: excess int sum max(0, |F| - {self.max_groove_force:g} N)^2 dtheta = "
               f"{squares_text(self.groove_excess)} N^2 rad (bound {self.deficit_tol:.3g}); largest at the samples "
               f"{self.groove_peak:.4g} N (impacts between the samples can reach higher; the excess above counts them)"]
              if self.max_groove_force is not None else []),
            f"  smallest contact force at the samples: {self.min_measure:.4f} N at {self.min_measure_angle:.1f} deg "
            f"(re-simulation, {self.samples} samples)",
            f"  friction power {self.friction_power:.3f} W vs {self.scene_friction_power:.3f} W at the scene's preload "
            f"({self.friction_power - self.scene_friction_power:+.3f} W)",
            *self._holding(),
            *robustness(self),
            f"  IPOPT: {self.ipopt_status}, {self.ipopt_iterations} iterations, {self.ipopt_time_s:.1f} s "
            f"({self.rounds} round{'s' if self.rounds != 1 else ''}"
            f"{'; solved again with its filter bounded after its first solve stalled' if self.filter_bounded else ''}"
            "); "
            f"build {self.build_time_s:.1f} s; "
            f"{self.nodes} shooting nodes, erk rtol {self.rtol:g}",
        ]
        return "\n".join(lines)

    def _deficit_where(self) -> list[str]:
        """Where the deficit builds up (:func:`deficit_span`), as a line of :meth:`describe`."""
        if not self.deficit_span_deg:
            return []
        (start, end), share = self.deficit_span_deg, self.deficit_span_share
        if (end - start) % 360.0 == 0.0:
            return ["  the deficit is spread over the whole revolution (no window of it stands out)"]
        where = f"  {100 * share:.0f} % of it at {start:.1f}...{end:.1f} deg, where the tip force falls short"
        if not self.deficit_span_kind:
            return [where]
        return [f"{where}: {shortfall_advice(self.deficit_span_kind, self.deficit_span_why)}"]

    def _headline_force(self) -> list[str]:
        """The smallest force the optimum reaches against the one asked, and the tolerance that accepts it."""
        if self.min_measure >= self.min_force:
            return [f"  at least the {self.min_force:g} N asked at every sample (smallest {self.min_measure:.4g} N)"]
        return [f"  smallest force reached {self.min_measure:.4g} N for the {self.min_force:g} N asked: met within the "
                f"force-deficit tolerance deficit_tol = {self.deficit_tol:.3g} N^2 rad (--deficit-tol; the default "
                "allows e.g. a 0.2 N shortfall over 0.1 deg), not at every angle"]

    def _holding(self) -> list[str]:
        """What holds a constant optimum (:attr:`active`), and how it was lowered from where IPOPT stopped."""
        if not self.active:
            return []
        if self.active == "zero":
            lines = ["  active at the optimum: only the bound delta_s >= 0 (no preload is needed: without one the "
                     "re-simulated force deficit is within its bound" + (", and so is the groove-force excess"
                                                                          if self.max_groove_force is not None else "")
                     + ")"]
            if self.ipopt_delta_s is not None:
                lines.append(f"  IPOPT stopped at {self.ipopt_delta_s / MM:.4f} mm; less preload re-simulated "
                             "feasibly down to none at all: lowered to the bound (no boundary to bisect)")
            return lines
        bound = "force-deficit bound" if self.active == "deficit" else "groove-force bound"
        lines = [f"  active at the optimum: the {bound} (less preload re-simulates beyond it)"]
        if self.ipopt_delta_s is not None:
            lines.append(f"  IPOPT stopped at {self.ipopt_delta_s / MM:.4f} mm, above that boundary: lowered by "
                         "bisection on the re-simulations (its gradient through the events was inexact)")
        return lines


def knot_angles(grid) -> list:
    """The knots' crank angles of a :class:`.schedule.SegmentGrid` as a result records them (deg, mod 360)."""
    return [float(a) % 360.0 for a in grid.knot_angles_deg]


def fill_result(res, setup, grid, knots_m, sim) -> None:
    res.knot_angles_deg = knot_angles(grid)
    res.knots = [float(v) for v in knots_m]
    res.delta_s = float(np.mean(Schedule(tuple(res.knot_angles_deg), tuple(res.knots))(
        np.degrees(sim.thetas))))
    res.spring_force = setup.pmap.spring_force(res.delta_s)
    res.friction_power = sim.friction_power
    res.deficit = sim.deficit
    span = deficit_span(sim.thetas, sim.deficit_at, setup.dth)
    if span is not None:
        res.deficit_span_deg, res.deficit_span_share = [span[0], span[1]], span[2]
        if (span[1] - span[0]) % 360.0:
            res.deficit_span_kind, res.deficit_span_why = shortfall_kind(
                sim.thetas, sim.measure, sim.pressures, span[0], span[1], rpm=setup.scene.operation.rpm)
    res.min_measure, res.min_measure_angle = setup.smallest(sim)
    res.periodic_change = sim.change
    if setup.max_groove_force is not None:
        res.groove_excess, res.groove_peak = sim.groove_excess, sim.groove_peak
    res.contact_friction_power = contact_powers(setup, sim)
    res.__dict__["simulation"] = sim  # not a field: kept for the figures, not written to JSON


def squares_text(x: float) -> str:
    """An integral of a square (the force deficit, the groove-force excess; N^2 rad) as printed: the integrator's
    round-off can leave it a little below 0, which is printed as 0, naming the raw value as round-off."""
    return f"{x:.3g}" if x >= 0 else f"0 (round-off: {x:.3g}, an integral of a square is >= 0)"


#: the span of :func:`deficit_span` holds the output intervals around the densest one whose deficit is at least this
#: fraction of the densest's
SPAN_FLOOR = 0.01


def deficit_span(thetas: np.ndarray, deficit_at: np.ndarray | None, dth: float) -> tuple[float, float, float] | None:
    """Where a revolution's force deficit builds up: the contiguous output intervals (cyclically) around the one with
    the most deficit, while each holds at least :data:`SPAN_FLOOR` of that one's, as (start deg, end deg, share of
    the revolution's deficit), the angles mod 360; None when the revolution has no deficit. ``thetas``: the ends of
    the intervals (rad), ``dth`` their width."""
    if deficit_at is None or not np.sum(deficit_at) > 0:
        return None
    d = np.maximum(np.asarray(deficit_at, float), 0.0)
    n, j = d.size, int(np.argmax(d))
    lo = hi = j
    while hi - lo + 1 < n and d[(lo - 1) % n] >= SPAN_FLOOR * d[j]:
        lo -= 1
    while hi - lo + 1 < n and d[(hi + 1) % n] >= SPAN_FLOOR * d[j]:
        hi += 1
    share = float(sum(d[k % n] for k in range(lo, hi + 1)) / d.sum())
    start = float(np.degrees(thetas[lo % n] - dth) % 360.0)
    return start, float(np.degrees(thetas[hi % n]) % 360.0), share


def contact_powers(setup, sim) -> dict:
    """Cycle-mean friction power of each contact (W) at the samples of a re-simulated revolution."""
    names = tuple(setup.functions.output_names)
    P = setup.pmap.p0[:, None] + setup.pmap.dp[:, None] * sim.delta_s[None, :]
    Y = setup.at_samples(setup.functions.outputs, sim.z[:, 1:], sim.thetas, P, sim.pressures)
    return {k[3:]: float(Y[i].mean()) for i, k in enumerate(names) if k.startswith("Pf_") and k != "Pf_total"}
