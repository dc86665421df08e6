"""The paper's figures for a run: Fig. 12 (polar displacements), Fig. 13 (forces), Fig. 14 (spectrum), modes."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...files import atomic_open
from .result import SimulationResult
from .summary import housing_force, spectrum


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(plt, fig, path: Path) -> Path:
    """Lay out, write atomically (PNG) and close ``fig``."""
    fig.tight_layout()
    with atomic_open(path, "wb") as fh:
        fig.savefig(fh, dpi=110, format="png")
    plt.close(fig)
    return path


def _ports(ax, ports: dict | None) -> None:
    for name, port in (ports or {}).items():
        a0 = np.radians(port["angle_deg"])
        w = np.radians(port["width_deg"])
        ax.axvspan(a0, a0 + w, color="tab:orange" if name == "inlet" else "tab:green", alpha=0.25, label=f"{name} port")


def fig12_displacements(result: SimulationResult, path: Path, ports: dict | None = None) -> Path:
    """Fig. 12: x, y and phi against crank angle, as polar plots with the ports marked."""
    plt = _plt()
    fig, axes = plt.subplots(1, 3, subplot_kw={"projection": "polar"}, figsize=(13, 4.6))
    th = result.theta
    for ax, (i, label, scale) in zip(axes, ((0, "x (µm)", 1e6), (1, "y (µm)", 1e6), (2, "ϕ (mrad)", 1e3)),
                                     strict=True):
        v = result.state[i] * scale
        lo, hi = float(v.min()), float(v.max())
        pad = 0.1 * (hi - lo or 1.0)
        ax.plot(th, v, lw=0.8)
        ax.set_rlim(lo - pad, hi + pad)
        _ports(ax, ports)
        ax.set_title(label, pad=14)
    axes[0].legend(loc="lower left", bbox_to_anchor=(-0.25, -0.2), fontsize=8)
    fig.suptitle("Seal displacements against crank angle (cf. Fig. 12)")
    return _save(plt, fig, path)


def fig13_forces(result: SimulationResult, path: Path) -> Path:
    """Fig. 13: groove contact forces Fi1, Fi2, Fc2, Fc4, spring force Fs6 and housing force Fs5."""
    plt = _plt()
    deg = np.degrees(result.theta)
    names = [("i1", "F_i1"), ("i2", "F_i2"), ("c2", "F_c2"), ("c4", "F_c4"), ("spring", "F_s6"), ("housing", "F_s5")]
    fig, axes = plt.subplots(3, 2, figsize=(12, 8), sharex=True)
    for ax, (key, label) in zip(axes.ravel(), names, strict=True):
        if f"F_{key}_X" in result.outputs:
            F = np.hypot(result.outputs[f"F_{key}_X"], result.outputs[f"F_{key}_Y"])
            ax.plot(deg, F, lw=0.7)
        else:
            ax.text(0.5, 0.5, "effect off", ha="center", va="center", transform=ax.transAxes)
        ax.set_ylabel(f"|{label}| (N)")
    for ax in axes[-1]:
        ax.set_xlabel("crank angle (deg)")
    fig.suptitle("Forces on the apex seal (cf. Fig. 13)")
    return _save(plt, fig, path)


def fig14_spectrum(result: SimulationResult, path: Path) -> Path:
    """Fig. 14: amplitude spectrum of the seal-housing force Fs5 against angular frequency."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 4))
    if result.n > 8:
        w, amp = spectrum(housing_force(result)[1:], float(np.mean(np.diff(result.time))))
        ax.semilogy(w, np.maximum(amp, 1e-12), lw=0.7)
    ax.set_xlabel("angular frequency (rad/s)")
    ax.set_ylabel("|Fs5| amplitude (N)")
    ax.set_title("Spectrum of the seal-housing force (cf. Fig. 14)")
    return _save(plt, fig, path)


def mode_timeline(result: SimulationResult, path: Path) -> Path:
    """Which contacts are closed at each crank angle, and the contact case (Algorithm 3)."""
    plt = _plt()
    deg = np.degrees(result.theta)
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(12, 5), sharex=True, gridspec_kw={"height_ratios": [1.2, 1]})
    for i in range(len(result.guard_names)):
        ax1.fill_between(deg, i, i + 0.8 * result.closed[i], step="post", alpha=0.8)
    ax1.set_yticks(np.arange(len(result.guard_names)) + 0.4, result.guard_names)
    ax1.set_title("closed contacts")
    cases = sorted(set(m.split("_")[0] for m in result.modes))
    idx = np.array([cases.index(m.split("_")[0]) for m in result.modes])
    ax2.step(deg, idx, where="post", lw=0.8)
    ax2.set_yticks(range(len(cases)), cases)
    ax2.set_xlabel("crank angle (deg)")
    ax2.set_title("seal-groove contact case")
    return _save(plt, fig, path)


def write_figures(result: SimulationResult, folder: Path, ports: dict | None = None) -> list[Path]:
    folder = Path(folder)
    return [fig12_displacements(result, folder / "fig12_displacements.png", ports),
            fig13_forces(result, folder / "fig13_forces.png"),
            fig14_spectrum(result, folder / "fig14_housing_spectrum.png"),
            mode_timeline(result, folder / "mode_timeline.png")]
