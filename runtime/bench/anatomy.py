"""Where the benchmark's error and work are, and what that asks of a method that would beat the peer 2x.

Made by ``python -m apexseal.runtime.bench.anatomy [--rtols 1e-6,1e-7,1e-8,1e-9] [--ring 20] [--no-scipy]
[--no-split] [--event-tol 1e-12]`` (about 3.5 minutes; docs/bench/levers.md, "Where the error and the work are").

The problem is the benchmark's (runtime/bench/problem.py: default scene, one revolution after three settling
ones, 360 output intervals, linear chamber pressures) with its reference (erk at rtol 1e-12, events to 1e-13
rad). Three measurements:

* **Where the error is** (:func:`windowed_errors`): the scaled error of each output sample (the largest of
  x, y and phi, each divided by the reference's range, as runtime/bench/metrics.py), its maximum inside the
  *switch windows* (the output intervals holding a contact switch of the reference and the ``ring`` degrees
  after each, while the contacts ring down) and outside them, for erk and rosenbrock at each rtol (interpreted,
  for their statistics: the compiled integrators compute the same numbers).
* **What standard methods need** (:func:`scipy_rows`): scipy's RK45, DOP853, LSODA, BDF and Radau on the
  peer's numba right-hand side (runtime/bench/peer_numba.py, contacts switched inside it): right-hand-side
  evaluations (finite-difference Jacobians included) against the same errors. Counts, not times: scipy's
  stepping runs in Python.
* **A stiff method where nothing switches** (:func:`split_rows`): the revolution cut at the switch windows,
  erk inside them and rosenbrock (L-stable) outside, against erk and rosenbrock alone: steps, CPU time (median
  of ``repeats`` after a warm-up), error. The windows come from the reference (an oracle), so this bounds what
  switching between the two by phase could give. Besides, erk with its tolerance loosened outside the windows
  (:data:`LOOSE_OUTSIDE` times rtol there): how much of erk's work between the windows the error needs.
"""

from __future__ import annotations

import argparse
import math
from contextlib import contextmanager

import numpy as np

from ...generated.layout import HybridLayout
from ...generated.scaling import to_physical, to_scaled
from .config import METHODS
from .methods import EngineCache, build_engine
from .metrics import STATE_KEYS, errors, trajectory
from .problem import load_model, make_problem
from .timing import warm_median

#: scipy's methods of :func:`scipy_rows`
SCIPY_METHODS = ("RK45", "DOP853", "LSODA", "BDF", "Radau")
#: the factors on rtol outside the switch windows of :meth:`Anatomy.split_rows`'s loosened plans
LOOSE_OUTSIDE = (100.0, 1000.0)


def switch_intervals(problem, z_ref: np.ndarray) -> np.ndarray:
    """(samples,) bool: True for the output intervals in which the reference switched a contact (its event
    counters, generated/layout.py, went up over the interval)."""
    lay = HybridLayout.of(problem.functions)
    counts = np.c_[problem.z0[lay.counts], np.asarray(z_ref)[lay.counts]].sum(axis=0)
    return np.diff(counts) > 0


def switch_windows(switched: np.ndarray, ring_samples: int) -> np.ndarray:
    """(samples,) bool: each switching interval and the ``ring_samples`` intervals after it (periodic: the
    span is a revolution, so a window near its end continues at its start)."""
    switched = np.asarray(switched, bool)
    inside = switched.copy()
    for k in range(1, ring_samples + 1):
        inside |= np.roll(switched, k)
    return inside


def sample_errors(traj, ref) -> np.ndarray:
    """(samples,) scaled error of each sample: max over x, y, phi of |traj - ref| / range of the reference."""
    rows = []
    for i, _ in enumerate(STATE_KEYS):
        rng = float(np.ptp(ref.X[i]))
        if rng > 0:
            rows.append(np.abs(traj.X[i] - ref.X[i]) / rng)
    return np.max(rows, axis=0)


def windowed_errors(traj, ref, windows: np.ndarray) -> dict:
    """The scaled error (the benchmark's) and its maximum inside and outside the switch ``windows``."""
    e = sample_errors(traj, ref)
    inside, outside = e[windows], e[~windows]
    return {"state": errors(traj, ref)["state"], "inside": float(inside.max()) if inside.size else 0.0,
            "outside": float(outside.max()) if outside.size else 0.0}


class Anatomy:
    """The benchmark's problem with its reference and switch windows, and the engines that integrate it."""

    def __init__(self, *, samples: int = 360, ring_deg: float = 20.0, settle: int = 3, problem=None,
                 reference_z: np.ndarray | None = None):
        from ..scenes.scene import load_scene

        span = 2 * math.pi if problem is None else problem.span
        samples = samples if problem is None else problem.samples
        self.engines = EngineCache(samples=samples, span=span, flags="optimised", pressure="linear")
        if problem is None:
            scene = load_scene()
            functions, _ = load_model(scene.effects, scene.assumptions)
            st_engine, st = self.engines.settle("all", functions, 1e-10, 1e-12)
            problem = make_problem("default", scene, scene.effects, functions, samples=samples, span=span,
                                   settle_revolutions=settle, settle_engine=st_engine, settle_settings=st,
                                   pressure_profile="linear")
        self.functions = problem.functions
        self.problem = problem
        if reference_z is None:
            ref_engine = self.engines.reference("all", self.functions, 1e-12, 1e-13)
            reference_z = ref_engine.run(problem.z0, problem.params, problem.theta0, problem.pressures).z
        self.ref_z = np.asarray(reference_z)
        self.ref = trajectory(problem, self.ref_z)
        self.dtheta = problem.span / problem.samples
        ring = int(round(math.radians(ring_deg) / self.dtheta))
        self.switched = switch_intervals(problem, self.ref_z)
        self.windows = switch_windows(self.switched, ring)
        self._segment_engines: dict = {}  # (method, rtol, intervals, compiled) -> engine of :meth:`_run_plan`

    def casadi_rows(self, methods=("erk", "rosenbrock"), rtols=(1e-6, 1e-7, 1e-8, 1e-9), event_tol: float | None = None,
                    velocity_scale: float = 1.0, log=print) -> list[dict]:
        """Error inside and outside the switch windows, steps and RHS evaluations, for each method and rtol, with the
        events located to ``event_tol`` rad (None: the run's default) and the integrated velocities scaled
        ``velocity_scale`` times larger (:func:`velocities_scaled`)."""
        p, rows = self.problem, []
        X0 = to_physical(p.z0[:6], p.omega)
        for method in methods:
            for rtol in rtols:
                with velocities_scaled(velocity_scale):
                    z0 = p.z0.copy()
                    z0[:6] = to_scaled(X0, p.omega)
                    vm = (self.engines.get("all", self.functions, METHODS[f"{method}-C"], rtol, compiled=False,
                                           event_tol=event_tol) if velocity_scale == 1 else
                          build_engine(self.functions, METHODS[f"{method}-C"], rtol, samples=p.samples, span=p.span,
                                       flags="optimised", compiled=False, event_tol=event_tol, pressure="linear"))
                    out = vm.run(z0, p.params, p.theta0, p.pressures)
                    traj = trajectory(p, out.z)
                label = method if event_tol is None else f"{method}, events to {event_tol:g} rad"
                label += "" if velocity_scale == 1 else f", velocities scaled {velocity_scale:g}x"
                rows.append({"method": label, "rtol": rtol, "steps": int(out.stats["n_steps"]),
                             "rhs": int(out.stats["n_rhs"])} | windowed_errors(traj, self.ref, self.windows))
                log(rows[-1])
        return rows

    def split_rows(self, rtols=(1e-7, 1e-8, 1e-9), repeats: int = 5, compiled: bool = True, log=print) -> list[dict]:
        """erk alone, rosenbrock alone, and erk in the switch windows with rosenbrock between them (timed compiled,
        or interpreted with ``compiled=False``)."""
        whole = lambda m: [(0, self.problem.samples, m, 1.0)]  # noqa: E731
        plans = {"erk": whole("erk"), "rosenbrock": whole("rosenbrock"), "erk, cut at the windows":
                 self.segments(between="erk"), "erk in the windows, rosenbrock between": self.segments()}
        plans |= {f"erk, {f:g}x rtol outside the windows": self.segments(between="erk", loose=f) for f in LOOSE_OUTSIDE}
        rows = []
        for rtol in rtols:
            for label, plan in plans.items():
                z, steps = self._run_plan(plan, rtol, compiled=False)
                inside = sum(n for (lo, *_), n in zip(plan, steps, strict=True) if self.windows[lo])
                # the warm-up compiles or loads the integrators
                _, cpu = warm_median(lambda plan=plan, rtol=rtol: self._run_plan(plan, rtol, compiled=compiled), repeats)
                err = windowed_errors(trajectory(self.problem, z), self.ref, self.windows)
                rows.append({"plan": label, "rtol": rtol, "steps": sum(steps), "steps_inside": inside,
                             "cpu_ms": 1e3 * cpu, "segments": len(plan)} | err)
                log(rows[-1])
        return rows

    def segments(self, between: str = "rosenbrock", loose: float = 1.0) -> list[tuple[int, int, str, float]]:
        """The revolution cut where the switch windows begin and end: (first interval, end, method, factor on
        rtol), erk at rtol in the windows and ``between`` at ``loose`` times rtol outside them."""
        w, out, start = self.windows, [], 0
        for k in range(1, w.size + 1):
            if k == w.size or w[k] != w[start]:
                out.append((start, k, "erk", 1.0) if w[start] else (start, k, between, loose))
                start = k
        return out

    def _run_plan(self, plan, rtol: float, *, compiled: bool) -> tuple[np.ndarray, list[int]]:
        """Integrate the revolution segment by segment, each with its method and factor on ``rtol``; (hybrid
        states, steps of each segment: 0 for a compiled integrator, which reports none)."""
        p, cols, steps = self.problem, [], []
        z = p.z0
        P = p.pressures  # linear: the values at the n + 1 edges
        for lo, hi, method, factor in plan:
            key = (method, rtol * factor, hi - lo, compiled)
            eng = self._segment_engines.get(key)
            if eng is None:
                eng = self._segment_engines[key] = build_engine(
                    self.functions, METHODS[f"{method}-C"], rtol * factor, samples=hi - lo,
                    span=(hi - lo) * self.dtheta,
                    flags="optimised", compiled=compiled, pressure="linear")
            out = eng.run(z, p.params, p.theta0 + lo * self.dtheta, P[:, lo:hi + 1])
            steps.append(int(out.stats.get("n_steps", 0)))
            cols.append(out.z)
            z = out.z[:, -1]
        return np.hstack(cols), steps


@contextmanager
def velocities_scaled(factor: float):
    """Within it, the integrated velocities are ``factor`` times smaller: each declared rate scale (l w, a w,
    generated/scaling.py) is ``factor`` times larger, so an integrator's error norm on them is ``factor``
    times looser, and nothing else changes. A measurement's device: engines built within it keep the scaling."""
    from ...generated import scaling

    declared = scaling.declared_scales
    if factor != 1:
        scaling.declared_scales = lambda names: (lambda b, r: (b * np.where(r, factor, 1.0), r))(*declared(names))
    try:
        yield
    finally:
        scaling.declared_scales = declared


def scipy_rows(an: Anatomy, methods=SCIPY_METHODS, rtols=(1e-5, 1e-6, 1e-7, 1e-8, 1e-9), velocity_scale: float = 1.0,
               log=print) -> list[dict]:
    """RHS evaluations of scipy's methods on the peer's numba switched right-hand side, with their errors."""
    from .peer_numba import NumbaPeer
    from .peer_source import numba_model

    p = an.problem
    peer = NumbaPeer(p, numba_model(p.effects, p.scene.assumptions))
    peer.build(numbalsoda=False)
    rows = []
    for method in methods:
        for rtol in rtols:
            row = {"method": method + ("" if velocity_scale == 1 else f", velocities scaled {velocity_scale:g}x"),
                   "rtol": rtol}
            try:
                out = peer.scipy(method, rtol, velocity_weight=velocity_scale)
            except RuntimeError as exc:
                row |= {"rhs": 0, "jacobians": 0, "failed": str(exc)[:120]}
            else:
                row |= {"rhs": out.stats["n_rhs"], "jacobians": out.stats["n_jac"]}
                row |= windowed_errors(trajectory(p, out.z), an.ref, an.windows)
            rows.append(row)
            log(row)
    return rows


def evaluations_at(rows: list[dict], method: str, target: float) -> float | None:
    """RHS evaluations a method needs for a scaled error of ``target``: log-log interpolation between the two of
    its points around it on its (evaluations, error) Pareto front; None when its points do not bracket it."""
    pts = sorted((r["rhs"], r["state"]) for r in rows if r["method"] == method and "state" in r)
    front, best = [], math.inf
    for n, e in pts:
        if e < best:
            front.append((n, e))
            best = e
    for (n0, e0), (n1, e1) in zip(front, front[1:], strict=False):
        if e1 <= target <= e0:
            w = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(n0) + w * (math.log(n1) - math.log(n0)))
    return None


def _reached(rows: list[dict], method: str, n: float | None) -> str:
    """``n`` evaluations, or what the method's most accurate point reached instead."""
    if n is not None:
        return f"{n:,.0f}"
    points = [(r["state"], r["rhs"]) for r in rows if r["method"] == method and "state" in r]
    if not points:
        return "failed at every tolerance"
    e, rhs = min(points)
    return f"not reached (best {e:.1e} with {rhs:,})"


def markdown(an: Anatomy, casadi: list[dict], scipy: list[dict], split: list[dict], ring_deg: float) -> str:
    deg = np.degrees(an.dtheta)
    n_in = int(an.windows.sum())
    out = [f"Switch windows: the {int(an.switched.sum())} output intervals in which the reference switched a contact "
           f"and the {ring_deg:g} deg after each: {n_in} of {an.windows.size} samples ({n_in * deg:.0f} deg), "
           f"segments {', '.join(f'{lo * deg:.0f}-{hi * deg:.0f} deg' for lo, hi, *_ in an.segments() if an.windows[lo])}."]
    fmt = "{:.1e}".format
    if casadi:
        out += ["", "| method | rtol | scaled error | inside the windows | outside | steps | RHS evaluations |",
                "|---|---|---|---|---|---|---|"]
        out += [f"| {r['method']} | {r['rtol']:g} | {fmt(r['state'])} | {fmt(r['inside'])} | {fmt(r['outside'])} | "
                f"{r['steps']:,} | {r['rhs']:,} |" for r in casadi]
    if scipy:
        out += ["", "| scipy method (numba RHS, switched) | rtol | scaled error | inside | outside | RHS evaluations "
                "(Jacobians) |", "|---|---|---|---|---|---|"]
        for r in scipy:
            if "failed" in r:
                out.append(f"| {r['method']} | {r['rtol']:g} | failed: {r['failed']} | | | {r['rhs']:,} |")
            else:
                out.append(f"| {r['method']} | {r['rtol']:g} | {fmt(r['state'])} | {fmt(r['inside'])} | "
                           f"{fmt(r['outside'])} | {r['rhs']:,} ({r['jacobians']:,}) |")
        at = {m: evaluations_at(scipy, m, 1e-6) for m in dict.fromkeys(r["method"] for r in scipy)}
        out += ["", "RHS evaluations for a scaled error of 1e-6 (interpolated on each method's Pareto front): "
                + ", ".join(f"{m} {_reached(scipy, m, n)}" for m, n in at.items()) + "."]
    if split:
        out += ["", "| integration | rtol | scaled error | inside | outside | steps (in the windows) | CPU / rev |",
                "|---|---|---|---|---|---|---|"]
        out += [f"| {r['plan']} | {r['rtol']:g} | {fmt(r['state'])} | {fmt(r['inside'])} | {fmt(r['outside'])} | "
                f"{r['steps']:,}" + (f" ({r['steps_inside']:,})" if r["segments"] > 1 else "")
                + f" | {r['cpu_ms']:.1f} ms |" for r in split]
    return "\n".join(out)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rtols", default="1e-6,1e-7,1e-8,1e-9", help="erk's and rosenbrock's tolerances")
    ap.add_argument("--ring", type=float, default=20.0, help="degrees after a switch that belong to its window")
    ap.add_argument("--no-scipy", action="store_true", help="skip scipy's methods (they need numba)")
    ap.add_argument("--no-split", action="store_true", help="skip the erk/rosenbrock split by phase")
    ap.add_argument("--event-tol", type=float, default=None,
                    help="also erk with its events located to this crank angle (rad; the run's default is 1e-10)")
    ap.add_argument("--velocity-scale", default=None,
                    help="also erk, LSODA and RK45 with the integrated velocities scaled these times larger, e.g. 10,30")
    a = ap.parse_args(argv)
    rtols = tuple(float(x) for x in a.rtols.split(","))
    log = lambda row: print("  ", row, flush=True)  # noqa: E731  (progress: one line per point)
    print("reference and switch windows ...", flush=True)
    an = Anatomy(ring_deg=a.ring)
    casadi = an.casadi_rows(rtols=rtols, log=log)
    if a.event_tol is not None:
        casadi += an.casadi_rows(methods=("erk",), rtols=rtols, event_tol=a.event_tol, log=log)
    scipy = [] if a.no_scipy else scipy_rows(an, log=log)
    for k in [] if a.velocity_scale is None else [float(x) for x in a.velocity_scale.split(",")]:
        casadi += an.casadi_rows(methods=("erk",), rtols=rtols, velocity_scale=k, log=log)
        scipy += [] if a.no_scipy else scipy_rows(an, methods=("LSODA", "RK45"), rtols=rtols, velocity_scale=k, log=log)
    split = [] if a.no_split else an.split_rows(rtols=rtols[1:], log=log)
    print(markdown(an, casadi, scipy, split, a.ring))


if __name__ == "__main__":
    main()
