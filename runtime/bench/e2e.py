"""End to end: where a warm ``apexseal simulate --revolutions N`` spends its wall time.

The command runs in a subprocess with ``--timings`` (src/apexseal/stopwatch.py),
once to warm the caches (derivation, compiled libraries), then ``repeats`` times
timed, with and without figures in turn; each stage's median is kept. ``unaccounted`` is the command's own total
less its stages (what its stopwatch prints as such: the lines it echoes between stages), ``exit`` the
subprocess's wall time measured from outside minus the command's own total (interpreter shutdown), so that
the stages of a run add up to its wall time.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import tempfile
import time

from ...cli import command
from ..results.folder import WRITE_BEHIND

#: what is timed: name, options, environment. The third run writes its parts in the run's own thread
#: (runtime/results/folder.py, ``APEXSEAL_WRITE_BEHIND=0``): the integration undisturbed by the writer thread
VARIANTS = (("no figures", ["--no-figures"], None), ("with figures", [], None),
            ("with figures, parts written in the run's thread", [], {WRITE_BEHIND: "0"}))

#: the stages in the order the command runs them
STAGES = ("startup", "import", "scene", "load", "compile", "integrate", "assemble", "run (other)", "save", "figures",
          "unaccounted", "exit")


def _once(args: list[str], env: dict | None = None) -> dict:
    w0 = time.perf_counter()
    proc = subprocess.run(command(*args), env=None if env is None else os.environ | env,
                          capture_output=True, text=True, check=False)
    wall = time.perf_counter() - w0
    line = next((x for x in proc.stdout.splitlines() if x.startswith("timings-json ")), None)
    if proc.returncode != 0 or line is None:
        raise RuntimeError(f"apexseal {' '.join(args)} failed ({proc.returncode}): {(proc.stderr or proc.stdout)[-500:]}")
    t = json.loads(line.split(" ", 1)[1])
    stages = dict(t["stages"])
    stages["unaccounted"] = max(0.0, t["total_s"] - sum(stages.values()))
    stages["exit"] = max(0.0, wall - t["total_s"])
    return {"stages": stages, "wall_s": wall}


def end_to_end(revolutions: int = 20, repeats: int = 2, *, log=print) -> dict:
    """Medians of the stages of ``apexseal simulate --revolutions N --timings`` for each of :data:`VARIANTS`: a
    warm-up of each, then ``repeats`` rounds of one run of each in turn, so that a machine whose speed drifts weighs
    on all alike."""
    out: dict = {"revolutions": revolutions, "repeats": repeats, "variants": {}}
    with tempfile.TemporaryDirectory(prefix="apexseal-e2e-") as tmp:
        variants = [(name, ["simulate", "--revolutions", str(revolutions), "--quiet", "--timings", "--out", tmp, *extra],
                     env) for name, extra, env in VARIANTS]
        shown = {name: "".join(f"{k}={v} " for k, v in (env or {}).items()) + "apexseal "
                 + " ".join(a for a in args if a not in ("--out", tmp)) for name, args, env in variants}
        log(f"end to end: {'; '.join(shown.values())}, in turn (1 warm-up + {repeats} each)")
        for _, args, env in variants:
            _once(args, env)
        runs: dict[str, list] = {name: [] for name, _, _ in variants}
        for _ in range(repeats):
            for name, args, env in variants:
                runs[name].append(_once(args, env))
        for name, done in runs.items():
            keys = [k for k in STAGES if any(k in r["stages"] for r in done)]
            med = {k: statistics.median(r["stages"].get(k, 0.0) for r in done) for k in keys}
            wall = statistics.median(r["wall_s"] for r in done)
            out["variants"][name] = {"command": shown[name], "stages_s": med, "wall_s": wall, "runs": done,
                                     "integrate_share": med.get("integrate", 0.0) / wall}
            log(f"  {name}: " + ", ".join(f"{k} {v:.2f}" for k, v in med.items()) + f"; wall {wall:.2f} s, "
                f"integrating {100 * med.get('integrate', 0.0) / wall:.0f} %")
    return out


def e2e_md(e2e: dict | None) -> list[str]:
    """The table of the split (stages as rows, the variants as columns)."""
    if not e2e:
        return []
    vs = e2e["variants"]
    names = list(vs)
    lines = ["## End to end: where a warm `apexseal simulate` spends its wall time", "",
             f"`apexseal simulate --revolutions {e2e['revolutions']} --timings` in a subprocess after one warm-up run "
             f"(caches warm), median of {e2e['repeats']} runs; wall seconds (src/apexseal/stopwatch.py; `compile` is "
             "building the integrator, i.e. loading the cached library once warm; `exit` is interpreter shutdown).", "",
             "| stage | " + " | ".join(names) + " |", "|---|" + "---|" * len(names)]
    keys = [k for k in STAGES if any(k in v["stages_s"] for v in vs.values())]
    for k in keys:
        cells = []
        for n in names:
            v = vs[n]["stages_s"].get(k)
            cells.append("–" if v is None else f"{v:.2f} s ({100 * v / vs[n]['wall_s']:.0f} %)")
        lines.append(f"| {k} | " + " | ".join(cells) + " |")
    lines.append("| **wall** | " + " | ".join(f"**{vs[n]['wall_s']:.2f} s**" for n in names) + " |")
    return lines + [""]
