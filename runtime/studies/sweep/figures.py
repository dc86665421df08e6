"""Figures of a sweep: each collected quantity against the varied parameters, and the feasible region.

* one varied parameter: a line plot of the quantity (points that did not complete marked with a red x);
* two or more, grid design: a heat map over the first two parameters (the mean over any others; a cell is
  feasible when every point in it is);
* two or more, sampled design: the points coloured by the quantity;
* ``feasible.png`` (when the study states constraints): each constrained quantity with the infeasible points
  hatched and the border of the feasible region drawn, and the region itself.

Parameters are shown in the unit the study file wrote them in (``"3 mm"`` gives mm axes).
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pandas as pd

from ...results.figures import new_figure, save_png
from ...results.quantities import quantity_help
from ...scenes.units import registry


def _scale(p) -> tuple[float, str]:
    """Factor from the parameter's SI unit to its display unit, and the display unit."""
    if not p.numeric or not p.display_unit or p.unit in ("", "1"):
        return 1.0, "" if p.unit in ("", "1") else p.unit
    ureg = registry()
    return float(ureg.Quantity(1.0, p.unit).to(p.display_unit).magnitude), p.display_unit


def _label(name: str, unit: str) -> str:
    return name if unit in ("", "1") else f"{name} ({unit})"


def _axis(ax, p, which: str) -> None:
    f, u = _scale(p)
    getattr(ax, f"set_{which}label")(_label(p.key, u))
    if p.scale == "log":
        from matplotlib.ticker import NullFormatter

        getattr(ax, f"set_{which}scale")("log")
        getattr(ax, f"{which}axis").set_minor_formatter(NullFormatter())


def _grid(study, table: pd.DataFrame, column: str, agg: str = "mean") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """x values, y values and the (ny, nx) grid of ``column`` over the first two parameters."""
    p1, p2 = study.parameters[:2]
    piv = table.pivot_table(index=p2.key, columns=p1.key, values=column, aggfunc=agg, dropna=False)
    piv = piv.reindex(index=sorted(set(p2.values)), columns=sorted(set(p1.values)))
    return (np.asarray(piv.columns, float) * _scale(p1)[0], np.asarray(piv.index, float) * _scale(p2)[0],
            piv.to_numpy(float))


def _feasible_cells(study, table: pd.DataFrame, feasible: np.ndarray) -> np.ndarray:
    """The (ny, nx) cells of the heat map over the first two parameters that are feasible: every point in them (at
    each value of the other parameters) feasible; a cell without a point is not."""
    _, _, m = _grid(study, table.assign(_feasible=feasible.astype(float)), "_feasible", agg="min")
    return np.nan_to_num(m) >= 0.5


def _edges(centres: np.ndarray, log: bool) -> np.ndarray:
    """Cell edges around grid values: midpoints (geometric on a log axis), the outer cells mirrored; on a linear
    axis of values of one sign the outer edges stop at zero (speeds of 0.01, 1500 and 3000 rpm had their first cell
    reach -750 rpm, a negative speed)."""
    c = np.log(centres) if log else np.asarray(centres, float)
    if c.size == 1:
        e = np.array([c[0] - 0.5, c[0] + 0.5])
    else:
        mid = (c[1:] + c[:-1]) / 2
        e = np.r_[2 * c[0] - mid[0], mid, 2 * c[-1] - mid[-1]]
    if log:
        return np.exp(e)
    if c.min() >= 0:
        e[0] = max(e[0], 0.0)
    if c.max() <= 0:
        e[-1] = min(e[-1], 0.0)
    return e


def _not_completed(ax, study, table: pd.DataFrame, ok: pd.Series) -> None:
    """Mark the points without a value (their cells left blank) and say why in the legend, by status
    (``invalid``: refused at their start; the others: their runs did not complete)."""
    p1, p2 = study.parameters[:2]
    bad = table[~ok.to_numpy()]
    for status, rows in bad.groupby("status", sort=True):
        ax.scatter(rows[p1.key] * _scale(p1)[0], rows[p2.key] * _scale(p2)[0], marker="x", c="tab:red", s=24,
                   label=f"{status} ({len(rows)}): no value")
    if len(bad):
        ax.legend(fontsize=8)


def _region(ax, xe: np.ndarray, ye: np.ndarray, ok: np.ndarray) -> None:
    """Hatch the infeasible cells and draw the border between feasible and infeasible cells."""
    from matplotlib.patches import Rectangle

    ny, nx = ok.shape
    for j in range(ny):
        for i in range(nx):
            if not ok[j, i]:
                # darkened and hatched in white: readable on the colour map's light and dark ends alike
                ax.add_patch(Rectangle((xe[i], ye[j]), xe[i + 1] - xe[i], ye[j + 1] - ye[j], facecolor=(0, 0, 0, 0.3),
                                       edgecolor="white", hatch="//", lw=0))
    pad = np.pad(ok, 1, constant_values=False)
    for j in range(ny + 1):  # horizontal borders: between rows j-1 and j
        for i in range(nx):
            if pad[j, i + 1] != pad[j + 1, i + 1]:
                ax.plot([xe[i], xe[i + 1]], [ye[j], ye[j]], color="white", lw=2.5)
    for i in range(nx + 1):
        for j in range(ny):
            if pad[j + 1, i] != pad[j + 1, i + 1]:
                ax.plot([xe[i], xe[i]], [ye[j], ye[j + 1]], color="white", lw=2.5)


def _numeric(study) -> bool:
    return all(p.numeric and p.unit != "" for p in study.parameters[:2])


def quantity_figure(study, table: pd.DataFrame, column: str, path: Path, *, ax=None, feasible=None) -> Path | None:
    """One quantity against the first one or two varied parameters (heat map, scatter or line)."""
    own = ax is None
    if own:
        fig = new_figure((6.4, 4.8))
        ax = fig.add_subplot()
    unit = study.units().get(column, "")
    ok = table["status"] == "completed"
    title = quantity_help().get(column, (unit, column))[1]
    if len(study.parameters) == 1 or not _numeric(study):
        p = study.parameters[0]
        f, _ = _scale(p)
        x = table[p.key].to_numpy(float) * f if p.numeric else np.arange(len(table))
        order = np.argsort(x)
        y = table[column].to_numpy(float)
        ax.plot(x[order][ok.to_numpy()[order]], y[order][ok.to_numpy()[order]], "o-", ms=3)
        bad = ~ok.to_numpy()
        if bad.any():
            ax.plot(x[bad], np.full(bad.sum(), np.nanmin(y) if np.isfinite(y).any() else 0.0), "rx",
                    label="not completed")
            ax.legend(fontsize=8)
        if feasible is not None and feasible.any():
            ax.fill_between(x[order], 0, 1, where=feasible[order], transform=ax.get_xaxis_transform(),
                            color="tab:green", alpha=0.15, label="feasible")
        _axis(ax, p, "x")
        ax.set_ylabel(_label(column, unit))
    elif study.design == "grid":
        p1, p2 = study.parameters[:2]
        values = table[column].where(ok)
        x, y, z = _grid(study, table.assign(**{column: values}), column)
        xe, ye = _edges(x, p1.scale == "log"), _edges(y, p2.scale == "log")
        mesh = ax.pcolormesh(xe, ye, z, cmap="viridis")
        ax.figure.colorbar(mesh, ax=ax, label=_label(column, unit))
        if feasible is not None:
            _region(ax, xe, ye, _feasible_cells(study, table, feasible))
        _not_completed(ax, study, table, ok)
        _axis(ax, p1, "x")
        _axis(ax, p2, "y")
    else:
        p1, p2 = study.parameters[:2]
        sc = ax.scatter(table[p1.key] * _scale(p1)[0], table[p2.key] * _scale(p2)[0], c=table[column].where(ok),
                        cmap="viridis", s=18)
        ax.figure.colorbar(sc, ax=ax, label=_label(column, unit))
        if feasible is not None:
            ax.scatter(table[p1.key][~feasible] * _scale(p1)[0], table[p2.key][~feasible] * _scale(p2)[0],
                       marker="x", c="k", s=14, label="infeasible")
            ax.legend(fontsize=8)
        _axis(ax, p1, "x")
        _axis(ax, p2, "y")
    if len(study.parameters) > 2 and study.design == "grid":
        others = ", ".join(p.key for p in study.parameters[2:])
        title += f" (mean over {others}" + ("; unhatched: feasible at every value of it)" if feasible is not None
                                              else ")")
    ax.set_title(textwrap.fill(title, 64), fontsize=9)  # a long meaning wraps instead of running off the panel
    if own:
        save_png(fig, path, 120)
        return path
    return None


def feasible_figure(study, table: pd.DataFrame, path: Path) -> Path | None:
    """The constrained quantities side by side, the infeasible points hatched, the region's border drawn."""
    if not study.constraints or table.empty:
        return None
    feasible = study.feasible(table)
    columns = [c.column for c in study.constraints if c.column in study.quantities]
    fig = new_figure((6.0 * max(1, len(columns)), 4.8))
    axes = fig.subplots(1, max(1, len(columns)), squeeze=False)
    for ax, col in zip(axes[0], columns, strict=False):
        quantity_figure(study, table, col, path, ax=ax, feasible=feasible)
    rule = "; ".join(c.describe() for c in study.constraints)
    fig.suptitle(textwrap.fill(f"{study.name}: feasible region (unhatched, white border) where {rule} "
                               f"- {feasible_count(study, table, feasible)}", 64 * len(axes[0])), fontsize=10)
    save_png(fig, path, 120)
    return path


def feasible_count(study, table: pd.DataFrame, feasible: np.ndarray) -> str:
    """How many points are feasible, and on the heat map of a grid of three parameters or more, whose cells each
    hold the points of every value of the others, how many cells are feasible at every one of them (those left
    unhatched): "5 of 8 points; 1 of 4 cells feasible at every value of friction.mu1"."""
    count = f"{int(feasible.sum())} of {len(table)} points"
    if len(study.parameters) > 2 and study.design == "grid" and _numeric(study):
        cells = _feasible_cells(study, table, feasible)
        count += (f"; {int(cells.sum())} of {cells.size} cells feasible at every value of "
                  + ", ".join(p.key for p in study.parameters[2:]))
    return count


def sweep_figures(study, table: pd.DataFrame, folder: str | Path) -> list[Path]:
    """Write ``<quantity>.png`` for every collected quantity and ``feasible.png``; returns the paths."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    if table.empty:
        return []
    paths = [quantity_figure(study, table, q, folder / f"{q}.png") for q in study.quantities]
    paths.append(feasible_figure(study, table, folder / "feasible.png"))
    return [p for p in paths if p is not None]
