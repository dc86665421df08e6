"""Run the whole benchmark: model, compilation, then per scene settle, reference and every point; targets; effects.

Order matters on a shared, noisy machine: everything that compiles happens
first (``compile_pool.precompile``), then the timed runs, one at a time; ratios
are taken between points of this one run.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import asdict, dataclass, field

from .compile_pool import cold_compile, precompile
from .config import METHODS, BenchConfig
from .effects import run_effects
from .methods import EngineCache, compile_target
from .metrics import time_at_error
from .points import casadi_point, failed_point, peer_point, point_base, scipy_point
from .problem import load_model, make_problem
from .reference import check_reference, solve_reference
from .rhs_cost import rhs_costs
from .timing import machine_info

MODEL = "all"  # engine-cache key of the full model with SX functions
MODEL_C = "all/c"  # ... with the compiled model library (stepper methods)
#: compiled method -> its interpreted twin (for the value of code generation)
VM_TWIN = {"erk-C": "erk-VM", "rosenbrock-C": "rosenbrock-VM"}


class NothingToMeasure(Exception):
    """Every method asked for is unavailable here (numba or numbalsoda not installed): said before settling."""


def run_benchmark(cfg: BenchConfig, *, log=print, into: dict | None = None) -> dict:
    """Run the benchmark ``cfg`` describes; the returned dict is what ``output.write_outputs`` writes. ``into``: the
    dict to fill, point by point (a run stopped halfway leaves there what it measured: :func:`partial_results`)."""
    from ...generated.load import load_functions
    from ..scenes.scene import load_scene

    t0 = time.perf_counter()
    cfg, skipped = _available(cfg, log)
    if not any(s.sweeps for s in cfg.scenes):
        raise NothingToMeasure("no method left to measure: " + "; ".join(f"{s['method']}: {s['reason']}"
                                                                         for s in skipped))
    results: dict = into if into is not None else {}
    results.update({"config": _config_dict(cfg), "machine": machine_info(), "skipped": skipped,
                    "started_wall": t0})  # time.perf_counter() at the start: a partial run's elapsed time
    base = load_scene()
    log("model: deriving / loading")
    sx, derive_info = load_model(base.effects, base.assumptions)
    results["model"] = derive_info | {"rhs_instructions": int(sx.rhs.n_instructions())}
    specs = cfg.methods_used()
    c_model = None
    if any(s.model_c for s in specs):
        w0, c0 = time.perf_counter(), time.process_time()
        c_model = load_functions(base.effects, base.assumptions, flags=cfg.flags).c
        results["model"]["library_load_wall_s"] = time.perf_counter() - w0  # includes its compile when not cached
        results["model"]["library_load_cpu_s"] = time.process_time() - c0

    engines = EngineCache(samples=cfg.samples, span=math.radians(cfg.span_deg), flags=cfg.flags, pressure=cfg.pressure)

    def pool(targets):
        return precompile(targets, flags=cfg.flags, workers=cfg.workers, log=log)

    log("compiling integrators (C generated serially, gcc in parallel)")
    ref_tols = (cfg.reference_rtol, cfg.reference_event_tol)
    targets = [compile_target(engines.reference(MODEL, sx, *ref_tols, compiled=False))]
    for s in cfg.scenes:
        for mid, values in s.sweeps.items():
            spec = METHODS[mid]
            if spec.compiled:
                targets += [compile_target(engines.get(MODEL, sx, spec, v, compiled=False)) for v in values]
    results["compile"] = pool(targets)

    ctx = _Context(cfg, engines, sx, c_model, base)
    scenes = results["scenes"] = []  # each scene's entry from its reference on, its points as they are measured
    for s in cfg.scenes:
        _run_scene(ctx, s, log, with_rhs_cost=not scenes, into=scenes)
    results["summary"] = summarise(scenes, cfg.target_error)
    if cfg.cold_compile:
        results["cold_compile"] = _cold_compile(results["summary"], scenes, cfg, engines, sx, log)
    results["targets"] = targets_table(results, cfg)
    if cfg.effects is not None:
        log("effects cost")
        results["effects"] = run_effects(base, cfg, engines, precompile=pool, log=log)
    if cfg.e2e_revolutions:
        from .e2e import end_to_end

        results["e2e"] = end_to_end(cfg.e2e_revolutions, cfg.e2e_repeats, log=log)
    if cfg.gas_revolutions:
        from .gas_cost import gas_cost

        results["gas"] = gas_cost(cfg.gas_revolutions, cfg.repeats, log=log)
    results["machine"]["load_average_at_end"] = list(os.getloadavg())
    results["elapsed_wall_s"] = time.perf_counter() - results.pop("started_wall")
    return results


def partial_results(results: dict, cfg: BenchConfig, why: str) -> dict | None:
    """What a run stopped halfway (``why``: the signal) measured, as a result of its own: the points measured, with
    the summary, targets and peer ratios over them and ``interrupted`` saying so; None when no point was measured
    (nothing to report)."""
    scenes = [s for s in results.get("scenes", []) if s["points"]]
    if not scenes:
        return None
    done = dict(results, scenes=scenes)
    done["summary"] = summarise(scenes, cfg.target_error)
    done["targets"] = targets_table(done, cfg)
    done["interrupted"] = (f"{why}: {sum(len(s['points']) for s in scenes)} of "
                           f"{sum(len(v) for s in cfg.scenes for v in s.sweeps.values())} points measured; the "
                           "effects, end-to-end and cold-compile parts not run")
    for part in ("effects", "e2e", "gas", "cold_compile"):
        done.pop(part, None)
    done["machine"] = dict(done["machine"], load_average_at_end=list(os.getloadavg()))
    started = done.pop("started_wall", None)
    done["elapsed_wall_s"] = time.perf_counter() - started if started is not None else done.get("elapsed_wall_s")
    return done


def _takes_linear_pressure(spec) -> bool:
    """The numba peer, the lambdify baselines and every apexseal engine that lists "linear" in its
    ``pressure_profiles`` (all of apexseal's own) take pressures linear over each interval."""
    from ..solving.fixed_step import RK4Integrator
    from ..solving.methods import method_of

    if spec.kind in ("peer", "scipy"):
        return True
    engine = {"rk4": RK4Integrator}.get(spec.kind) or (method_of(spec.method).engine_class()
                                                       if spec.kind == "casadi" else None)
    return engine is not None and "linear" in engine.pressure_profiles


def _available(cfg: BenchConfig, log) -> tuple[BenchConfig, list[dict]]:
    """Drop the peer methods whose packages are missing (numba; numbalsoda, which needs gfortran), with a note."""
    from .config import NEEDS_NUMBALSODA
    from .peer_numba import numba_available, numbalsoda_available

    skipped = []
    for spec in cfg.methods_used():
        if cfg.pressure != "steps" and not _takes_linear_pressure(spec):
            why = f"pressure = {cfg.pressure!r}: this method holds the pressures per output interval"
            skipped.append({"method": spec.id, "reason": why})
            log(f"note: skipping {spec.id}: {why}")
            continue
        if spec.kind != "peer":
            continue
        why = numbalsoda_available() if spec.id in NEEDS_NUMBALSODA else numba_available()
        if why:
            skipped.append({"method": spec.id, "reason": why})
            log(f"note: skipping {spec.id}: {why}")
    return (cfg.without(tuple(s["method"] for s in skipped)) if skipped else cfg), skipped


def _run_scene(ctx, s, log, *, with_rhs_cost: bool, into: list) -> dict:
    """Settle, reference (and its check), then every point of one scene; its entry is appended to ``into`` once its
    reference is solved, and each point to the entry as it is measured."""
    cfg, engines, sx, c_model, base = ctx.cfg, ctx.engines, ctx.sx, ctx.c_model, ctx.base
    ref_tols = (cfg.reference_rtol, cfg.reference_event_tol)
    scene = base.with_overrides(**s.overrides) if s.overrides else base
    log(f"scene {s.name}: settling {cfg.settle_revolutions} revolutions")
    settle_engine, settle_settings = engines.settle(MODEL, sx, *ref_tols)
    problem = make_problem(s.name, scene, base.effects, sx, samples=cfg.samples, span=math.radians(cfg.span_deg),
                           settle_revolutions=cfg.settle_revolutions, settle_engine=settle_engine,
                           settle_settings=settle_settings, pressure_profile=cfg.pressure)
    ref, ref_info = solve_reference(problem, engines.reference(MODEL, sx, *ref_tols))
    ref_info |= {"rtol": cfg.reference_rtol, "atol_scaled": cfg.reference_rtol, "event_tol": cfg.reference_event_tol}
    if cfg.check_reference:
        if cfg.pressure == "steps":
            fns, key = (c_model, MODEL_C) if c_model is not None else (sx, MODEL)
            eng = engines.get(key, fns, METHODS["cvodes-C"], cfg.reference_rtol, compiled=False,
                              event_tol=cfg.reference_event_tol)
            how = "cvodes (BDF), apexseal event loop"
        else:  # rosenbrock locates every switch on its dense output; cvodes' event loop checks the guards on a
            # 0.05 deg sub-grid and can miss a bounce shorter than that (measured: 2 of 46 switches in 6 deg)
            eng = engines.get(MODEL, sx, METHODS["rosenbrock-C"], cfg.reference_rtol, compiled=True,
                              event_tol=cfg.reference_event_tol)
            how = "rosenbrock (Rosenbrock 5(4), events on dense output), compiled C"
        ref_info["check"] = check_reference(problem, ref, eng, method=how, rtol=cfg.reference_rtol,
                                            event_tol=cfg.reference_event_tol)
        d = ref_info["check"].get("difference", {})
        log(f"  reference: {ref_info['events']} events; check vs {how.split()[0]}: state "
            f"{d.get('state', float('nan')):.2g}, friction power {d.get('friction_power') or float('nan'):.2g}")
    points: list = []
    entry = {"name": s.name, "overrides": s.overrides, "problem": problem.describe(), "reference": ref_info,
             "points": points, "lambdify": ctx.lambdify_info}
    into.append(entry)
    for mid, values in s.sweeps.items():
        for v in values:
            points.append(ctx.point(problem, ref, METHODS[mid], v))
            _log_point(log, points[-1])
    entry["lambdify"] = ctx.lambdify_info
    if problem.name in ctx.peers:
        entry["peer"] = ctx.peer_info(problem.name)
    if with_rhs_cost:  # per-evaluation costs, once
        entry["rhs_cost"] = rhs_costs(problem, sx, c_model, ctx.lambdified, points, peer=ctx.peers.get(problem.name),
                                      flags=cfg.flags)
    return entry


@dataclass
class _Context:
    """What every point needs: settings, engines, the model's Functions, the lambdified model (built once)."""

    cfg: BenchConfig
    engines: EngineCache
    sx: object
    c_model: object
    base: object  # the default scene (effects, assumptions)
    lambdified: object = None
    lambdify_info: dict | None = None
    numba_model: object = None
    peers: dict = field(default_factory=dict)  # problem name -> NumbaPeer

    def peer(self, problem):
        """The hand-written numba peer of this problem (its source printed and its kernels compiled once)."""
        from .config import NEEDS_NUMBALSODA
        from .peer_numba import NumbaPeer

        if self.numba_model is None:
            from .peer_source import numba_model

            self.numba_model = numba_model(self.base.effects, self.base.assumptions)
        if problem.name not in self.peers:
            peer = self.peers[problem.name] = NumbaPeer(problem, self.numba_model)
            peer.build(numbalsoda=any(m in NEEDS_NUMBALSODA for s in self.cfg.scenes for m in s.sweeps))
        return self.peers[problem.name]

    def peer_info(self, name: str) -> dict:
        nm, peer = self.numba_model, self.peers[name]
        return {"source_lines": sum(1 for _ in nm.path.open()), "print_cpu_s": nm.print_s, "jit_wall_s": nm.jit_s,
                "kernels_build_wall_s": peer.build_s,
                "options": "sympy.cse (optimizations=None), PythonCodePrinter (math), numba.njit(error_model='numpy'), "
                           "no fastmath; integrated on the scaled state against the crank angle, atol = rtol"}

    def point(self, problem, ref, spec, value) -> dict:
        cfg = self.cfg
        kw = {"repeats": cfg.repeats, "slow_run_s": cfg.slow_run_s, "budget_s": cfg.budget_s}
        if spec.kind == "peer":
            return peer_point(problem, ref, spec, value, self.peer(problem), **kw)
        if spec.kind == "scipy":
            if self.lambdified is None:
                from .baseline_scipy import lambdify_model

                m = self.lambdified = lambdify_model(self.base.effects, self.base.assumptions)
                self.lambdify_info = {"lambdify_cpu_s": m.setup_s, "model_load_cpu_s": m.derive_s,
                                      "options": "modules='numpy', cse=True; accelerations = M.LUsolve(f)"}
            return scipy_point(problem, ref, spec, value, self.lambdified, **kw)
        fns, key = (self.c_model, MODEL_C) if spec.model_c else (self.sx, MODEL)
        w0, c0 = time.perf_counter(), time.process_time()
        try:  # an engine that cannot be built (its settings refused, a library missing) is that point's failure
            engine = self.engines.get(key, fns, spec, value, compiled=spec.compiled)
            build = time.perf_counter() - w0
            stats_engine = None
            if spec.compiled and spec.kind == "casadi" and spec.method not in ("euler", "erk-rk4"):
                stats_engine = self.engines.get(key, fns, spec, value, compiled=False)
        except Exception as exc:  # noqa: BLE001 - every failure is a result, the other points go on
            return failed_point(point_base(problem, spec, value), exc, time.process_time() - c0)
        return casadi_point(problem, ref, spec, value, engine, stats_engine=stats_engine, build_s=build, **kw)


def _log_point(log, p: dict) -> None:
    if p["status"] != "ok":
        log(f"  {p['method']:>15} {p['value']:<9g} FAILED {p.get('reason', '')[:90]}")
        return
    t = p["timing"]
    log(f"  {p['method']:>15} {p['value']:<9g} {1e3 * t['median_cpu_s']:9.1f} ms  error {p['error']['state']:.2e}  "
        f"Pf {p['error']['friction_power'] or 0:.1e}  ({t['n_timed']} timed)")


def summarise(scenes: list[dict], target: float) -> dict:
    """Per scene and method: CPU time at the target scaled error (and at the same friction-power error)."""
    out = {}
    for s in scenes:
        per = {}
        for mid in dict.fromkeys(p["method"] for p in s["points"]):
            pts = [p for p in s["points"] if p["method"] == mid]
            ok = [p for p in pts if p["status"] == "ok"]
            curve = [(p["timing"]["median_cpu_s"], p["error"]["state"]) for p in ok]
            curve_pf = [(p["timing"]["median_cpu_s"], p["error"]["friction_power"]) for p in ok]
            per[mid] = {"label": pts[0]["label"], "family": pts[0]["family"], "generated_c": pts[0]["generated_c"],
                        "at_target": time_at_error(curve, target),
                        "at_target_friction_power": time_at_error(curve_pf, target),
                        "points": len(pts), "failed": len(pts) - len(ok)}
        out[s["name"]] = per
    return out


def _best(per: dict, pred) -> tuple[str | None, float | None]:
    cands = [(v["at_target"]["time_s"], k) for k, v in per.items()
             if pred(k, v) and v["at_target"] and v["at_target"]["time_s"] is not None]
    if not cands:
        return None, None
    t, k = min(cands)
    return k, t


def best_c(per: dict) -> tuple[str | None, float | None]:
    return _best(per, lambda k, v: v["generated_c"] and k != "euler-C")


def _cold_compile(summary, scenes, cfg, engines, sx, log) -> dict | None:
    """Compile the best C integrator that has an interpreted twin (:data:`VM_TWIN`; at the setting that first
    reaches the target) in an empty cache: what code generation costs against what it saves per revolution."""
    per = summary.get(scenes[0]["name"], {})
    k, _ = _best(per, lambda k, v: k in VM_TWIN)
    if k is None or not METHODS[k].compiled:
        return None
    spec = METHODS[k]
    pts = [p for p in scenes[0]["points"] if p["method"] == k and p["status"] == "ok"]
    reach = [p for p in pts if p["error"]["state"] <= cfg.target_error] or pts
    value = reach[0]["value"]
    target = compile_target(engines.get(MODEL, sx, spec, value, compiled=False))
    log(f"cold compile of {k} at {value:g} (empty cache)")
    out = cold_compile(target, flags=cfg.flags) | {"method": k, "value": value}
    log(f"  {out['wall_s']:.1f} s wall, {out['compiler_cpu_s']:.1f} s compiler CPU")
    return out


def targets_table(results: dict, cfg: BenchConfig) -> list[dict]:
    """The issue's targets, each with its measured value and 'met' / 'missed' (never asserted)."""
    rows = []
    e = cfg.target_error
    for name, per in results["summary"].items():
        kc, tc = best_c(per)
        ks, ts = _best(per, lambda k, v: k.startswith("scipy-"))
        ke, te = _best(per, lambda k, v: k == "euler-C")
        how = {k: (per[k]["at_target"] or {}).get("how") for k in (kc, ks, ke) if k}
        if tc and ts:
            r = ts / tc
            rows.append({"scene": name, "target": f"best generated C >= 100x faster than best lambdify+solve_ivp at {e:g}",
                         "value": r, "text": f"{r:.0f}x ({kc} {1e3 * tc:.3g} ms vs {ks} {ts:.3g} s; {how[ks]})",
                         "status": "met" if r >= 100 else "missed", "aim_300": r >= 300})
        if tc and te:
            r = te / tc
            rows.append({"scene": name, "target": f"best generated C >= 10x faster than the paper's Euler at {e:g}",
                         "value": r, "text": f"{r:.0f}x ({kc} {1e3 * tc:.3g} ms vs euler-C {te:.3g} s; {how[ke]})",
                         "status": "met" if r >= 10 else "missed"})
        if name == "default" and tc and cfg.span_deg == 360.0:  # a shorter --span's times are per span
            rows.append({"scene": name, "target": f"one revolution at {e:g} in < 10 ms CPU", "value": tc,
                         "text": f"{1e3 * tc:.3g} ms ({kc}, {how[kc]})", "status": "met" if tc < 0.01 else "missed"})
    for name in results["summary"]:
        row = next((r for r in peer_ratios(results, name) if r["error"] == e), None)
        if row and row["ratio"] is not None:
            rows.append({"scene": name, "target": f"best apexseal method >= 2x faster than the best numba peer at {e:g}",
                         "value": row["ratio"], "status": "met" if row["ratio"] >= 2 else "missed",
                         "text": f"{row['ratio']:.2f}x ({row['apexseal']} {1e3 * row['apexseal_s']:.3g} ms vs "
                                 f"{row['peer']} {1e3 * row['peer_s']:.3g} ms)"})
    be = break_even(results)
    if be:
        rows.append(be)
    return rows


#: the errors at which apexseal is compared with the hand-written peer (README "What accuracy costs in time")
PEER_ERRORS = (1e-3, 1e-4, 1e-6, 1e-8)


def peer_ratios(results: dict, scene: str, errors=PEER_ERRORS) -> list[dict]:
    """At each error: apexseal's fastest generated-C method, the fastest peer, and time(peer) / time(apexseal).

    Times are interpolated on each method's Pareto front as for the target error (``metrics.time_at_error``);
    a ratio below 1 means the peer is faster."""
    s = next(x for x in results["scenes"] if x["name"] == scene)
    curves: dict = {}
    for p in s["points"]:
        if p["status"] == "ok":
            curves.setdefault(p["method"], []).append((p["timing"]["median_cpu_s"], p["error"]["state"]))
    fam = {p["method"]: p["family"] for p in s["points"]}
    gen = {p["method"]: p["generated_c"] for p in s["points"]}
    rows = []
    for e in errors:
        def best(pred, e=e):
            at = {m: time_at_error(c, e) or {} for m, c in curves.items() if pred(m)}
            cands = [(a["time_s"], m) for m, a in at.items() if a.get("time_s") is not None]
            t, m = min(cands) if cands else (None, None)
            # extrapolated beyond the method's most accurate point: an estimate, which the tables mark
            return t, m, bool(m) and at[m]["how"].startswith("extrapolated")

        ta, ka, xa = best(lambda m: gen[m] and m != "euler-C")
        tp, kp, xp = best(lambda m: fam[m] == "sympy.cse + numba (peer)")
        rows.append({"error": e, "apexseal": ka, "apexseal_s": ta, "apexseal_extrapolated": xa, "peer": kp,
                     "peer_s": tp, "peer_extrapolated": xp, "ratio": tp / ta if ta and tp else None})
    return rows


def break_even(results: dict) -> dict | None:
    """Revolutions after which the cold compile of the best C integrator is recovered against its VM twin."""
    cc = results.get("cold_compile")
    if not cc:
        return None
    name = next(iter(results["summary"]))
    per = results["summary"][name]
    twin = VM_TWIN.get(cc["method"])
    tc = ((per.get(cc["method"]) or {}).get("at_target") or {}).get("time_s")
    tv = ((per.get(twin) or {}).get("at_target") or {}).get("time_s") if twin else None
    if not (tc and tv and tv > tc):
        return {"scene": name, "target": "code generation pays for itself", "value": None, "status": "not measured",
                "text": f"no interpreted twin of {cc['method']} reached the target"}
    n = cc["wall_s"] / (tv - tc)
    return {"scene": name, "target": "code generation pays for itself", "value": n, "status": "met",
            "text": f"after {math.ceil(n)} revolutions: compile {cc['wall_s']:.1f} s wall once, then {1e3 * tc:.3g} ms "
                    f"(C) instead of {1e3 * tv:.3g} ms ({twin}) per revolution"}


def _config_dict(cfg: BenchConfig) -> dict:
    return asdict(cfg)
