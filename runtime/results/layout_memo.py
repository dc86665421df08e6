"""Constrained layouts remembered between runs: a saved figure laid out as an identical earlier one was.

matplotlib's constrained layout measures every tick label, axis label and title of every axes in two passes
before it draws: a fifth to a third of the time of each of a run's figures (docs/performance.md). The layout it
finds (each axes' position, the suptitle's) is a function of what the figure holds before it is drawn: its size,
grid and axes, their limits and scales, and every text with its content, font and position. So
:func:`savefig` computes a :func:`signature` of that state and looks it up in ``$APEXSEAL_CACHE/layouts/``:

* found: the positions are put back and the figure is saved without its layout engine (the same PNG bytes as a
  laid-out one; tests/runtime/test_layout_memo.py checks every figure of a run, the gas figures included);
* not found: the figure is saved with its layout, and the positions the layout found are kept under the signature.

The signature also holds matplotlib's version, its rcParams and the digest of the modules that draw the figures,
so an upgrade, a style or a change to the figures' code starts afresh. Lines, patches and images take no part:
matplotlib leaves artists clipped to their axes out of the layout, and the figures clip every one of them.
Re-running a scene (or one that differs only where the figures show no text) reuses its layouts; a run whose
ranges change a tick label lays the figure out again. ``APEXSEAL_LAYOUT_MEMO=0`` turns the memo off. A memo
that cannot be read or written is ignored, like the compile cache: the figure is laid out as without it.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from apexseal.files import atomic_write, files_digest, read_json_object

#: the format of the kept layouts (a change to the signature or to what is kept starts new files)
FORMAT = 1
#: at most this many layouts are kept; the oldest go first
LIMIT = 512
#: the modules whose code decides what a figure holds
DRAWING_MODULES = ("figures.py", "gas.py", "plots.py", "decimate.py", "layout_memo.py")


def enabled() -> bool:
    """False when ``APEXSEAL_LAYOUT_MEMO=0``."""
    return os.environ.get("APEXSEAL_LAYOUT_MEMO", "1") != "0"


def _folder() -> Path:
    from apexseal.derive.cache import cache_dir

    return cache_dir() / "layouts"


def _static() -> list:
    """What every signature holds: the format, matplotlib's version and rcParams, the drawing modules' digest."""
    import matplotlib

    here = Path(__file__).resolve().parent
    # read as a dict: matplotlib's own lookup of "backend" would import pyplot and resolve the user's backend (and
    # the backend, which saving a PNG does not use, would stand as an object whose repr changes with the process)
    rc = hashlib.sha256(repr(sorted((k, repr(v)) for k, v in dict.items(matplotlib.rcParams)
                                    if k != "backend")).encode()).hexdigest()
    return [FORMAT, matplotlib.__version__, rc, files_digest(here, DRAWING_MODULES)]


def _text(t) -> list:
    """A text's content, font and placement as matplotlib has them before the layout."""
    fp = t.get_fontproperties()
    xy = getattr(t, "xy", None)  # an annotation's point (its text sits at an offset from it)
    return [t.get_text(), t.get_visible(), t.get_in_layout(), [float(v) for v in t.get_position()],
            None if xy is None else [float(v) for v in xy],
            fp.get_family(), fp.get_size_in_points(), fp.get_weight(), fp.get_style(), fp.get_stretch(),
            t.get_rotation(), t.get_horizontalalignment(), t.get_verticalalignment(), t.get_rotation_mode()]


def _axis(axis) -> list:
    """An axis's scale, its label, its offset text and the labels of its ticks inside the limits."""
    ticks = [*axis.get_majorticklabels(), *axis.get_minorticklabels()]  # these update the ticks, as a draw would
    return [axis.get_scale(), _text(axis.label), _text(axis.get_offset_text()), [_text(t) for t in ticks],
            axis.get_visible()]


def _axes(ax) -> list:
    """An axes' kind, place in its grid before the layout, limits, axes and (polar) origin and label ray."""
    spec = ax.get_subplotspec()
    grid = None if spec is None else [list(spec.get_geometry()), repr(spec.get_gridspec().get_height_ratios()),
                                      repr(spec.get_gridspec().get_width_ratios())]
    polar = ([float(ax.get_rorigin()), float(ax.get_theta_offset()), float(ax.get_theta_direction()),
              float(ax.get_rlabel_position())] if ax.name == "polar" else None)
    return [ax.name, grid, ax.get_position(original=True).get_points().tolist(), ax.viewLim.get_points().tolist(),
            ax.axison, ax.get_visible(), polar, *(_axis(a) for a in (ax.xaxis, ax.yaxis))]


def signature(fig, dpi: float) -> str:
    """The sha256 of what ``fig``'s constrained layout depends on, saved at ``dpi``."""
    from matplotlib.text import Text

    axes = [_axes(ax) for ax in fig.axes]  # first: it updates the ticks, whose texts are left out below
    owned = {id(t) for ax in fig.axes for axis in (ax.xaxis, ax.yaxis)
             for t in (axis.label, axis.get_offset_text(),
                       *(t for tick in (*axis.majorTicks, *axis.minorTicks) for t in (tick.label1, tick.label2)))}
    texts = [_text(t) for t in fig.findobj(Text) if id(t) not in owned]
    engine = fig.get_layout_engine()
    state = [_static(), float(dpi), fig.get_size_inches().tolist(), float(fig.dpi),
             None if engine is None else [type(engine).__name__, repr(sorted(engine.get().items()))], axes, texts]
    return hashlib.sha256(json.dumps(state, default=repr).encode()).hexdigest()


def positions(fig) -> dict:
    """Where the layout put ``fig``'s axes (original and active boxes) and suptitle."""
    sup = fig._suptitle
    return {"axes": [[ax.get_position(original=True).get_points().tolist(),
                      ax.get_position(original=False).get_points().tolist()] for ax in fig.axes],
            "suptitle": None if sup is None else [[float(v) for v in sup.get_position()], sup.get_verticalalignment()]}


def apply(fig, kept: dict) -> bool:
    """Put ``kept`` positions back into ``fig`` and switch its layout engine off; False (``fig`` untouched) if they
    do not fit it."""
    from matplotlib.transforms import Bbox

    boxes, sup = kept.get("axes"), kept.get("suptitle")
    if not isinstance(boxes, list) or len(boxes) != len(fig.axes) or (sup is None) != (fig._suptitle is None):
        return False
    fig.set_layout_engine(None)  # no engine at all: savefig draws once (with any engine it draws twice)
    if fig.get_layout_engine() is not None:  # the rcParams give figures a layout by default
        fig.set_layout_engine("none")
    for ax, (original, active) in zip(fig.axes, boxes, strict=True):
        ax._set_position(Bbox(original), which="original")
        ax._set_position(Bbox(active), which="active")
    if sup is not None:
        fig._suptitle.set_position(sup[0])
        fig._suptitle.set_verticalalignment(sup[1])
    return True


def _keep(key: str, kept: dict) -> None:
    try:
        folder = _folder()
        atomic_write(folder / f"{key}.json", json.dumps(kept))
        files = sorted(folder.glob("*.json"), key=lambda p: p.stat().st_mtime_ns)
        for old in files[:max(0, len(files) - LIMIT)]:
            old.unlink(missing_ok=True)
    except OSError:
        pass


def savefig(fig, fh, *, dpi: float, **kwargs) -> bool:
    """``fig.savefig(fh, dpi=dpi, **kwargs)``, laid out as the kept identical figure if there is one (True), else
    laid out by its engine and its layout kept (False)."""
    key = None
    if enabled() and fig.get_layout_engine() is not None:
        try:
            key = signature(fig, dpi)
        except Exception:  # a figure the signature cannot describe is laid out as usual
            key = None
    kept = None if key is None else read_json_object(_folder() / f"{key}.json")
    laid_out = kept is not None and apply(fig, kept)
    fig.savefig(fh, dpi=dpi, **kwargs)
    if key is not None and not laid_out:
        _keep(key, positions(fig))
    return laid_out
