"""Throughput of a sweep: points per second serially, on every core, and on a 2-worker LocalCluster.

Each mode runs the whole study into a fresh temporary folder (nothing resumed), after one warm-up point that
fills the compile cache, so no mode pays for compiling. Times include what a user waits for: starting the
cluster and its workers, building the scenes, writing the results. Modes are interleaved repeat by repeat (so
slow drift of a shared machine spreads over all of them) and the median is reported, with the spread
(min-max) and the machine's 1-minute load average before and after each run (other programs' load included:
on a shared machine, a load above the core count means the workers were sharing cores) as the measures of noise.
Scaling efficiency = (points/s with n workers) / (n x serial points/s).
"""

from __future__ import annotations

import os
import statistics
import tempfile
import time
from pathlib import Path

from ....cores import available_cores
from .execute import run_sweep, scenes_of
from .point import run_point


def modes() -> list[tuple[str, int]]:
    """(label, workers): serial, every core, 2-worker LocalCluster (the last two coincide on a 2-core machine)."""
    cores = available_cores()
    return [("serial", 1), (f"all cores (LocalCluster, {cores} workers)", cores), ("LocalCluster, 2 workers", 2)]


def measure(study, *, repeats: int = 3, log=print) -> dict:
    """Run the study ``repeats`` times in each mode; returns medians, spreads and efficiencies."""
    i, scene, overrides = scenes_of(study)[0]
    run_point(i, scene, overrides, study.quantities, study.max_wall_time)  # warm-up: compile once
    times: dict[str, list[float]] = {label: [] for label, _ in modes()}
    loads: dict[str, list[float]] = {label: [] for label, _ in modes()}
    n_points = 0
    walls, runs = [], []  # serial points: whole point, and the integration alone (s)
    for r in range(repeats):
        for label, workers in modes():
            with tempfile.TemporaryDirectory(prefix="apexseal-sweep-bench-") as tmp:
                loads[label].append(os.getloadavg()[0])
                t0 = time.perf_counter()
                report = run_sweep(study, Path(tmp) / "out", workers=workers, resume=False, quiet=True)
                dt = time.perf_counter() - t0
                loads[label].append(os.getloadavg()[0])
            n_points = report.total
            if workers == 1:
                walls += list(report.table["wall_time_s"])
                runs += list(report.table["run_time_s"])
            if report.failed:
                log(f"  note: {report.failed} points did not complete in {label}")
            times[label].append(dt)
            log(f"  repeat {r + 1}/{repeats}, {label}: {report.total} points in {dt:.1f} s "
                f"({report.total / dt:.2f} points/s; load average {loads[label][-2]:.1f} before, "
                f"{loads[label][-1]:.1f} after)")
    serial = n_points / statistics.median(times["serial"])
    rows = []
    for label, workers in modes():
        med = statistics.median(times[label])
        rate = n_points / med
        rows.append({"mode": label, "workers": workers, "median_s": med, "min_s": min(times[label]),
                     "max_s": max(times[label]), "points_per_s": rate, "speed_up": rate / serial,
                     "efficiency": rate / (workers * serial), "load_min": min(loads[label]),
                     "load_max": max(loads[label])})
    per_point = {"median_wall_s": statistics.median(walls), "median_run_s": statistics.median(runs)}
    return {"points": n_points, "repeats": repeats, "cores": available_cores(), "rows": rows,
            "per_point": per_point}


def table(result: dict) -> str:
    """The measurement as a Markdown table."""
    lines = ["| mode | workers | median wall (s) | min-max (s) | points/s | speed-up | scaling efficiency | "
             "load average (min-max) |", "|---|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        lines.append(f"| {r['mode']} | {r['workers']} | {r['median_s']:.1f} | {r['min_s']:.1f}-{r['max_s']:.1f} | "
                     f"{r['points_per_s']:.2f} | {r['speed_up']:.2f} | {r['efficiency']:.0%} | "
                     f"{r['load_min']:.1f}-{r['load_max']:.1f} |")
    p = result["per_point"]
    lines.append("")
    lines.append(f"Serial points: median {p['median_wall_s']:.3f} s a point, of which {p['median_run_s']:.3f} s "
                 "in the run (integrating, and building the integrator for a worker's first point of a model; "
                 "the rest: loading the model, the summary, the row).")
    return "\n".join(lines)
