"""The chamber gas model's figures: both chamber pressures against crank angle (cf. Fig. 11) and the p-V diagram,
over the last whole revolution."""

from __future__ import annotations

import numpy as np

from .figures import new_figure
from .gas import last_revolution
from .result import SimulationResult


def fig11_pressures(result: SimulationResult, *, pyplot: bool = False):
    """Fig. 11 style: both chamber pressures against crank angle over the last revolution."""
    k = last_revolution(result)
    deg = np.degrees(result.theta[k]) % 360
    order = np.argsort(deg)
    fig = new_figure((7, 3.6), pyplot)
    ax = fig.subplots()
    for c, colour, label in (("a", "tab:blue", "chamber a (+Ys, upper)"), ("b", "tab:red", "chamber b (-Ys, lower)")):
        ax.plot(deg[order], result.outputs["P" + c][k][order] / 1e5, color=colour, label=label)
    ax.set_xlabel("crank angle (deg)")
    ax.set_ylabel("pressure (bar)")
    ax.set_xlim(0, 360)
    ax.legend()
    ax.grid(alpha=0.3)
    ax.set_title("Chamber pressures against crank angle (cf. Fig. 11)", y=1.0)  # placed: see figures.TITLE_Y_POLAR
    return fig


def pv_diagram(result: SimulationResult, *, pyplot: bool = False):
    """p-V diagram of both chambers over the last revolution."""
    k = last_revolution(result)
    fig = new_figure((5, 4), pyplot)
    ax = fig.subplots()
    for c, colour in (("a", "tab:blue"), ("b", "tab:red")):
        ax.plot(result.outputs["V" + c][k] * 1e6, result.outputs["P" + c][k] / 1e5, color=colour, label=f"chamber {c}")
    ax.set_xlabel("volume (cm^3)")
    ax.set_ylabel("pressure (bar)")
    ax.legend()
    ax.grid(alpha=0.3)
    return fig
