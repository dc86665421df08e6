"""Markdown tables of a benchmark result: ``table.md`` (targets, time at the target error, every point) and
``effects.md`` (cost of each physical effect)."""

from __future__ import annotations

import math

from .budget import budget_md
from .e2e import e2e_md
from .gas_cost import gas_md


def _t(s: float | None) -> str:
    if s is None or not math.isfinite(s):
        return "–"
    if s < 1:
        return f"{1e3 * s:.3g} ms"
    return f"{s:.3g} s"


def _int(v) -> str:
    return "–" if v is None else f"{v:,}"


def _us(s: float) -> str:
    return f"{1e9 * s:.0f} ns" if s < 1e-6 else f"{1e6 * s:.1f} µs"


def _e(v: float | None) -> str:
    return "–" if v is None or not math.isfinite(v) else f"{v:.1e}"


def _n(tim: dict) -> str:
    if not tim:
        return "–"
    return f"{tim['n_timed']}×{tim.get('batch', 1)}" if tim.get("n_timed") else "1"


def _setting(p: dict) -> str:
    return f"rtol {p['value']:.0e}" if p["sweep"] == "rtol" else f"{int(p['value']):,} steps"


def _versions(r: dict) -> str:
    m = r["machine"]
    pk = ", ".join(f"{k} {v}" for k, v in m["packages"].items() if v)
    git = m["git"]
    dirty = f" + uncommitted changes to {', '.join(git.get('modified') or [])}" if git.get("dirty") else ""
    rev = f"git {git['commit'][:10]}{dirty}" if git.get("commit") else "no git"
    return (f"{m['date']}; {m['cpu']} ({m['cores']} cores, load {m['load_average_at_start'][0]:.1f} at start, "
            f"{m.get('load_average_at_end', [math.nan])[0]:.1f} at end); {m['platform']}; Python {m['python']}; {pk}; "
            f"{m['compiler']['version']}, flags `{' '.join(m['compiler']['flag_sets'][r['config']['flags']])}`; {rev}")


def problem_lines(r: dict) -> list[str]:
    cfg = r["config"]
    out = []
    for s in r["scenes"]:
        p, ref = s["problem"], s["reference"]
        chk = ref.get("check") or {}
        d = chk.get("difference") or {}
        over = ", ".join(f"{k} = {v:g}" for k, v in s["overrides"].items()) or "as shipped"
        line = (f"- **{s['name']}** ({over}): {p['span_deg']:g} deg from crank angle {p['theta0_rad']:.4f} rad after "
                f"{p['settle']['revolutions']} settling revolution(s); reference {ref['events']} contact events, "
                f"mean friction power {ref['mean_friction_power_W']:.4g} W; ranges x {1e6 * ref['range']['x']:.3g} µm, "
                f"y {1e6 * ref['range']['y']:.3g} µm, phi {1e3 * ref['range']['phi']:.3g} mrad.")
        if chk.get("status") == "ok":
            line += (f" Check ({chk['method']}, rtol {chk['rtol']:g}, events to {chk['event_tol']:g} rad): state "
                     f"{_e(d.get('state'))}, friction power {_e(d.get('friction_power'))}, events "
                     f"{'identical' if chk['events_match'] else 'differ'}.")
        elif chk:
            line += f" Check failed: {chk.get('reason')}."
        out.append(line)
    if cfg.get("pressure", "steps") == "linear":
        out.append(f"- Grid: {cfg['samples']} output samples per span; the chamber pressures are linear over each "
                   "interval between their values at its ends (continuous), for every method (so the grid is part of "
                   "the problem).")
    else:
        out.append(f"- Grid: {cfg['samples']} output samples per span; the chamber pressures are their interval "
                   "means, constant per interval, for every method (so the grid is part of the problem).")
    return out


def metrics_lines(cfg: dict) -> list[str]:
    slow = cfg.get("slow_run_s", 0.5)
    every = slow is None or not math.isfinite(slow)  # inf (None once written to JSON): no run is "slow"
    samples = (f"every point {cfg.get('repeats')} timed samples after the warm-up" if every else
               "slow runs get fewer samples, `1` = the warm-up run alone")
    return [
        "- **Scaled error**: for x, y and phi, max over the samples of |method - reference| / (range of the reference "
        "over the span); the largest of the three.",
        "- **Friction power error**: |mean Pf_total - reference| / reference, means over the samples (the cycle's "
        "mean).",
        "- **CPU time**: `time.process_time()` per revolution, median of the timed samples after one warm-up; `n` = "
        f"samples × revolutions per sample (a sample lasts >= 0.2 s; {samples}). "
        "Compile, derivation and lambdify times are reported apart (Setup).",
    ]


def span_note(cfg: dict) -> list[str]:
    """A run over less or more than a revolution (``--span``): its times are per span, not per revolution."""
    span = cfg.get("span_deg", 360.0)
    if span == 360.0:
        return []
    return [f"- **Span {span:g} deg, not a revolution** (`--span`): every time labelled per revolution (`CPU / rev`) "
            "in this run is per span, not scaled, and the one-revolution target is not judged."]


def targets_md(r: dict) -> list[str]:
    rows = ["| scene | target | measured | status |", "|---|---|---|---|"]
    for t in r.get("targets", []):
        status = t["status"] + (" (aim 300x: met)" if t.get("aim_300") else " (aim 300x: missed)" if "aim_300" in t else "")
        rows.append(f"| {t['scene']} | {t['target']} | {t['text']} | **{status}** |")
    rep = repeatability(r)
    if rep:
        rows += ["", f"Repeatability: {rep}"]
    return rows


def repeatability(r: dict) -> str | None:
    """The same configuration timed twice in this run (main sweep and effects table): how far apart."""
    eff = next((e for e in r.get("effects") or [] if e["effects"] == "all" and e["status"] == "ok"), None)
    if not eff or not r["scenes"]:
        return None
    rtol = eff["stats_rtol"]
    main = next((p for p in r["scenes"][0]["points"] if p["method"] == "erk-C" and p["value"] == rtol
                 and p["status"] == "ok"), None)
    other = eff["at_stats_rtol"].get("timing")
    if not main or not other or r["scenes"][0]["name"] != "default":
        return None
    a, b = main["timing"]["median_cpu_s"], other["median_cpu_s"]
    return (f"erk-C at rtol {rtol:g} on the default scene was timed twice in this run, {_t(a)} in the sweep above "
            f"and {_t(b)} in the effects table (load average {main.get('load_average', math.nan):.1f} and "
            f"{eff['at_stats_rtol'].get('load_average', math.nan):.1f}); each is a tight median, but the two differ by "
            f"{100 * abs(b - a) / min(a, b):.0f} %: other jobs on this 2-vCPU machine slow the same code down by that "
            "much, so ratios between points timed minutes apart carry that uncertainty.")


def at_target_md(r: dict) -> list[str]:
    names = list(r["summary"])
    target = r["config"]["target_error"]
    rows = [f"| method | family | {' | '.join(f'{n}: CPU at {target:g}' for n in names)} |",
            "|---|---|" + "---|" * len(names)]
    methods = dict.fromkeys(m for n in names for m in r["summary"][n])
    for m in methods:
        cells, label, family = [], m, ""
        for n in names:
            v = r["summary"][n].get(m)
            if not v:
                cells.append("")
                continue
            label, family = v["label"], v["family"]
            a = v["at_target"] or {}
            how = a.get("how", "no successful point")
            cell = f"{_t(a.get('time_s'))} ({how})" if a.get("time_s") else how
            if v["failed"]:
                cell += f"; {v['failed']} of {v['points']} failed"
            cells.append(cell)
        rows.append(f"| {label} | {family} | {' | '.join(cells)} |")
    return rows


def points_md(scene: dict) -> list[str]:
    rows = ["| method | setting | scaled error | x | y | phi | friction power | CPU / rev | n | steps | RHS evals | events "
            "| VM run | status |", "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for p in scene["points"]:
        st = p.get("stats") or {}
        err = p.get("error") or {}
        tim = p.get("timing") or {}
        status = p["status"] if p["status"] == "ok" else f"**failed**: {p.get('reason', '')[:80]}"
        steps = st.get("steps", st.get("integrator_calls"))
        steps = f"{steps:,}" + (" calls" if "steps" not in st and steps is not None else "") if steps is not None else "–"
        rhs = st.get("rhs_evaluations")
        rows.append(f"| {p['label']} | {_setting(p)} | {_e(err.get('state'))} | {_e(err.get('x'))} | {_e(err.get('y'))} "
                    f"| {_e(err.get('phi'))} | {_e(err.get('friction_power'))} | {_t(tim.get('median_cpu_s'))} "
                    f"| {_n(tim)} | {steps} | {f'{rhs:,}' if rhs else '–'} | {st.get('events', '–')} "
                    f"| {_t(p.get('interpreted_cpu_s'))} | {status} |")
    return rows


def setup_md(r: dict) -> list[str]:
    m, c = r["model"], r["compile"]
    out = [f"- Model (all effects, {m['rhs_instructions']} SX instructions in the right-hand side): "
           f"{'loaded from the derivation cache' if m['derive_cached'] else 'derived'} in {m['derive_wall_s']:.1f} s wall."]
    if "library_load_wall_s" in m:
        out.append(f"- Compiled model library (for the stepper methods): {m['library_load_wall_s']:.1f} s wall "
                   "(includes its compile when it was not cached).")
    out.append(f"- Integrators generated to C and compiled in this run: {c['functions']} in {c['wall_s']:.1f} s wall, "
               f"{c['compiler_cpu_s']:.1f} s compiler CPU, {c['workers']} at a time (cached libraries take ~0 s).")
    cc = r.get("cold_compile")
    if cc:
        out.append(f"- Cold compile (empty cache) of the best C integrator, {cc['method']} at {cc['value']:g}: "
                   f"{cc['wall_s']:.1f} s wall, {cc['compiler_cpu_s']:.1f} s compiler CPU.")
    lam = next((s["lambdify"] for s in r["scenes"] if s.get("lambdify")), None)
    if lam:
        out.append(f"- sympy.lambdify of the model ({lam['options']}): {lam['lambdify_cpu_s']:.2f} s CPU.")
    out.append(f"- Whole benchmark: {r['elapsed_wall_s'] / 60:.1f} min wall.")
    return out


def table_md(r: dict, command: str) -> str:
    lines = ["# Work-precision benchmark", "",
             f"Made by `{command}` ({r['config']['mode']} mode). Data: `results.json`; diagram: `work-precision.png`; "
             "effects: `effects.md`.", "",
             *([f"**A partial run**, {r['interrupted']}.", ""] if r.get("interrupted") else []),
             f"Machine and software: {_versions(r)}.", "",
             "## Problem and metrics", "", *problem_lines(r), *metrics_lines(r["config"]), *span_note(r["config"]), "",
             "## Targets", "", *targets_md(r), "",
             f"## CPU time per revolution at scaled error {r['config']['target_error']:g}", "",
             "Interpolated (log-log) on each method's Pareto front; *extrapolated* along its last two points when its "
             "most accurate point is still above the target (at most 4 decades, and only for a plausible order of "
             "convergence): such values are estimates, not measurements.", "", *at_target_md(r), ""]
    lines += peer_md(r)
    lines += budget_md(r)
    lines += e2e_md(r.get("e2e"))
    lines += gas_md(r.get("gas"))
    for s in r["scenes"]:
        lines += [f"## All points: {s['name']}", "",
                  "`VM run`: CPU time of the interpreted run that gave the statistics of a compiled integrator.", "",
                  *points_md(s), ""]
    cost = next((s["rhs_cost"] for s in r["scenes"] if s.get("rhs_cost")), None)
    if cost:
        lines += ["## Cost of one right-hand-side evaluation", "",
                  "A method's speed-up = (cost per evaluation) x (evaluations it needs for the error). Python-called "
                  "forms timed in a loop at the initial state; the last rows are CPU per revolution / evaluations of "
                  "benchmark points.", "", "| form | CPU per evaluation | from |", "|---|---|---|"]
        lines += [f"| {c['form']} | {_us(c['s'])} | {c['n']} |" for c in cost]
        lines.append("")
    lines += ["## Setup costs (not in the run times)", "", *setup_md(r), ""]
    return "\n".join(lines)


def peer_md(r: dict) -> list[str]:
    """apexseal's fastest method against the fastest hand-written numba peer, per scene and error."""
    from .runner import peer_ratios

    skipped = r.get("skipped") or []
    note = [f"Skipped: {', '.join(x['method'] for x in skipped)} ({skipped[0]['reason']})."] if skipped else []
    if not any(p["family"] == "sympy.cse + numba (peer)" for s in r["scenes"] for p in s["points"]):
        return (["## Against the hand-written numba peer", "", *note, ""]) if note else []
    lines = ["## Against the hand-written numba peer", "",
             "The same sympy equations through `sympy.cse` into a numba right-hand side (runtime/bench/peer_source.py) "
             "under scipy's and numbalsoda's integrators (runtime/bench/peer_numba.py); CPU per revolution at each "
             "scaled error, interpolated on each method's Pareto front as above (*extrap.*: extrapolated beyond the "
             "method's most accurate point, an estimate). `ratio` = peer / apexseal: above 1 apexseal is faster.", "",
             *note, *([""] if note else []),
             "| scene | scaled error | fastest apexseal (generated C) | fastest peer | ratio |", "|---|---|---|---|---|"]
    for s in r["scenes"]:
        for row in peer_ratios(r, s["name"]):
            mark = {side: " (*extrap.*)" if row[f"{side}_extrapolated"] else "" for side in ("apexseal", "peer")}
            a = f"{row['apexseal']} {_t(row['apexseal_s'])}{mark['apexseal']}" if row["apexseal"] else "not reached"
            p = f"{row['peer']} {_t(row['peer_s'])}{mark['peer']}" if row["peer"] else "not reached"
            ratio = (f"{row['ratio']:.2f}" + (" (*extrap.*)" if any(mark.values()) else "")) if row["ratio"] else "–"
            lines.append(f"| {s['name']} | {row['error']:g} | {a} | {p} | {ratio} |")
    info = next((s["peer"] for s in r["scenes"] if s.get("peer")), None)
    if info:
        lines += ["", f"Peer setup (not in the run times): {info['source_lines']} lines of numba source printed in "
                  f"{info['print_cpu_s']:.1f} s CPU (0 when cached), jit {info['jit_wall_s']:.1f} s wall, integrator "
                  f"kernels {info['kernels_build_wall_s']:.1f} s wall; {info['options']}."]
    said = [(s["name"], p) for s in r["scenes"] for p in s["points"] if p.get("solver_messages")]
    if said:
        lines += ["", "What the peers' integrators printed (warnings, not failures: the points stand as measured): " +
                  "; ".join(f"{name} {p['method']} at {p['sweep']} {p['value']:g}: {p['solver_messages']['lines']} "
                            f"lines over its runs, first \"{p['solver_messages']['first']}\"" for name, p in said) + "."]
    return lines + [""]


def effects_md(r: dict, command: str) -> str:
    rows = r.get("effects") or []
    cfg = r["config"]
    if not rows:
        return f"# Cost of each physical effect\n\nNot measured in this run (`{command}`).\n"
    e0 = rows[0]
    target = cfg["target_error"]
    rt = ", ".join(f"{v:g}" for v in e0["rtols"])
    lines = ["# Cost of each physical effect", "",
             f"Made by `{command}` ({cfg['mode']} mode), machine as in `table.md`. Per model: erk-C at rtol {rt}, one "
             "revolution from a settled start, against the model's own reference (erk-C, rtol "
             f"{cfg['reference_rtol']:g}); `CPU at {target:g}` is interpolated on that sweep (log-log). *base* = the "
             "three contacts (housing, groove, spring) with their damping, which hold the seal in its groove: without "
             "contacts the seal leaves the groove (inertia alone) or the run fails (pressure alone; also pressure on "
             "undamped contacts), so every other effect is measured on top of the base; *elastic contacts* = the base "
             "without damping.", "",
             f"| effects | guards | RHS instr. | derive | compile (x{len(e0['rtols'])}) | CPU / rev at {target:g} | "
             f"at rtol {e0['stats_rtol']:g}: CPU / rev | error | steps | RHS evals | events | ns / RHS eval | VM / rev "
             "| status |", "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for e in rows:
        m = e.get("at_stats_rtol") or {}
        st, tim = m.get("stats") or {}, m.get("timing") or {}
        comp = sum(b["wall_s"] for b in e.get("compile") or [])
        derive = f"{e['derive_wall_s']:.1f} s" + (" (cached)" if e["derive_cached"] else "")
        status = e["status"] if e["status"] == "ok" else f"**failed**: {(e.get('reason') or '')[:90]}"
        at = e.get("at_target") or {}
        at_s = f"{_t(at['time_s'])} ({at['how']})" if at.get("time_s") else at.get("how", "–")
        ns = m.get("ns_per_rhs_evaluation")
        rhs = st.get("rhs_evaluations")
        err = (m.get("error") or {}).get("state")
        lines.append(f"| {e['effects']} | {len(e['guards'])} | {e['rhs_instructions']} | {derive} | {_t(comp)} "
                     f"| {at_s} | {_t(tim.get('median_cpu_s'))} | {_e(err)} | {_int(st.get('steps'))} "
                     f"| {f'{rhs:,}' if rhs else '–'} | {st.get('events', '–')} | {f'{ns:.0f}' if ns else '–'} "
                     f"| {_t(m.get('interpreted_cpu_s'))} | {status} |")
    lines += ["", "`compile`: this run's compiles of the model's integrators (~0 s when cached). `ns / RHS eval`: CPU per "
              "revolution / right-hand-side evaluations (events and dense output included). `VM / rev`: the same "
              "integrator interpreted."]
    return "\n".join(lines) + "\n"
