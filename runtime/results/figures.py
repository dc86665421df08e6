"""The paper's figures for a run: Fig. 12 (polar displacements), Fig. 13 (forces), Fig. 14 (spectrum), modes.

Each function returns a matplotlib :class:`~matplotlib.figure.Figure` drawn with constrained layout. Figures
are made without pyplot (``Figure()``), so drawing never touches the user's backend or pyplot's figure list; in
a notebook a returned Figure displays itself, in a script ``fig.savefig(path)`` writes it. ``pyplot=True``
makes them through ``matplotlib.pyplot`` instead (for ``plt.show()`` windows). :mod:`.saved_figures` says which
figures a run writes and saves them as PNG files.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .decimate import columns_of, envelope, envelope_index, step_changes
from .outputs import describe
from .result import SimulationResult
from .spectra import contact_force, spectral_peaks, spectrum

PORT_COLOURS = {"inlet": "tab:orange", "outlet": "tab:green"}
#: height of Fig. 12's panel titles (axes fraction): just above the 90 deg label, where matplotlib's automatic placement
#: put them. Every title is placed at a given height: the automatic one measures the tick labels of the axes again for
#: each title in each layout pass, a tenth to a fifth of Fig. 12's, Fig. 14's and the modes' drawing time
#: (docs/performance.md); their tick labels are never above the axes (Fig. 12's angle labels are fixed)
TITLE_Y_POLAR = 1.075


def new_figure(figsize: tuple[float, float], pyplot: bool = False):
    """An empty Figure with constrained layout (through pyplot only if asked)."""
    if pyplot:
        import matplotlib.pyplot as plt

        return plt.figure(figsize=figsize, layout="constrained")
    from matplotlib.figure import Figure

    return Figure(figsize=figsize, layout="constrained")


def save_png(fig, path, dpi: int) -> None:
    """Save ``fig`` as the PNG file ``path`` at ``dpi``, atomically: a half-written PNG never carries the final
    name."""
    from ...files import atomic_open

    with atomic_open(path, "wb") as fh:
        fig.savefig(fh, format="png", dpi=dpi)


def crank_angle_ticks(ax, value_ticks: int | None = 4) -> None:
    """At most five crank-angle ticks (x, deg) at multiples of 90 deg (of 1.5 or 4.5 times a power of ten on
    longer runs), and at most ``value_ticks`` on the value axis (None: left as they are): every tick costs
    matplotlib a line and a text laid out in each pass of constrained layout (docs/performance.md)."""
    from matplotlib.ticker import MaxNLocator

    ax.xaxis.set_major_locator(MaxNLocator(nbins=5, steps=[1, 1.5, 3, 4.5, 9, 10]))
    if value_ticks is not None:
        ax.yaxis.set_major_locator(MaxNLocator(nbins=value_ticks))


def ports_of(scene) -> dict | None:
    """``{name: {"angle_deg", "width_deg"}}`` of a scene's ports (Table 1), or None: each centred where the seal
    passes it on the figures' crank-angle axis, which counts from the scene's start angle as ``result.theta`` does.
    The port is centred at housing angle ``datum + angle`` and the seal at housing angle theta (derive/ports.py),
    so on that axis its centre is ``datum + angle - operation.start_angle``."""
    ports = getattr(getattr(scene, "machine", None), "ports", None)
    if not ports:
        return None
    shift = math.degrees(ports.datum - scene.operation.start_angle)
    return {k: {"angle_deg": v.angle_deg + shift, "width_deg": v.width_deg} for k, v in ports.items()}


def _ports(ax, ports: dict | None, polar: bool) -> list:
    """Shade the ports (centred on their angle); returns the legend handles."""
    handles = []
    for name, port in (ports or {}).items():
        a0, w = port["angle_deg"] - port["width_deg"] / 2, port["width_deg"]
        lo, hi = (np.radians(a0), np.radians(a0 + w)) if polar else (a0 % 360, a0 % 360 + w)
        handles.append(ax.axvspan(lo, hi, color=PORT_COLOURS.get(name, "tab:gray"), alpha=0.25, lw=0,
                                  label=f"{name} port"))
    return handles


#: tick objects made ahead in each axis of a frame (matplotlib makes any further ones as it needs them): more than
#: the figures show
TICKS_AHEAD = 8


@dataclass
class Frame:
    """A figure drawn before its data: its axes, texts, shading and empty lines, built for ``spec`` (what it shows
    besides the data: Fig. 12's ports, Fig. 13's panels). A figure process builds the frames while the run
    integrates (:meth:`.figure_worker.FigureWorker.prepare`); the figure function fills one in if it was built for
    what the result shows, else draws its own (the same calls in the same order either way)."""

    kind: str
    spec: Any
    fig: Any
    axes: list
    lines: list
    #: minor tick objects to make ahead in each axis (only logarithmic axes show them)
    minor_ticks: int = 0
    used: bool = False


def _framed(frame: Frame | None, kind: str, spec) -> Frame | None:
    """``frame`` if it is an unused frame of ``kind`` built for ``spec``, else None."""
    if frame is None or frame.kind != kind or frame.spec != spec or frame.used:
        return None
    frame.used = True  # a frame holds one figure's data: it is never filled twice
    return frame


def fig12_frame(ports: dict | None = None, pyplot: bool = False) -> Frame:
    """Fig. 12 without its data (see :func:`fig12_displacements`)."""
    from matplotlib.lines import Line2D
    from matplotlib.ticker import MaxNLocator

    fig = new_figure((13, 5.2), pyplot)
    axes = list(fig.subplots(1, 3, subplot_kw={"projection": "polar"}))
    lines, handles = [], []
    for ax, name in zip(axes, ("x", "y", "phi"), strict=True):
        ax.yaxis.set_major_locator(MaxNLocator(4))
        ax.set_rlabel_position(112.5)
        ax.set_thetagrids([0, 90, 180, 270])  # four angle labels, not eight: each costs a text layout per pass
        ax.tick_params(axis="y", labelsize=8)
        lines.append(ax.plot([], [], lw=0.8, color="tab:blue")[0])
        ax.plot(np.linspace(0, 2 * np.pi, 181), np.zeros(181), ls="--", lw=0.8, color="k")
        handles = _ports(ax, ports, polar=True)
        ax.set_title(describe(name).label, pad=18, y=TITLE_Y_POLAR)
    zero = Line2D([], [], ls="--", lw=0.8, color="k", label="zero")
    fig.legend(handles=[*handles, zero], loc="outside lower center", ncols=len(handles) + 1, fontsize=9)
    fig.suptitle("Seal displacements against crank angle (cf. Fig. 12; angle = crank angle, radius = value)")
    return Frame("fig12", ports, fig, axes, lines)


def fig12_displacements(result: SimulationResult, ports: dict | None = None, *, pyplot: bool = False,
                        frame: Frame | None = None):
    """Fig. 12: x, y and phi against crank angle as polar plots (radius = value), ports shaded.

    The radial axis starts below the smallest value (a hole in the middle) and the zero circle is drawn
    dashed, so negative displacements read as "inside the dashed circle" rather than folding through the
    centre; at most four radial ticks, labelled on a clear ray; angle labels every 90 deg. ``frame``: a
    :func:`fig12_frame` built ahead (used if it has these ports).
    """
    frame = _framed(frame, "fig12", ports) or fig12_frame(ports, pyplot)
    th = result.theta
    for ax, line, name in zip(frame.axes, frame.lines, ("x", "y", "phi"), strict=True):
        v = result.column(name) * describe(name).scale
        lo, hi = (float(v.min()), float(v.max())) if v.size else (0.0, 1.0)
        lo, hi = min(lo, 0.0), max(hi, 0.0)
        span = hi - lo or 1.0
        r0 = lo - 0.05 * span
        ax.set_rorigin(r0 - 0.35 * span)  # a hole in the middle: the smallest value does not sit on the centre
        ax.set_rlim(r0, hi + 0.05 * span)
        line.set_data(th, v)
        ax.relim()  # the data limits plotting the line would give (the view is set above)
    return frame.fig


def force_panels(outputs) -> list[str]:
    """The contacts and loads whose force a result carries (the ``F_<name>_X``/``F_<name>_Y`` outputs the model
    derives for every contact model of its active submodels), in the model's order: one Fig. 13 panel each. A
    contact whose effect is off is never derived, so it has no panel; a registered extra contact gets one."""
    return [n[2:-2] for n in outputs if n.startswith("F_") and n.endswith("_X") and n[:-2] + "_Y" in outputs]


def fig13_frame(names: list[str], pyplot: bool = False) -> Frame:
    """Fig. 13 without its data: a panel for each force of ``names`` (:func:`force_panels`)."""
    rows = max(1, -(-len(names) // 2))
    fig = new_figure((12, 1.2 + 2.3 * rows), pyplot)
    axes = list(np.atleast_1d(fig.subplots(rows, 2, sharex=True, squeeze=False)).ravel())
    lines = []
    for ax, key in zip(axes[:len(names)], names, strict=True):
        lines.append(ax.plot([], [], lw=0.7)[0])
        ax.set_ylabel(f"|F {key}| (N)")
        crank_angle_ticks(ax)
    for ax in axes[len(names):]:
        ax.set_axis_off()
    for ax in axes[max(0, len(names) - 2):len(names)]:  # the lowest panel of each column
        ax.set_xlabel("crank angle (deg)")
        ax.xaxis.set_tick_params(labelbottom=True)
    fig.suptitle("Forces on the apex seal (cf. Fig. 13)")
    return Frame("fig13", list(names), fig, axes[:len(names)], lines)


def fig13_forces(result: SimulationResult, *, pyplot: bool = False, save_dpi: float | None = None,
                 frame: Frame | None = None):
    """Fig. 13: the magnitude of every force on the seal the run's model has (:func:`force_panels`): for the
    full model the groove contacts Fi1, Fc2, Fi2, Fc4, the spring Fs6, the housing Fs5 and the chamber pressure.

    With ``save_dpi`` (the figure is to be saved at that resolution) each line is reduced to its envelope over
    the pixel columns (:func:`.decimate.envelope`); without it every sample is drawn. ``frame``: a
    :func:`fig13_frame` built ahead (used if it has these panels).
    """
    deg = np.degrees(result.theta)
    names = force_panels(result.outputs)
    frame = _framed(frame, "fig13", names) or fig13_frame(names, pyplot)
    columns = None if save_dpi is None else columns_of(frame.fig, save_dpi)
    for line, key in zip(frame.lines, names, strict=True):
        F = contact_force(result.outputs, key)
        line.set_data(*((deg, F) if columns is None else envelope(deg, F, columns)))
    for ax in frame.axes:  # every panel's data first: their x axis is shared
        ax.relim()
        ax.autoscale_view()
    return frame.fig


_SUPERSCRIPT = str.maketrans("-0123456789", "\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078\u2079")


def decade_label(value: float, _pos=None) -> str:
    """``10³`` for a power of ten (Unicode superscripts, plain text), "" for anything else."""
    if not value > 0:
        return ""
    e = float(np.log10(value))
    return f"10{str(int(round(e))).translate(_SUPERSCRIPT)}" if abs(e - round(e)) < 1e-9 else ""


def plain_log_ticks(ax) -> None:
    """Logarithmic axes labelled at the decades in plain text, minor ticks at 2 and 5 without labels.

    matplotlib's default labels (``$\\mathdefault{10^{3}}$``) go through its mathtext parser and its minor
    locator puts 8 ticks in each decade: together about half of Fig. 14's drawing time (docs/performance.md).
    An axis whose limits hold fewer than two decades keeps matplotlib's ticks (it labels minor ticks there).
    Call it after the limits are set.
    """
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    for axis, (lo, hi) in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
        lo, hi = sorted((lo, hi))
        if axis.get_scale() == "log" and lo > 0 and np.floor(np.log10(hi)) - np.ceil(np.log10(lo)) >= 1:
            axis.set_major_formatter(FuncFormatter(decade_label))
            axis.set_minor_locator(LogLocator(subs=(2.0, 5.0)))
            axis.set_minor_formatter(NullFormatter())


#: N: the least amplitude Fig. 14 draws (its logarithmic axis has no zero); a spectrum no higher has nothing to show
AMPLITUDE_FLOOR = 1e-12
#: a spectrum below this fraction of the largest |Fs5| is the round-off of a constant force, not a spectrum
ROUND_OFF = 1e-9


def no_spectrum(result: SimulationResult, force: np.ndarray | None, amp: np.ndarray | None) -> str | None:
    """Why Fig. 14 has no spectrum to draw on its logarithmic axes, or None when it has one: too few samples, no
    housing contact in the model, a tip off the housing for the whole run (no contact force Fs5 at any sample), or a
    constant force (its spectrum ``amp`` is round-off). ``force``: |Fs5| after the start sample (None: the model has
    no housing contact)."""
    if result.n <= 8:
        return f"{result.n} samples: too few for a spectrum"
    if force is None:
        return "no seal-housing contact in this model (effects.housing_contact off): no force Fs5"
    if not np.any(force > 0):
        return ("the seal tip is off the housing for the whole run:\nno contact force Fs5, so no spectrum\n"
                "(summary.json: liftoff)")
    if not float(amp[1:].max()) > max(AMPLITUDE_FLOOR, ROUND_OFF * float(force.max())):
        return f"the seal-housing force Fs5 is constant ({float(force.mean()):.4g} N): no spectrum"
    return None


def fig14_frame(pyplot: bool = False) -> Frame:
    """Fig. 14 without its data (see :func:`fig14_spectrum`)."""
    fig = new_figure((8, 4.2), pyplot)
    ax = fig.subplots()
    ax.set_xlabel("angular frequency (rad/s)")
    ax.set_ylabel("|Fs5| amplitude (N)")
    ax.set_title("Spectrum of the seal-housing force (cf. Fig. 14); ▼ distinct peaks", y=1.0)  # see TITLE_Y_POLAR
    return Frame("fig14", None, fig, [ax], [], minor_ticks=2 * TICKS_AHEAD)  # log axes: minor ticks at 2 and 5


def fig14_spectrum(result: SimulationResult, *, count: int = 5, pyplot: bool = False, save_dpi: float | None = None,
                   frame: Frame | None = None):
    """Fig. 14: amplitude spectrum of the seal-housing force Fs5, on logarithmic axes, with its distinct peaks
    (:func:`.summary.spectral_peaks`, from every frequency) marked and labelled; with ``save_dpi`` the line is
    its envelope over the pixel columns of the logarithmic axis (:func:`.decimate.envelope_index`). Where there is
    no spectrum to draw on logarithmic axes (:func:`no_spectrum`: e.g. the tip off the housing for the whole run)
    the axes say why instead, and matplotlib warns of nothing. ``frame``: a :func:`fig14_frame` built ahead."""
    frame = _framed(frame, "fig14", None) or fig14_frame(pyplot)
    fig, ax = frame.fig, frame.axes[0]
    force, w, amp = contact_force(result.outputs, "housing"), None, None
    if force is not None and result.n > 8:
        force = force[1:]
        w, amp = spectrum(force, float(np.mean(np.diff(result.time))))
    empty = no_spectrum(result, force, amp)
    if empty is not None:  # nothing positive to draw on logarithmic axes: say why instead
        ax.set_xticks([])
        ax.set_yticks([])
        ax.text(0.5, 0.5, empty, transform=ax.transAxes, ha="center", va="center", color="0.3")
        return fig
    line = np.maximum(amp[1:], AMPLITUDE_FLOOR)
    keep = (slice(None) if save_dpi is None else
            envelope_index(np.log(w[1:]), line, columns_of(fig, save_dpi)))
    ax.loglog(w[1:][keep], line[keep], lw=0.7)
    ax.set_xlim(w[1] / 1.5, w[-1])  # room for the label of a peak at the first frequency
    floor = max(float(amp[1:].max()) * 1e-4, AMPLITUDE_FLOOR)
    ax.set_ylim(floor, float(amp.max()) * 3)
    plain_log_ticks(ax)
    for p in spectral_peaks(w, amp, count):
        ax.plot(p["omega_rad_s"], p["amplitude_N"], "v", color="tab:red", ms=6)
        ax.annotate(f"{p['omega_rad_s']:.3g}", (p["omega_rad_s"], p["amplitude_N"]), textcoords="offset points",
                    xytext=(0, 7), ha="center", fontsize=8, color="tab:red")
    return fig


def contact_cases(modes: list[str]) -> tuple[list[str], np.ndarray]:
    """The contact cases of a run's mode labels (the label before its first ``_``), sorted, and each sample's
    index among them. Each distinct label is split once: a run has a few labels over tens of thousands of
    samples."""
    labels: dict[str, int] = {}
    codes = np.fromiter((labels.setdefault(m, len(labels)) for m in modes), dtype=np.intp, count=len(modes))
    case_of = [label.split("_")[0] for label in labels]
    cases = sorted(set(case_of))
    return cases, np.array([cases.index(c) for c in case_of], dtype=np.intp)[codes]


def modes_frame(pyplot: bool = False) -> Frame:
    """The modes figure without its data (see :func:`mode_timeline`)."""
    fig = new_figure((12, 5), pyplot)
    ax1, ax2 = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [1.2, 1]})
    ax1.set_title("closed contacts", y=1.0)  # placed, not searched: see TITLE_Y_POLAR
    ax2.set_xlabel("crank angle (deg)")
    crank_angle_ticks(ax2, value_ticks=None)
    ax2.set_title("seal-groove contact case", y=1.0)
    return Frame("modes", None, fig, [ax1, ax2], [])


def mode_timeline(result: SimulationResult, *, pyplot: bool = False, save_dpi: float | None = None,
                  frame: Frame | None = None):
    """Which contacts are closed at each crank angle, and the contact case (Algorithm 3).

    Both are steps, drawn through the samples where they change (:func:`.decimate.step_changes`: the same
    steps, without the repeated vertices). ``save_dpi`` is accepted like the other figures' and changes nothing.
    ``frame``: a :func:`modes_frame` built ahead.
    """
    frame = _framed(frame, "modes", None) or modes_frame(pyplot)
    ax1, ax2 = frame.axes
    deg = np.degrees(result.theta)
    for i in range(len(result.guard_names)):
        x, closed = step_changes(deg, np.asarray(result.closed[i], float))
        ax1.fill_between(x, i, i + 0.8 * closed, step="post", alpha=0.8)
    ax1.set_yticks(np.arange(len(result.guard_names)) + 0.4, result.guard_names)
    cases, idx = contact_cases(result.modes)
    ax2.step(*step_changes(deg, idx), where="post", lw=0.8)
    ax2.set_yticks(range(len(cases)), cases)
    return frame.fig


def frames_ahead(panels: list[str], ports: dict | None, stop=None) -> dict[str, Frame]:
    """The four figures' frames with their tick objects made, Fig. 13's for the force ``panels`` and Fig. 12's for
    the ``ports``: what a figure process builds while the run integrates (:mod:`.figure_worker`), by figure kind,
    costliest first. ``stop()`` is asked before each: once it is true (the result is there), the frames not built
    yet are left to the processes that draw the figures, which build them side by side."""
    makers = {"fig13": lambda: fig13_frame(panels), "fig12": lambda: fig12_frame(ports), "fig14": fig14_frame,
              "modes": modes_frame}
    frames = {}
    for kind, make in makers.items():
        if stop is not None and stop():
            break
        frame = frames[kind] = make()
        for ax in frame.fig.axes:
            for axis in (ax.xaxis, ax.yaxis):
                axis.get_major_ticks(TICKS_AHEAD)
                axis.get_minor_ticks(frame.minor_ticks)
    return frames
