"""``result.plot(...)`` and the comparison of several results in one figure (PyBaMM's ``dynamic_plot`` model).

Figures come from :mod:`.figures` (never through the user's backend unless ``pyplot=True``); quantities are
shown in the display units of :mod:`.outputs` against crank angle in degrees.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from . import figures
from .outputs import describe

#: figure names accepted by :func:`plot`
FIGURES = ("fig12", "fig13", "fig14", "modes", "fig11", "pv")


def figure(result, kind: str, *, ports: dict | None = None, pyplot: bool = False, save_dpi: float | None = None,
           frame: figures.Frame | None = None):
    """One of the paper's figures by name (see :data:`FIGURES`); ``save_dpi``: drawn to be saved at that
    resolution, long lines reduced to their envelope over its pixel columns (:mod:`.decimate`); ``frame``: the
    figure built ahead without its data (:func:`.figures.frames_ahead`), used if it fits."""
    if kind == "fig12":
        return figures.fig12_displacements(result, ports if ports is not None else figures.ports_of(result.scene),
                                           pyplot=pyplot, frame=frame)
    if kind == "fig13":
        return figures.fig13_forces(result, pyplot=pyplot, save_dpi=save_dpi, frame=frame)
    if kind == "fig14":
        return figures.fig14_spectrum(result, pyplot=pyplot, save_dpi=save_dpi, frame=frame)
    if kind == "modes":
        return figures.mode_timeline(result, pyplot=pyplot, save_dpi=save_dpi, frame=frame)
    if kind in ("fig11", "pv"):
        from . import gas, gas_figures

        if not gas.has_gas(result):
            from ..scenes.schema import GAS_SOURCES

            raise ValueError(f"figure {kind!r} needs the chamber gas model (pressure.source = "
                             + " or ".join(f'"{s}"' for s in GAS_SOURCES) + ")")
        return (gas_figures.fig11_pressures(result, pyplot=pyplot) if kind == "fig11" else
                gas_figures.pv_diagram(result, pyplot=pyplot))
    raise ValueError(f"unknown figure {kind!r}; figures: {', '.join(FIGURES)}")


def _check_quantities(result, names: Sequence[str], label: str | None = None, elsewhere=frozenset()) -> None:
    """Every name a column of ``result``; one that another result of the same plot has (``elsewhere``) is named as
    missing from this one (``label``: an effect off in its model), not as a typo."""
    known = [*result.state_names, *result.outputs]
    bad = [n for n in names if n not in known]
    absent = [n for n in bad if n in elsewhere]
    if absent:
        raise ValueError(f"cannot plot {', '.join(map(repr, absent))} of result {label!r}: the other results have "
                         "it, this one's model does not (an effect off in its scene?); plot it without that result")
    if bad:
        from ...suggest import did_you_mean

        hints = [f"{b!r}{did_you_mean(b, known)}" for b in bad]
        raise ValueError(f"cannot plot {', '.join(hints)}: not a figure ({', '.join(FIGURES)}) nor a quantity of "
                         f"this result ({', '.join(known)})")


def quantities(results, names: Sequence[str], labels: Sequence[str] | None = None, *, pyplot: bool = False):
    """One panel per quantity against crank angle (deg), one line per result, a shared legend."""
    names = [names] if isinstance(names, str) else list(names)  # one quantity, not its characters
    if not names:
        raise ValueError("quantities: name at least one quantity, e.g. ['x', 'Pf_total']")
    labels = list(labels) if labels is not None else [result_label(r, i) for i, r in enumerate(results)]
    if len(labels) != len(results):
        raise ValueError(f"{len(labels)} labels for {len(results)} results")
    columns = [{*r.state_names, *r.outputs} for r in results]
    for i, (r, label) in enumerate(zip(results, labels, strict=True)):
        _check_quantities(r, names, label, set().union(*columns[:i], *columns[i + 1:]))
    fig = figures.new_figure((10, 1.2 + 2.0 * len(names)), pyplot)
    axes = np.atleast_1d(fig.subplots(len(names), 1, sharex=True, squeeze=False)[:, 0])
    for ax, name in zip(axes, names, strict=True):
        c = describe(name)
        for r, label in zip(results, labels, strict=True):
            ax.plot(np.degrees(r.theta), r.column(name) * c.scale, lw=0.8, label=label)
        ax.set_ylabel(c.label)
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("crank angle (deg)")
    if len(results) > 1:
        fig.legend(*axes[0].get_legend_handles_labels(), loc="outside upper center", ncols=min(len(results), 4))
    return fig


def result_label(result, i: int) -> str:
    """A result's name in a legend: its scene's name and the start of its content hash."""
    scene = result.info.get("scene") or f"result {i + 1}"
    h = str(result.info.get("scene_hash", ""))[:8]
    return f"{scene} {h}".strip()


def plot(result, *what: str, ports: dict | None = None, pyplot: bool = False):
    """The paper's figures by name (``fig12``, ``fig13``, ``fig14``, ``modes``) or quantities against crank angle.

    ``result.plot()`` is Fig. 12; ``result.plot("fig14")`` a Figure; ``result.plot("fig12", "fig13")`` a list of
    Figures; ``result.plot("x", "Pf_total")`` one Figure with a panel per quantity.
    """
    what = what or ("fig12",)
    kinds = [w for w in what if w in FIGURES]
    if kinds and len(kinds) != len(what):
        raise ValueError("give either figure names or quantities, not both")
    if kinds:
        figs = [figure(result, k, ports=ports, pyplot=pyplot) for k in kinds]
        return figs[0] if len(figs) == 1 else figs
    return quantities([result], what, pyplot=pyplot)


def plot_comparison(results, quantities: Sequence[str] = ("x", "y", "phi", "Pf_total"),  # noqa: F811
                    labels: Sequence[str] | None = None, *, pyplot: bool = False):
    """Several results in one Figure: a panel per quantity (``quantities``: states and outputs by name), a line per
    result (labels: the scenes' names and content hashes unless given)."""
    from .result import SimulationResult

    results = [SimulationResult.load(r) if isinstance(r, str | Path) else r
               for r in ([results] if isinstance(results, str | Path | SimulationResult) else results)]
    if not results:
        raise ValueError("plot_comparison needs at least one result")
    return _quantities_figure(results, quantities, labels, pyplot=pyplot)


#: :func:`quantities` under a name :func:`plot_comparison`'s keyword ``quantities`` does not hide
_quantities_figure = quantities
