"""The work-precision diagram: error against CPU time per revolution, one curve per method.

One row per scene; left the scaled state error, right the friction-power error.
Solid lines: generated C; dashed with hollow markers: CasADi's interpreted VM;
dotted: lambdify + solve_ivp; dash-dotted: the hand-written numba peer; the paper's Euler in black.
Failed points are counted in the legend.
"""

from __future__ import annotations

from pathlib import Path
from typing import BinaryIO

STYLE = {  # method -> (colour, line style, marker)
    "euler-C": ("black", "-", "s"),
    "rk4-C": ("tab:olive", "-", "v"),
    "erk-rk4-C": ("tab:brown", "-", "^"),
    "erk-C": ("tab:blue", "-", "o"),
    "composite-C": ("crimson", "-", "*"),  # the fastest: drawn bold (it was the default thin grey)
    "rosenbrock-C": ("tab:orange", "-", "D"),
    "cvodes-C": ("tab:green", "-", "P"),
    "cvodes-adams-C": ("tab:cyan", "-", "X"),
    "idas-C": ("tab:purple", "-", "h"),
    "collocation-C": ("tab:gray", "-", "*"),
    "erk-VM": ("tab:blue", "--", "o"),
    "rosenbrock-VM": ("tab:orange", "--", "D"),
    "scipy-RK45": ("tab:red", ":", "o"),
    "scipy-Radau": ("tab:pink", ":", "D"),
    "scipy-LSODA": ("maroon", ":", "P"),
    "numba-scipy-LSODA": ("indigo", "-.", "x"),
    "numbalsoda-LSODA": ("darkviolet", "-.", "P"),
    "numbalsoda-DOP853": ("magenta", "-.", "o"),
}


#: drawn thicker: the paper's method and apexseal's fastest
BOLD = ("euler-C", "composite-C")


def work_precision(results: dict, path: Path | BinaryIO) -> Path | BinaryIO:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenes = results["scenes"]
    target = results["config"]["target_error"]
    fig, axes = plt.subplots(len(scenes), 2, figsize=(13, 5.2 * len(scenes)), squeeze=False)
    handles: dict = {}
    for row, s in zip(axes, scenes, strict=True):
        for ax, key, title in ((row[0], "state", "scaled error (max of x, y, phi)"),
                               (row[1], "friction_power", "relative error of mean friction power")):
            for mid in dict.fromkeys(p["method"] for p in s["points"]):
                pts = [p for p in s["points"] if p["method"] == mid]
                order = sorted(pts, key=lambda p: -p["value"] if p["sweep"] == "rtol" else p["value"])  # sweep order
                ok = [(p["timing"]["median_cpu_s"], p["error"][key]) for p in order
                      if p["status"] == "ok" and p["error"].get(key)]
                failed = len(pts) - sum(p["status"] == "ok" for p in pts)
                colour, ls, marker = STYLE.get(mid, ("tab:gray", "-", "."))
                label = pts[0]["label"] + (f" ({failed} failed)" if failed else "")
                (h,) = ax.plot([q[0] for q in ok], [q[1] for q in ok], ls=ls, marker=marker, color=colour,
                               lw=2.2 if mid in BOLD else 1.5, ms=8 if mid == "composite-C" else 5, label=label,
                               mfc="none" if mid.endswith("-VM") else colour)
                handles.setdefault(label, h)
            ax.axhline(target, color="0.5", lw=0.8, ls="-.")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel("CPU time per revolution [s]")
            ax.set_ylabel(title)
            ax.set_title(f"{s['name']} scene: {title}", fontsize=10)
            ax.grid(True, which="both", alpha=0.25)
    fig.legend(handles.values(), handles.keys(), loc="lower center", ncol=4, fontsize=8, frameon=False)
    m = results["machine"]
    fig.suptitle(f"apexseal work-precision ({results['config']['mode']}): one revolution, {results['config']['samples']} "
                 f"samples; {m['cpu']}, casadi {m['packages'].get('casadi')}", fontsize=11)
    rows = (len(handles) + 3) // 4
    fig.tight_layout(rect=(0, 0.03 + 0.025 * rows / len(scenes), 1, 0.97))
    fig.savefig(path, dpi=110, format="png")  # a path or an open binary file
    plt.close(fig)
    return path
