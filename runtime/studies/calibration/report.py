"""The calibration's report folder: ``calibration.json`` (what identifies the study, then its fit, verdicts and every
evaluation) and ``scene.toml`` (the scene the study ran, ``--set`` keys included, every value explicit, with the
samples per revolution it ran, and its pressure table beside it), written as one unit by
:class:`~apexseal.runtime.results.folder.ReportFolder`, as the preload study's report is (docs/preload.md, "Written
as one unit"): a calibration that a signal stopped never replaces a completed one at the same folder.

From the folder, ``apexseal calibrate scene.toml`` with the options recorded runs the study again
(:func:`rerun_line`), and ``apexseal simulate scene.toml`` with the best set's keys simulates the fit
(:func:`simulate_line`).
"""

from __future__ import annotations

import json
from pathlib import Path

from ....files import atomic_write

#: the files a calibration report folder may hold (another file makes the command refuse to replace the folder)
REPORT_FILES = frozenset({"calibration.json", "scene.toml", "pressure.csv"})
#: the report's record: its run id and status ("completed", "interrupted"), as a result's result.json
RECORD = "calibration.json"
SCENE_FILE = "scene.toml"


def report_folder(out: Path, run_id: str | None = None):
    """The :class:`~apexseal.runtime.results.folder.ReportFolder` of a calibration report at ``out`` (refused, a
    ResultFolderError, where ``out`` holds other files)."""
    from ...results.folder import ReportFolder

    return ReportFolder(out, RECORD, REPORT_FILES, "a calibration report", run_id)


def _set(key: str, value) -> str:
    """``--set key=value``, the value written to be read back as the same number (a float's shortest repr)."""
    return f"--set {key}={value!r}" if isinstance(value, float) else f"--set {key}={json.dumps(value)}"


def simulate_line(cal, scene_file: str = SCENE_FILE) -> str:
    """The command that simulates the best set of ``cal`` (a :class:`~.fit.Calibration`) as the study simulated it:
    its scene file, the study's revolutions and the best set's contact keys (kg sets kg1..kg4)."""
    sets = " ".join(_set(k, v) for k, v in cal.best_overrides().items())
    return f"apexseal simulate {scene_file} -n {cal.revolutions} {sets}"


def rerun_line(cal, scene_file: str = SCENE_FILE) -> str:
    """The command that runs the study of ``cal`` again from its scene file, with the options it ran: its unknowns
    and their ranges as ``--unknown NAME=LOW:HIGH`` where they are not the default ones of its scene
    (:func:`~.fit.default_ranges`), each number as short as it reads back exactly (scenes.errors.show_repr;
    scene.toml holds the samples per revolution it ran)."""
    from ...scenes.errors import show_repr
    from .fit import default_ranges

    o = cal.options
    line = (f"apexseal calibrate {scene_file} --grid {o.get('grid')} --polish {o.get('polish')} "
            f"--revolutions {cal.revolutions}")
    ranges = {n: (float(lo), float(hi)) for n, (lo, hi) in cal.ranges.items()}
    if cal.scene is not None and ranges != default_ranges(cal.scene):
        line += "".join(f" --unknown {n}={show_repr(lo)}:{show_repr(hi)}" for n, (lo, hi) in ranges.items())
    return line


def write_report(folder: Path, cal) -> list[Path]:
    """Write calibration.json and scene.toml (with its pressure table, where the scene has one) of ``cal`` into
    ``folder``; return their paths. Each file is written atomically, the folder is not: write a report folder as
    one unit through :func:`save_report`."""
    from ..scene_file import write_study_scene

    folder = Path(folder)
    payload = cal.to_dict()
    rerun = rerun_line(cal) if cal.scene is not None else None
    if cal.scene is not None:
        payload |= {"scene_file": SCENE_FILE, "rerun": rerun, "simulate_best": simulate_line(cal)}
    path = folder / RECORD
    atomic_write(path, json.dumps(payload, indent=2) + "\n")
    paths = [path]
    if cal.scene is not None:
        paths += write_study_scene(folder, cal.scene, "calibration", cal.run_id, rerun, cal.samples_per_revolution)
    return paths


def save_report(cal, out, folder=None) -> Path:
    """Write the report of ``cal`` to the folder ``out`` as one unit (``folder``: its :func:`report_folder`, made
    before the study by the command, so that a folder of other files is refused before any work). Returns where
    the report is: ``out``, or ``<out>.partial-<run id>`` where a study that did not complete would replace a
    completed report (the reason in ``folder.kept_aside``). A report that could not be written leaves nothing
    beside ``out``; one that could not be moved into place stays whole in ``<out>.partial-<run id>`` (the
    ResultStorageError says so)."""
    folder = folder if folder is not None else report_folder(Path(out), cal.run_id)
    return folder.save(lambda into: write_report(into, cal), cal.status)
