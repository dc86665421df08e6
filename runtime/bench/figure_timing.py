"""How long a default run's figures take against its simulation: ``python -m apexseal.runtime.bench.figure_timing``.

``python -m apexseal.runtime.bench.figure_timing 7 --pairs`` measures what the figures add to a default run as a user
meets it: whole ``apexseal simulate -q`` runs of the default scene with figures and with ``--no-figures``, in turn,
timed from outside (wall clock; CPU of the process and of every process it waited for), and prints the medians and
the median of what each pair's run with figures took more than the one without.

``python -m apexseal.runtime.bench.figure_timing 7 --cli`` times whole ``apexseal simulate --timings`` runs of the
default scene instead (each in a new process, as a user runs it: the figure worker of :mod:`..results.figure_worker`
imports matplotlib while the run integrates) and prints the medians of the figures stage against the stages
that simulate (scene, load, compile, integrate, assemble) and against the integration alone.

Runs the default scene once to warm the caches (derivation, compiled libraries), then ``repeats`` times:
``apexseal.simulate(scene)`` (wall time of the call: integrator set-up from the cache plus integration; and
the integration alone, ``result.info["wall_time_s"]``) and :func:`..results.figure_job.write_figures` (draw and save the four
PNG files), as ``apexseal simulate`` draws them (some in a forked second process, :mod:`..results.figure_job`) and all in
this process, in turn; the :func:`skeleton` of each figure (made and saved), matplotlib's cost for the same
axes whatever the data; and :func:`single_axes`, the least figure a run could draw. Prints the medians and their
ratios, all measured in one process.
"""

from __future__ import annotations

import os
import statistics
import sys
import tempfile
import time
from pathlib import Path


def skeleton(fig):
    """``fig`` without its data: the same size, layout engine, axes (grid cells, projections, scales, limits),
    ticks with their labels, titles and axis labels, each axes holding one two-point line instead of the data (no
    legend, no shading, no annotation). Saving it costs what matplotlib's machinery costs for these figures
    whatever the data: the floor of :func:`measure`. ``fig`` must have been drawn (its tick labels are set then)."""
    from matplotlib.figure import Figure

    sk = Figure(figsize=fig.get_size_inches(), layout=fig.get_layout_engine() and "constrained")
    grids: dict = {}
    for ax in fig.axes:
        spec = ax.get_subplotspec()
        if spec is None:
            continue
        shape = spec.get_gridspec().get_geometry()
        if shape not in grids:  # one grid per shape (setdefault would make a new one for every axes)
            grids[shape] = sk.add_gridspec(*shape)
        gs = grids[shape]
        rows, cols = spec.rowspan, spec.colspan
        new = sk.add_subplot(gs[rows.start:rows.stop, cols.start:cols.stop], projection=ax.name)
        new.set_xscale(ax.get_xscale())
        new.set_yscale(ax.get_yscale())
        new.plot(ax.get_xlim(), ax.get_ylim())
        new.set_xlim(ax.get_xlim())
        new.set_ylim(ax.get_ylim())
        for minor in (False, True):
            new.set_xticks(ax.get_xticks(minor=minor), [t.get_text() for t in ax.get_xticklabels(minor=minor)],
                           minor=minor)
            new.set_yticks(ax.get_yticks(minor=minor), [t.get_text() for t in ax.get_yticklabels(minor=minor)],
                           minor=minor)
        new.set_title(ax.get_title())
        new.set_xlabel(ax.get_xlabel())
        new.set_ylabel(ax.get_ylabel())
        if not ax.axison:
            new.set_axis_off()
    sk.suptitle(fig.get_suptitle())
    return sk


def single_axes(result, path: Path) -> None:
    """The least figure a run could draw: one axes with constrained layout, the run's x against crank angle, two
    axis labels, saved as a PNG at 100 dpi. Its time against the ``simulate()`` call answers whether *any*
    matplotlib figure can be cheaper than the simulation it shows."""
    import numpy as np

    from ..results.figures import new_figure
    from ..results.outputs import describe

    fig = new_figure((6.4, 4.8))
    ax = fig.subplots()
    ax.plot(np.degrees(result.theta), result.column("x") * describe("x").scale, lw=0.8)
    ax.set_xlabel("crank angle (deg)")
    ax.set_ylabel(describe("x").label)
    fig.savefig(path, dpi=100)


def measure(repeats: int = 5) -> dict:
    import apexseal

    from ..results.figure_job import write_figures
    from ..results.figures import ports_of
    from ..results.plots import figure
    from ..results.saved_figures import figure_files, write_figure

    scene = apexseal.load_scene()
    result = apexseal.simulate(scene)  # warm-up: derivation and compilation come from the caches afterwards
    with tempfile.TemporaryDirectory() as tmp:
        write_figures(result, tmp, ports_of(scene))
        call, integration, figures, alone = [], [], [], []
        each: dict[str, list[float]] = {name: [] for name in figure_files(result)}
        floor: dict[str, list[float]] = {name: [] for name in figure_files(result)}
        least = []
        single_axes(result, Path(tmp) / "single-axes.png")
        for _ in range(repeats):
            t0 = time.perf_counter()
            result = apexseal.simulate(scene)
            call.append(time.perf_counter() - t0)
            integration.append(result.info["wall_time_s"])
            t0 = time.perf_counter()
            write_figures(result, tmp, ports_of(scene), fork=True)
            figures.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            write_figures(result, tmp, ports_of(scene), fork=False)
            alone.append(time.perf_counter() - t0)
            for name, kind in figure_files(result).items():
                t0 = time.perf_counter()
                write_figure(result, Path(tmp), name, kind, ports_of(scene))
                each[name].append(time.perf_counter() - t0)
                drawn = figure(result, kind, ports=ports_of(scene), save_dpi=100)
                drawn.draw_without_rendering()
                t0 = time.perf_counter()
                skeleton(drawn).savefig(Path(tmp) / f"skeleton-{name}", dpi=100)
                floor[name].append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            single_axes(result, Path(tmp) / "single-axes.png")
            least.append(time.perf_counter() - t0)
    med = {k: statistics.median(v) for k, v in (("simulate_call_s", call), ("integration_s", integration),
                                                  ("figures_s", figures), ("figures_one_process_s", alone))}
    med["figures_over_simulate_call"] = med["figures_s"] / med["simulate_call_s"]
    med["figures_over_integration"] = med["figures_s"] / med["integration_s"]
    med["repeats"] = repeats
    med["each_s"] = {name: statistics.median(v) for name, v in each.items()}
    med["floor_s"] = {name: statistics.median(v) for name, v in floor.items()}
    med["single_axes_s"] = statistics.median(least)
    return med


def _simulate(folder: str) -> list[str]:
    """The command line of a quiet ``apexseal simulate`` of the default scene into ``folder``, in a new process."""
    from ...cli import command

    return command("simulate", "-q", "--out", folder)


def _bytecode_note() -> None:
    """Whole runs compile apexseal's modules again in every process when Python may not write bytecode."""
    if os.environ.get("PYTHONDONTWRITEBYTECODE"):
        print("note: PYTHONDONTWRITEBYTECODE is set, so every whole run compiles apexseal's modules again (about "
              "0.1 s more per process than in an install); unset it for numbers comparable with docs/performance.md")


#: the stages of ``apexseal simulate --timings`` that make the result
SIMULATION_STAGES = ("scene", "load", "compile", "integrate", "assemble")


def measure_cli(repeats: int = 7) -> dict:
    """Medians of ``repeats`` whole ``apexseal simulate --timings -q`` runs (after one to warm the caches)."""
    import json
    import subprocess

    stages = []
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(repeats + 1):
            run = subprocess.run([*_simulate(f"{tmp}/run{k}"), "--timings"], capture_output=True, text=True, check=True)
            line = next(x for x in run.stdout.splitlines() if x.startswith("timings-json "))
            if k:
                stages.append(json.loads(line.split(" ", 1)[1]))
    med = {"figures_s": statistics.median(s["stages"].get("figures", 0.0) for s in stages),
           "simulation_s": statistics.median(sum(s["stages"].get(k, 0.0) for k in SIMULATION_STAGES) for s in stages),
           "integrate_s": statistics.median(s["stages"]["integrate"] for s in stages),
           "total_s": statistics.median(s["total_s"] for s in stages), "repeats": repeats}
    med["figures_over_simulation"] = med["figures_s"] / med["simulation_s"]
    return med


def _whole_run(folder: str, figures: bool) -> tuple[float, float]:
    """One whole ``apexseal simulate -q`` run of the default scene into ``folder``: its wall seconds, timed from
    outside, and the CPU seconds of its process and of every process it waited for (the figure worker and the
    process that worker forks)."""
    import resource
    import subprocess

    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(_simulate(folder) + ([] if figures else ["--no-figures"]), capture_output=True, check=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)


def measure_pairs(repeats: int = 7) -> dict:
    """What the figures add to a default run: ``repeats`` pairs of whole runs with and without figures (the order
    alternates from pair to pair, after one run of each to warm the caches); the medians of each kind and of the
    differences within the pairs, in wall and CPU seconds."""
    runs: dict[bool, list[tuple[float, float]]] = {True: [], False: []}
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(repeats + 1):
            for figures in ((True, False) if k % 2 else (False, True)):
                measured = _whole_run(f"{tmp}/run{k}-{int(figures)}", figures)
                if k:
                    runs[figures].append(measured)
    med = {"repeats": repeats}
    for i, clock in enumerate(("wall", "cpu")):
        with_, without = ([r[i] for r in runs[f]] for f in (True, False))
        med[f"{clock}_with_s"] = statistics.median(with_)
        med[f"{clock}_without_s"] = statistics.median(without)
        med[f"{clock}_added_s"] = statistics.median(a - b for a, b in zip(with_, without, strict=True))
        med[f"{clock}_added_over_without"] = med[f"{clock}_added_s"] / med[f"{clock}_without_s"]
    return med


def main() -> None:
    repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    if "--pairs" in sys.argv[2:]:
        _bytecode_note()
        m = measure_pairs(repeats)
        print(f"apexseal simulate -q (default scene), {repeats} pairs of whole runs with and without figures, medians: "
              f"wall {m['wall_with_s']:.2f} s with figures, {m['wall_without_s']:.2f} s without; the figures add "
              f"{m['wall_added_s']:.2f} s = {m['wall_added_over_without']:.2f} x the run without them; CPU "
              f"{m['cpu_with_s']:.2f} s against {m['cpu_without_s']:.2f} s, the figures add {m['cpu_added_s']:.2f} s "
              f"= {m['cpu_added_over_without']:.2f} x")
        return
    if "--cli" in sys.argv[2:]:
        _bytecode_note()
        m = measure_cli(repeats)
        print(f"apexseal simulate (default scene), medians of {repeats} runs: figures {m['figures_s']:.2f} s, "
              f"simulation (scene, load, compile, integrate, assemble) {m['simulation_s']:.2f} s, ratio "
              f"{m['figures_over_simulation']:.2f}; integration {m['integrate_s']:.2f} s; whole run {m['total_s']:.2f} s")
        return
    m = measure(repeats)
    print(f"default scene, medians of {repeats} runs: simulate() {m['simulate_call_s']:.2f} s (integration "
          f"{m['integration_s']:.2f} s); four figures {m['figures_s']:.2f} s = {m['figures_over_simulate_call']:.2f} x "
          f"the simulate() call, {m['figures_over_integration']:.1f} x the integration (in one process: "
          f"{m['figures_one_process_s']:.2f} s)")
    print("each figure: " + ", ".join(f"{name} {t:.3f} s" for name, t in m["each_s"].items()))
    floor = sum(m["floor_s"].values())
    print("matplotlib's floor, the same axes with a two-point line each (figure_timing.skeleton): "
          + ", ".join(f"{name} {t:.3f} s" for name, t in m["floor_s"].items())
          + f"; together {floor:.2f} s, {floor / 2:.2f} s on two cores = {floor / 2 / m['simulate_call_s']:.2f} x the "
          "simulate() call")
    print("the least figure, one axes with a line of x and two labels (figure_timing.single_axes): "
          f"{m['single_axes_s']:.3f} s = {m['single_axes_s'] / m['simulate_call_s']:.2f} x the simulate() call, "
          f"{m['single_axes_s'] / m['integration_s']:.2f} x the integration")


if __name__ == "__main__":
    main()
