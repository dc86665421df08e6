"""The figure files a run writes: which (:data:`FILES`, and :data:`GAS_FILES` with the chamber gas model), what
they read of the result (:func:`figure_view`, what a figure process is handed), and one figure drawn and saved
(:func:`write_figure`). Drawing them all, in a second process beside the writing of the result:
:func:`.figure_job.write_figures`."""

from __future__ import annotations

from pathlib import Path

from ...files import atomic_open
from . import layout_memo
from .figures import Frame
from .gas import has_gas
from .plots import figure
from .result import SimulationResult

#: the figures a run writes: file name -> drawing function
FILES = {"fig12_displacements.png": "fig12", "fig13_forces.png": "fig13", "fig14_housing_spectrum.png": "fig14",
         "mode_timeline.png": "modes"}
#: the figures a run with the chamber gas model writes besides
GAS_FILES = {"fig11_pressures.png": "fig11", "pv_diagram.png": "pv"}


def figure_files(result: SimulationResult) -> dict[str, str]:
    """The figures a run writes, file name -> figure name: :data:`FILES` (Fig. 14, the housing force's spectrum,
    only with the housing contact), and :data:`GAS_FILES` with the chamber gas model."""
    files = {n: k for n, k in FILES.items() if k != "fig14" or "F_housing_X" in result.outputs}
    return files | (GAS_FILES if has_gas(result) and result.n > 2 else {})


def figure_outputs(result: SimulationResult) -> list[str]:
    """The outputs the figures of :func:`figure_files` read: the forces (Fig. 13's panels, Fig. 14's housing
    force) and, with the chamber gas model, the chambers' volumes and pressures (Fig. 11, the p-V diagram)."""
    gas = {"Va", "Vb", "Pa", "Pb"} if has_gas(result) else set()
    return [k for k in result.outputs if k.startswith("F_") or k in gas]


def figure_view(result: SimulationResult) -> SimulationResult:
    """``result`` with only what its figures read (its states, switches and modes, :func:`figure_outputs`), and
    without its scene: what a figure process is handed (:mod:`.figure_worker`; 14 of the default run's 37
    outputs). Its figures are the full result's, byte for byte (tests/runtime/test_figure_worker.py)."""
    import dataclasses

    return dataclasses.replace(result, scene=None, outputs={k: result.outputs[k] for k in figure_outputs(result)})


#: zlib's level for the PNG files: 3 writes them in two thirds of the time of Pillow's default 6 (on the critical
#: path of the figure processes: docs/performance.md), from 5 % smaller to 27 % larger
PNG_COMPRESS_LEVEL = 3


def write_figure(result: SimulationResult, folder: Path, name: str, kind: str, ports: dict | None = None,
                 dpi: int = 100, frame: Frame | None = None) -> Path:
    """Draw one figure (long lines as their envelope at ``dpi``; in ``frame`` if it was built for it) and save it
    as the PNG file ``folder/name``, laid out as an identical figure saved before if there was one
    (:mod:`.layout_memo`)."""
    fig = figure(result, kind, ports=ports, save_dpi=dpi, frame=frame)
    with atomic_open(folder / name, "wb") as fh:  # a half-written PNG never carries the final name
        layout_memo.savefig(fig, fh, dpi=dpi, format="png", pil_kwargs={"compress_level": PNG_COMPRESS_LEVEL})
    return folder / name
