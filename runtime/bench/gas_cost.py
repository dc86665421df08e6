"""What the gas states cost: time per revolution of the pressure table, the chamber model and the chamber model with
leakage on one machine (runtime/scenes/expander-gas.toml, docs/gas.md).

The three variants differ only in ``pressure.source`` (the table is the default scene's ``expander-pressure.csv``):
same geometry, contacts, method (the scene's erk, rtol 1e-6) and output grid. Each is run once to warm the caches
(derivation, compiled libraries), once interpreted for CasADi's step counts (right-hand-side evaluations, steps,
events), then ``repeats`` timed rounds *interleaved* (table, chamber, chamber+leakage, then the next round, the order
rotated each round), so that the machine's load falls on all three alike. Per variant: median wall time of the
integration stage (the result's ``timings_s["integrate"]``) and median process CPU time of the whole ``simulate`` call,
each per revolution, and their ratios to the table's.
"""

from __future__ import annotations

import os
import statistics
import time

#: (label, scene overrides) of the three pressure sources, on the gas scene
VARIANTS = (
    ("table", {"pressure.source": "table", "pressure.file": "expander-pressure.csv", "pressure.unit": "Pa"}),
    ("chamber", {"pressure.source": "chamber"}),
    ("chamber+leakage", {"pressure.source": "chamber+leakage"}),
)
SCENE = "expander-gas.toml"


def gas_scenes() -> dict:
    """The three scenes of :data:`VARIANTS`."""
    from ..scenes.scene import embedded_scene_path, load_scene

    base = load_scene(embedded_scene_path(SCENE))
    table = {"pressure.file": str(embedded_scene_path("expander-pressure.csv"))}  # the package's, whatever the cwd
    return {label: base.with_overrides(**(over | table if "pressure.file" in over else over))
            for label, over in VARIANTS}


def gas_cost(revolutions: int = 2, repeats: int = 5, *, log=print) -> dict:
    """Measure the three variants (see the module docstring); the dict ``gas_md`` prints."""
    from ..api import model_functions, simulate

    scenes = gas_scenes()
    out: dict = {"scene": SCENE, "revolutions": revolutions, "repeats": repeats, "variants": {},
                 "load_average_at_start": list(os.getloadavg())}
    for label, scene in scenes.items():
        log(f"gas cost: {label}: warm-up (derives and compiles on first use)")
        warm = simulate(scene, revolutions=revolutions)
        stats = simulate(scene.with_overrides(**{"solver.interpreted": True}), revolutions=revolutions).solver_stats
        f = model_functions(scene, compiled=False)
        out["variants"][label] = {"status": warm.status, "states": len(f.state_names),
                                  "rhs_instructions": int(f.rhs.n_instructions()),
                                  "events": int(warm.solver_stats.get("n_events", 0)),
                                  "rhs_evaluations": int(stats.get("n_rhs", 0)), "steps": int(stats.get("n_steps", 0)),
                                  "integrate_s": [], "cpu_s": []}
    labels = list(scenes)
    for k in range(repeats):
        for label in labels[k % len(labels):] + labels[:k % len(labels)]:
            c0 = time.process_time()
            r = simulate(scenes[label], revolutions=revolutions)
            v = out["variants"][label]
            v["cpu_s"].append(time.process_time() - c0)
            v["integrate_s"].append(r.info["timings_s"]["integrate"])
        log(f"gas cost: round {k + 1}/{repeats} done")
    for v in out["variants"].values():
        v["integrate_per_rev_s"] = statistics.median(v["integrate_s"]) / revolutions
        v["cpu_per_rev_s"] = statistics.median(v["cpu_s"]) / revolutions
    base = out["variants"]["table"]
    for v in out["variants"].values():
        v["integrate_ratio"] = v["integrate_per_rev_s"] / base["integrate_per_rev_s"]
        v["cpu_ratio"] = v["cpu_per_rev_s"] / base["cpu_per_rev_s"]
    out["load_average_at_end"] = list(os.getloadavg())
    return out


def gas_md(gas: dict | None) -> list[str]:
    """The small table of the gas states' cost (one row per pressure source)."""
    if not gas:
        return []
    la = ", ".join(f"{x:.1f}" for x in gas["load_average_at_start"][:1] + gas["load_average_at_end"][:1])
    lines = ["## What the gas states cost", "",
             f"`{gas['scene']}` with `pressure.source` = table / chamber / chamber+leakage (same machine, contacts, "
             f"erk at the scene's rtol, output grid): {gas['revolutions']} revolutions from the scene's start, "
             f"{gas['repeats']} timed rounds interleaved after a warm-up; medians per revolution. Integration: wall "
             "time of the integrator calls; CPU: process time of the whole `simulate` call. RHS evaluations and steps "
             f"from one interpreted run. Load average at start and end: {la} (runtime/bench/gas_cost.py).", "",
             "| pressure source | states | RHS instructions | RHS evaluations / rev | steps / rev | events / rev | "
             "integration / rev | CPU / rev |", "|---|---|---|---|---|---|---|---|"]
    n = gas["revolutions"]
    for label, v in gas["variants"].items():
        lines.append(f"| {label} | {v['states']} | {v['rhs_instructions']} | {v['rhs_evaluations'] / n:.0f} | "
                     f"{v['steps'] / n:.0f} | {v['events'] / n:.0f} | {1e3 * v['integrate_per_rev_s']:.0f} ms "
                     f"(x{v['integrate_ratio']:.2f}) | {1e3 * v['cpu_per_rev_s']:.0f} ms (x{v['cpu_ratio']:.2f}) |")
    return lines + [""]
