"""The composite method's measurements: RK45 where contacts switch, an exponential step between.

``python -m apexseal.runtime.bench.composite [--rtols 1e-7,1e-8,1e-9,1e-10]`` (under a minute; the settings of
:data:`SETTINGS`; docs/bench/composite.md), ``--hard 60`` (the stress scenes, 7 minutes;
docs/bench/composite-hard.md), ``--rules`` (the run method's rules beside what they replace) and ``--default-run``
(a user's run of the default scene; both in docs/bench/composite-rules.md), all read in docs/bench/levers.md,
"Where the error and the work are".

runtime/bench/anatomy.py found the benchmark's error inside the switch windows (the impacts at the chamber
switches and the degrees of ringing after them) and two thirds of erk's steps between them, where the error is
4-7 decades smaller; runtime/bench/exponential.py found that an exponential Rosenbrock step (exprb32) crosses
those degrees in about two steps per degree when its tolerance on the velocities is loose. This prototype puts the
two together with a rule that needs no oracle:

* **tight phase**: Dormand and Prince's RK5(4) (scipy's RK45) at ``rtol`` on the
  benchmark's scaled state (``atol = rtol``), events located on the step (Illinois method, as exprb32's);
* **quiet phase**, from ``ring`` degrees after the last contact event: exprb32 at ``loose`` times ``rtol``, with the
  velocities' tolerance ``quiet`` times looser still;
* a quiet step across which a zero function changes sign is not taken: the tight phase takes over from the step's
  start, so every switch is located and integrated by RK45 at ``rtol``.

It is written twice: with numba on the peer's right-hand side (runtime/bench/peer_source.py), and in C generated at
the station (generated/templates/apexseal_composite.in.c, compiled into the model library, calling its hybrid_ode
and hybrid_zero; :func:`composite_c`). The CPU times of both are beside erk's (generated C, compiled) measured in
the same run, each the median of ``repeats`` after a warm-up. The C is the run method ``composite``
(runtime/solving/composite.py), with the run's limits, checks and diagnosis around it; the numba prototype has
none of them.
"""

from __future__ import annotations

import argparse
import math
import re

import numpy as np

from .anatomy import Anatomy, windowed_errors
from .config import METHODS
from .exponential import make_kernels
from .metrics import errors, trajectory
from .timing import warm_median

#: the most steps (rejected ones included) of one run
MAX_STEPS = 10_000_000
#: (loose, quiet, ring) of the quiet phase: its rtol is ``loose`` times the tight one, its velocities' tolerance
#: ``quiet`` times looser still, and it starts ``ring`` degrees after the last event
SETTINGS = ((100.0, 100.0, 20.0), (1.0, 1000.0, 20.0), (100.0, 1000.0, 20.0), (100.0, 100.0, 10.0))


#: Dormand and Prince's RK5(4)7M: nodes, stages, the fifth-order weights and the error weights (fifth minus fourth)
DP_C = np.array([0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0, 1.0])
DP_A = np.array([
    [0, 0, 0, 0, 0, 0],
    [1 / 5, 0, 0, 0, 0, 0],
    [3 / 40, 9 / 40, 0, 0, 0, 0],
    [44 / 45, -56 / 15, 32 / 9, 0, 0, 0],
    [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729, 0, 0],
    [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656, 0],
    [35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84]])
DP_B = np.append(DP_A[6], 0.0)  # b7 = 0: the fifth-order solution is the seventh stage's point
DP_E = np.array([71 / 57600, 0, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40])


def make_composite(problem, nm):
    """``run(z0, rtol, loose, quiet, ring, ev_tol, max_steps, Z, phase) -> (tight steps, quiet steps, rejected,
    evaluations, Jacobians, events, quiet steps given back, output intervals done)``, filling the hybrid states at
    the samples ``Z`` and, per output interval, the fraction of its steps that were quiet ``phase``; it stops once
    its steps (rejected ones included) exceed ``max_steps``."""
    import numba

    kn = make_kernels(problem, nm)
    F, zeros, jacobian, exprb, NW = kn["F"], kn["zeros"], kn["jacobian"], kn["exprb"], kn["NW"]
    toggle, norm = kn["toggle"], kn["norm"]
    N, DTH, n_g = problem.samples, problem.span / problem.samples, nm.n_guards
    C, A, B, E = DP_C, DP_A, DP_B, DP_E

    @numba.njit
    def dp45(w, s, k, h, f0, K, cnt):
        """One RK45 step from w (F(w) = f0): (w+, error estimate); K (9, 7) is scratch: the stages in K[:7] (F(w+)
        in K[6]), the stage point in K[7], the error estimate in K[8] (returned: use it before the next step)."""
        K[0] = f0
        wj, err = K[7], K[8]
        for j in range(1, 7):
            for i in range(NW):
                acc = w[i]
                for m in range(j):
                    acc += h * A[j, m] * K[m, i]
                wj[i] = acc
            wj[6] = w[6] + C[j] * h
            F(wj, s, k, K[j])
        cnt[0] += 6
        w1 = np.empty(NW)
        for i in range(NW):
            a, e = w[i], 0.0
            for m in range(7):
                a += h * B[m] * K[m, i]
                e += h * E[m] * K[m, i]
            w1[i], err[i] = a, e
        w1[6] = w[6] + h
        return w1, err

    locate_dp = kn["make_locate"](dp45)

    @numba.njit
    def run(z0, rtol, loose, quiet, ring, ev_tol, max_steps, Z, phase):
        w = np.empty(NW)
        w[:6], w[6] = z0[:6], 0.0
        s, counts = z0[6:6 + n_g].copy(), z0[6 + n_g:].copy()
        f0, J, K, cnt = np.empty(NW), np.empty((NW, NW)), np.empty((9, NW)), np.zeros(1, np.int64)
        e0, e1 = np.empty(n_g), np.empty(n_g)
        h_t, h_q, last_event = 1e-5, 1e-3, 0.0
        tight, quiet_steps, rejected, jacobians, events, given_back = 0, 0, 0, 0, 0, 0
        F(w, s, 0, f0)
        cnt[0] += 1
        for k in range(N):
            t_end = (k + 1) * DTH
            q_before, all_before = quiet_steps, tight + quiet_steps  # (f0 holds: the pressures are continuous)
            while w[6] < t_end * (1 - 1e-14):
                if tight + quiet_steps + rejected > max_steps:
                    return tight, quiet_steps, rejected, cnt[0], jacobians, events, given_back, k
                zeros(w, s, k, e0)
                if w[6] - last_event > ring:  # quiet: exprb32, the velocities' tolerance ``quiet`` times looser
                    jacobian(w, s, k, f0, J, cnt)
                    jacobians += 1
                    while True:
                        hh = min(h_q, t_end - w[6])
                        w1, err_v = exprb(w, s, k, hh, f0, J, cnt)
                        err = norm(w, w1, err_v, rtol * loose, quiet)
                        if np.isfinite(err) and err <= 1.0:
                            break
                        rejected += 1
                        h_q = hh * (max(0.2, 0.9 * err ** (-1 / 3)) if np.isfinite(err) else 0.2)
                    zeros(w1, s, k, e1)
                    if ((e1 < 0.0) & (e0 >= 0.0)).any():  # a switch ahead: the tight phase takes this step over
                        given_back += 1
                        last_event = w[6]
                        h_t = min(h_t, hh)
                        continue
                    h_q = hh * min(5.0, max(0.2, 0.9 * max(err, 1e-10) ** (-1 / 3)))
                    w = w1
                    F(w, s, k, f0)
                    cnt[0] += 1
                    quiet_steps += 1
                    continue
                while True:  # tight: RK45 at rtol
                    hh = min(h_t, t_end - w[6])
                    w1, err_v = dp45(w, s, k, hh, f0, K, cnt)
                    err = norm(w, w1, err_v, rtol, 1.0)
                    if np.isfinite(err) and err <= 1.0:
                        break
                    rejected += 1
                    h_t = hh * (max(0.2, 0.9 * err ** (-1 / 5)) if np.isfinite(err) else 0.2)
                zeros(w1, s, k, e1)
                if ((e1 < 0.0) & (e0 >= 0.0)).any():
                    w1, e1 = locate_dp(w, s, k, hh, f0, K, cnt, e0, e1, ev_tol)
                    events += toggle(e1, s, counts)
                    last_event = w1[6]
                    h_t = max(0.5 * hh, 1e-9)
                    w = w1
                    F(w, s, k, f0)
                    cnt[0] += 1
                else:
                    h_t = hh * min(5.0, max(0.2, 0.9 * max(err, 1e-10) ** (-1 / 5)))
                    w = w1
                    f0[:] = K[6]  # first same as last
                tight += 1
            n_k = tight + quiet_steps - all_before
            phase[k] = (quiet_steps - q_before) / n_k if n_k else 1.0
            Z[:6, k], Z[6:6 + n_g, k], Z[6 + n_g:, k] = w[:6], s, counts
        return tight, quiet_steps, rejected, cnt[0], jacobians, events, given_back, N

    return run


def composite_c(problem, rtol: float, loose: float | None, quiet: float | None, ring: float | None,
                ev_tol: float = 1e-10, max_steps: int = MAX_STEPS, stiff_steps: int | None = None,
                stiff_hlam: float | None = None):
    """The same method in generated C: the run method's engine (runtime/solving/composite.py, calling
    templates/apexseal_composite.in.c compiled into the model library) over ``problem``'s span and grid, with this
    setting of its quiet phase (None: the engine's rule) and no event limit; ``max_steps`` per output interval."""
    from ...generated.load import load_functions
    from ..solving.composite import CompositeIntegrator

    loaded = load_functions(problem.effects, problem.scene.assumptions, compiled=True)
    if loaded.library is None:
        raise RuntimeError("the model library is not compiled (no C compiler): the composite needs it")
    return CompositeIntegrator(loaded.c, n_samples=problem.samples, span=problem.span, rtol=rtol, event_tol=ev_tol,
                               max_steps=max_steps, max_events=10**8, pressure=problem.pressure, loose=loose,
                               quiet=quiet, ring=ring, stiff_steps=stiff_steps, stiff_hlam=stiff_hlam)


def erk_cpu(an: Anatomy, rtol: float, repeats: int) -> tuple[float, float]:
    """erk's (generated C, compiled) CPU time per revolution (median of ``repeats`` after a warm-up) and error."""
    p = an.problem
    eng = an.engines.get("all", an.functions, METHODS["erk-C"], rtol, compiled=True)
    out, cpu = warm_median(lambda: eng.run(p.z0, p.params, p.theta0, p.pressures), repeats)
    return cpu, errors(trajectory(p, out.z), an.ref)["state"]


def rows(an: Anatomy, rtols=(1e-7, 1e-8, 1e-9, 1e-10), settings=SETTINGS, repeats: int = 5, ev_tol: float = 1e-10,
         erk: bool = True, log=print) -> list[dict]:
    """The composite at each setting and rtol (beside erk-C at the same rtol): steps by phase, evaluations, errors,
    CPU times."""
    from .peer_source import numba_model

    p = an.problem
    nm = numba_model(p.effects, p.scene.assumptions)
    run = make_composite(p, nm)
    Z, phase = np.empty((6 + 2 * nm.n_guards, p.samples)), np.empty(p.samples)
    run(p.z0, 1e-4, 1.0, 1.0, 0.0, ev_tol, MAX_STEPS, Z, phase)  # compiles
    erk_points = {rtol: erk_cpu(an, rtol, repeats) if erk else (math.nan, math.nan) for rtol in rtols}
    out = []
    for loose, quiet, ring_deg in settings:
        args = (loose, quiet, math.radians(ring_deg), ev_tol, MAX_STEPS, Z, phase)
        for rtol in rtols:
            # the timed runs write the same states into Z as the first
            stats, cpu = warm_median(lambda rtol=rtol, args=args: run(p.z0, rtol, *args), repeats)
            traj = trajectory(p, Z)
            tight, quiet_steps, rejected, rhs, jac, events, given_back, _ = (int(x) for x in stats)
            # the prototype's method: the quiet phase from `ring` on, without the run method's stiffness count
            eng = composite_c(p, rtol, loose, quiet, math.radians(ring_deg), ev_tol, stiff_steps=0)
            out_c, cpu_c = warm_median(lambda eng=eng: eng.run(p.z0, p.params, p.theta0, p.pressures), repeats)
            row = {"loose": loose, "quiet": quiet, "ring_deg": ring_deg, "rtol": rtol, "tight_steps": tight,
                   "quiet_steps": quiet_steps, "rejected": rejected, "rhs": rhs, "jacobians": jac, "events": events,
                   "given_back": given_back, "quiet_inside": float(np.mean(phase[an.windows] > 0)),
                   "cpu_ms": 1e3 * cpu, "erk_cpu_ms": 1e3 * erk_points[rtol][0],
                   "erk_state": erk_points[rtol][1], "c_state": errors(trajectory(p, out_c.z), an.ref)["state"],
                   "c_cpu_ms": 1e3 * cpu_c, "c_rhs": out_c.stats["n_rhs"], "c_events": out_c.stats["n_events"]}
            row |= windowed_errors(traj, an.ref, an.windows)
            out.append(row)
            log(row)
    return out


def markdown(an: Anatomy, rs: list[dict]) -> str:
    ref_events = int(an.ref.events.sum())
    lines = [f"| {r['loose']:g}, {r['quiet']:g}, {r['ring_deg']:g} deg | {r['rtol']:g} | {r['state']:.1e} | "
             f"{r['inside']:.1e} | {r['outside']:.1e} | {r['tight_steps']:,} | {r['quiet_steps']:,} | "
             f"{r['events']} ({ref_events}) | {r['rhs']:,} ({r['jacobians']:,}) | {r['cpu_ms']:.1f} ms | "
             f"{r['c_state']:.1e} / {r['c_rhs']:,} / {r['c_cpu_ms']:.1f} ms | {r['erk_state']:.1e} | "
             f"{r['erk_cpu_ms']:.1f} ms |" for r in rs]
    return "\n".join(["| quiet phase: loose, quiet, ring | rtol | scaled error | inside | outside | RK45 steps | "
                      "exprb32 steps | events (reference) | RHS evaluations (Jacobians) | CPU / rev (numba) | "
                      "generated C: scaled error / RHS evaluations / CPU per rev | erk-C at this rtol: scaled error | "
                      "erk-C: CPU / rev |", "|---" * 13 + "|", *lines])


def cluster_rows(an: Anatomy, rtols=(1e-8, 1.58e-8), before: int = 3) -> list[dict]:
    """Where the error of a revolution arises: the scaled error at each sample from ``before`` samples ahead of each
    cluster of switching intervals (the reference's) to its end, for the run method at each rtol and for RK45 alone
    (its events located to min(1e-10, 1e-3 rtol) rad) at the first."""
    from ..solving.composite import EVENTS_PER_RTOL
    from .anatomy import sample_errors

    p, sw = an.problem, np.flatnonzero(an.switched)
    clusters = np.split(sw, np.flatnonzero(np.diff(sw) > 1) + 1) if sw.size else []
    runs = [(f"the run method, rtol {rtol:g}", composite_c(p, rtol, None, None, None)) for rtol in rtols]
    runs.append((f"RK45 alone, rtol {rtols[0]:g}",
                 composite_c(p, rtols[0], 1.0, 1.0, math.inf, min(1e-10, EVENTS_PER_RTOL * rtols[0]), stiff_steps=0)))
    out = []
    for label, eng in runs:
        e = sample_errors(trajectory(p, eng.run(p.z0, p.params, p.theta0, p.pressures).z), an.ref)
        for c in clusters:
            ks = range(max(0, int(c[0]) - before), int(c[-1]) + 1)
            out.append({"run": label, "samples": [int(k) for k in ks], "errors": [float(e[k]) for k in ks],
                        "elsewhere": float(np.delete(e, np.concatenate(clusters)).max())})
    return out


def cluster_markdown(rs: list[dict], dtheta_deg: float) -> str:
    lines = [f"| {r['run']} | {r['samples'][0] * dtheta_deg:g}-{r['samples'][-1] * dtheta_deg:g} | "
             + " ".join(f"{v:.0e}" for v in r["errors"]) + f" | {r['elsewhere']:.0e} |" for r in rs]
    return "\n".join(["| run | samples (deg) | scaled error at each sample | largest outside the clusters |",
                      "|---|---|---|---|", *lines])


def default_run_rows(rtols=(1e-6, 1e-8), samples=(720, 3600), revolutions: int = 3, repeats: int = 3,
                     log=print) -> list[dict]:
    """What a user's run gets: ``apexseal.simulate`` of the default scene (``revolutions`` from its start) with erk
    and with the composite, at each rtol and output grid (720 samples: one per pressure row; 3600: the default's):
    integration wall time per revolution (the run's own timing, median of ``repeats`` after a warm-up), the
    composite's steps by phase."""
    import statistics

    import apexseal

    scene = apexseal.load_scene()
    out = []
    for n in samples:
        for rtol in rtols:
            for method in ("erk", "composite"):
                runs = [apexseal.simulate(scene, method=method, rtol=rtol, revolutions=revolutions,
                                          samples_per_revolution=n) for _ in range(repeats + 1)][1:]
                st = runs[-1].info["solver_stats"]
                row = {"samples": n, "rtol": rtol, "method": method,
                       "ms_per_rev": 1e3 * statistics.median(r.info["timings_s"]["integrate"] for r in runs)
                       / revolutions, "tight_steps": st.get("n_tight_steps"), "quiet_steps": st.get("n_quiet_steps")}
                out.append(row)
                log(row)
    return out


def default_run_markdown(rs: list[dict]) -> str:
    def steps(r):
        return "–" if r["tight_steps"] is None else f"{r['tight_steps']:,} + {r['quiet_steps']:,}"

    lines = [f"| {r['samples']} | {r['rtol']:g} | {r['method']} | {r['ms_per_rev']:.1f} ms | {steps(r)} |" for r in rs]
    return "\n".join(["| samples per revolution | rtol | method | integration per revolution | RK45 + exprb32 steps |",
                      "|---|---|---|---|---|", *lines])


#: the variants :func:`rule_rows` sets beside the run method's rules: (label, loose, quiet, ring in deg, event_tol,
#: stiff_steps, stiff_hlam); None: the engine's rule (runtime/solving/composite.py), math.inf: no quiet phase
RULE_VARIANTS = (
    ("the run method (its rules)", None, None, None, 1e-10, None, None),
    ("its rules, the quiet phase only after the ringing window (no stiffness count)", None, None, None, 1e-10, 0, None),
    ("its rules, quiet after 5 steps at the stability boundary (not 15)", None, None, None, 1e-10, 5, None),
    ("its rules, quiet after 30 steps at the stability boundary (not 15)", None, None, None, 1e-10, 30, None),
    ("quiet phase 100, 100 uncapped, events to 1e-10 rad", 100.0, 100.0, 20.0, 1e-10, None, None),
    ("RK45 alone, events to 1e-10 rad", 1.0, 1.0, math.inf, 1e-10, 0, None),
    ("RK45 alone, events to min(1e-10, 1e-3 rtol) rad", 1.0, 1.0, math.inf, None, 0, None),
    ("its rules, stiff once the step's estimate of h lambda exceeds 2.0 (not 3.25)", None, None, None, 1e-10, None, 2.0),
)


def rule_rows(an: Anatomy, rtols=(1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10), variants=RULE_VARIANTS, repeats: int = 3,
              log=print) -> list[dict]:
    """The run method's rules (runtime/solving/composite.py: the quiet phase's caps, no quiet phase below rtol 1e-8,
    events located more tightly there) beside what they replace, in generated C on the benchmark's problem:
    scaled error, evaluations, CPU per revolution (median of ``repeats`` after a warm-up)."""
    from ..solving.composite import EVENTS_PER_RTOL

    p = an.problem
    out = []
    for label, loose, quiet, ring_deg, ev_tol, stiff_steps, stiff_hlam in variants:
        for rtol in rtols:
            ev = min(1e-10, EVENTS_PER_RTOL * rtol) if ev_tol is None else ev_tol
            ring = None if ring_deg is None else math.radians(ring_deg)
            eng = composite_c(p, rtol, loose, quiet, ring, ev, stiff_steps=stiff_steps, stiff_hlam=stiff_hlam)
            res, cpu = warm_median(lambda eng=eng: eng.run(p.z0, p.params, p.theta0, p.pressures), repeats)
            row = {"variant": label, "rtol": rtol, "state": errors(trajectory(p, res.z), an.ref)["state"],
                   "rhs": res.stats["n_rhs"], "quiet_steps": res.stats["n_quiet_steps"],
                   "events": res.stats["n_events"], "cpu_ms": 1e3 * cpu}
            out.append(row)
            log(row)
    return out


def rule_markdown(an: Anatomy, rs: list[dict]) -> str:
    ref_events = int(an.ref.events.sum())
    lines = [f"| {r['variant']} | {r['rtol']:g} | {r['state']:.1e} | {r['events']} ({ref_events}) | {r['rhs']:,} | "
             f"{r['quiet_steps']:,} | {r['cpu_ms']:.1f} ms |" for r in rs]
    return "\n".join(["| variant (generated C) | rtol | scaled error | events (reference) | RHS evaluations | "
                      "exprb32 steps | CPU / rev |", "|---|---|---|---|---|---|---|", *lines])


def hard_rows(names=None, degrees: float = 60.0, rtol: float = 1e-8, setting=SETTINGS[0], max_steps: int = 2_000_000,
              log=print) -> list[dict]:
    """The composite on the first ``degrees`` of each stress scene (runtime/scenes/hard/, from its initial state,
    1-degree output intervals, linear pressures) beside erk at the same rtol, both against erk at rtol 1e-10 with
    events located to 1e-12 rad (interpreted engines): switches, scaled error over the span, steps; a run that
    fails or exceeds ``max_steps`` says so."""
    from pathlib import Path

    from ..scenes.scene import load_scene
    from .peer_source import numba_model
    from .problem import load_model, make_problem

    hard = Path(__file__).resolve().parents[1] / "scenes" / "hard"
    names = names or sorted(q.stem for q in hard.glob("*.toml"))
    samples, span = int(round(degrees)), math.radians(degrees)
    out = []
    for name in names:
        scene = load_scene(hard / f"{name}.toml")
        functions, _ = load_model(scene.effects, scene.assumptions)
        p = make_problem(name, scene, scene.effects, functions, samples=samples, span=span, settle_revolutions=0,
                         pressure_profile="linear")
        row: dict = {"scene": name}
        try:
            ref = _erk(p, 1e-10, 1e-12)
        except Exception as exc:  # noqa: BLE001  (a stress scene may defeat the reference: say so)
            row |= {"reference": _failure(exc)}
            ref = None
        ref_traj = None if ref is None else trajectory(p, ref.z)
        if ref_traj is not None:
            row["reference_events"] = int(ref_traj.events.sum())
        try:
            plain = _erk(p, rtol)
            plain_traj = trajectory(p, plain.z)
            row |= {"erk_steps": int(plain.stats["n_steps"]), "erk_events": int(plain_traj.events.sum())}
            if ref_traj is not None:
                row["erk_state"] = errors(plain_traj, ref_traj)["state"]
        except Exception as exc:  # noqa: BLE001
            row["erk"] = _failure(exc)
        run = make_composite(p, numba_model(scene.effects, scene.assumptions))
        Z, phase = np.full((p.z0.size, samples), np.nan), np.empty(samples)
        loose, quiet, ring_deg = setting
        stats = run(p.z0, rtol, loose, quiet, math.radians(ring_deg), 1e-10, max_steps, Z, phase)
        tight, quiet_steps, rejected, rhs, _, events, _, done = (int(x) for x in stats)
        row |= {"tight_steps": tight, "quiet_steps": quiet_steps, "rejected": rejected, "events": events,
                "done_deg": done * degrees / samples}
        if done == samples and ref_traj is not None and np.isfinite(Z).all():
            row["state"] = errors(trajectory(p, Z), ref_traj)["state"]
        out.append(row)
        log(row)
    return out


def _failure(exc: Exception) -> str:
    """"failed: " and the last line of an integrator's error (CasADi's: its innermost message, without the source
    file it was raised in)."""
    last = [line for line in str(exc).splitlines() if line.strip()][-1]
    return "failed: " + re.sub(r"^\S*\.(hpp|cpp):\d+:\s*", "", last)[:80]


def _erk(p, rtol: float, event_tol: float | None = None):
    """erk (interpreted) over problem ``p`` at ``rtol``, events located to ``event_tol`` (None: the run's)."""
    from .methods import build_engine

    eng = build_engine(p.functions, METHODS["erk-C"], rtol, samples=p.samples, span=p.span, flags="optimised",
                       compiled=False, event_tol=event_tol, pressure="linear")
    return eng.run(p.z0, p.params, p.theta0, p.pressures)


def hard_markdown(rs: list[dict], degrees: float, rtol: float) -> str:
    def cell(r, key, fmt="{:,}"):
        return fmt.format(r[key]) if key in r else "–"

    lines = []
    for r in rs:
        ref = r.get("reference", cell(r, "reference_events"))
        erk = r.get("erk", f"{cell(r, 'erk_events')} / {cell(r, 'erk_state', '{:.1e}')} / {cell(r, 'erk_steps')}")
        stop = "" if r["done_deg"] >= degrees else f"stopped at {r['done_deg']:g}° (step budget); "
        lines.append(f"| {r['scene']} | {ref} | {erk} | {stop}{r['events']:,} / {cell(r, 'state', '{:.1e}')} / "
                     f"{r['tight_steps']:,} + {r['quiet_steps']:,} |")
    return "\n".join([f"The first {degrees:g}° of each stress scene at rtol {rtol:g}; the reference is erk at rtol 1e-10 "
                      "with events to 1e-12 rad.", "", "| scene | reference: switches | erk: switches / scaled error / "
                      "steps | composite: switches / scaled error / RK45 + exprb32 steps |", "|---|---|---|---|",
                      *lines])


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rtols", default=None, help="comma-separated (default: 1e-7 .. 1e-10; with --rules 1e-4 .. 1e-10)")
    ap.add_argument("--variants", default=None, help="with --rules: the indices of RULE_VARIANTS to run (default: all)")
    ap.add_argument("--hard", type=float, default=None, metavar="DEGREES",
                    help="instead: the first DEGREES of every stress scene at rtol 1e-8 (hard_rows)")
    ap.add_argument("--rules", action="store_true", help="instead: the run method's rules beside what they replace "
                    "(rule_rows)")
    ap.add_argument("--clusters", action="store_true", help="instead: the error at each sample around the clusters "
                    "of switches, the run method at --rtols (default 1e-8,1.58e-8) and RK45 alone (cluster_rows)")
    ap.add_argument("--default-run", action="store_true", help="instead: the default scene's run with erk and the "
                    "composite on the default's and a coarser output grid (default_run_rows)")
    a = ap.parse_args(argv)
    if a.default_run:
        print(default_run_markdown(default_run_rows(log=lambda r: print("  ", r, flush=True))))
        return
    if a.hard is not None:
        print(hard_markdown(hard_rows(degrees=a.hard, log=lambda r: print("  ", r, flush=True)), a.hard, 1e-8))
        return
    print("reference and switch windows ...", flush=True)
    an = Anatomy()
    rtols = {} if a.rtols is None else {"rtols": tuple(float(x) for x in a.rtols.split(","))}
    if a.clusters:
        print(cluster_markdown(cluster_rows(an, **rtols), math.degrees(an.dtheta)))
        return
    if a.rules:
        if a.variants is not None:
            rtols["variants"] = [RULE_VARIANTS[int(i)] for i in a.variants.split(",")]
        print(rule_markdown(an, rule_rows(an, **rtols, log=lambda r: print("  ", r, flush=True))))
        return
    rs = rows(an, **rtols, log=lambda r: print("  ", r, flush=True))
    print(markdown(an, rs))


if __name__ == "__main__":
    main()
