"""Where a stopped run continues from: the whole revolutions of its result folder and the integrator's state
after them.

A run interrupted (Ctrl-C, SIGTERM, a wall-time budget), stopped by a failure, killed outright (its
``<out>.partial-<run id>`` folder), or completed and asked for more revolutions, continues with
``apexseal simulate --resume <folder>`` (:func:`apexseal.runtime.api.resume`). Each part of a result folder stores
the integrator's state after its last sample (``z_end``) and, for a method that carries more than the state from
one call into the next (the composite: the crank angle since the last contact event, which decides when its quiet
phase starts), what it carried from there (``carried``, ``Engine.carried`` in runtime/solving/methods.py). Every
integrator call starts from such a state and what it carries, so continuing after the last whole revolution makes
the calls the uninterrupted run makes: the continued result equals it to the bit
(tests/runtime/test_continuation.py). A revolution in progress when the run stopped is computed again. A part
written before parts stored ``carried`` continues with nothing carried, as such a folder did then (the composite's
next call in its tight phase: close to the run never stopped, not equal to it).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .reading import (
    PARTIAL,
    SCENE_FILE,
    ResultFolderError,
    being_written,
    check_stamp,
    check_tables,
    read_part,
    read_record,
    scene_changed,
    scene_of_result,
)
from .result import SimulationResult


@dataclass
class Continuation:
    """A result folder's whole revolutions, to continue a run from."""

    source: Path  # the folder read
    target: Path  # where the continued result goes: the folder itself, or the target of a killed run's folder
    record: dict  # its result.json
    scene: object  # the scene that ran (its scene.toml)
    revolutions: int  # whole revolutions kept
    parts: list[dict]  # their entries in result.json
    z: np.ndarray  # the integrator's state after them
    carried: np.ndarray | None  # what the integrator carried from there into its next call (None: nothing)
    last: tuple[float, str]  # crank angle (from the start) and contact mode of their last sample

    @property
    def in_place(self) -> bool:
        """The source is the folder the continued run writes into (a killed run's ``.partial-`` folder)."""
        return self.source != self.target


def partial_target(folder: Path, run_id: str) -> Path | None:
    """The target of ``folder`` if it is run ``run_id``'s ``<out>.partial-<run id>`` folder (a run killed outright,
    or one kept aside so as not to replace another run's result), else None."""
    match = PARTIAL.match(Path(folder).name)
    return Path(folder).with_name(match["name"]) if match and run_id.startswith(match["run"]) else None


def continuation(folder: str | Path, read: SimulationResult | None = None) -> Continuation:
    """The revolutions of the result in ``folder`` to continue from; a :class:`ResultFolderError` says why a folder
    cannot be continued (not a result, mixed files, no scene, no whole revolution, written before parts stored
    the integrator's state). ``read``: the folder's result as :func:`.reading.read` returned it (its parts checked
    already), so that they are not read again."""
    folder = Path(folder)
    record = read_record(folder)
    run_id = record["run_id"]
    _not_being_written(folder)
    if not (folder / SCENE_FILE).is_file():
        raise ResultFolderError(f"{folder} has no {SCENE_FILE}, so the run's scene and settings are unknown: "
                                "simulate again")
    check_stamp(folder / SCENE_FILE, run_id)
    if record["parts"] and not _holds_state(folder / record["parts"][0]["file"]):
        raise ResultFolderError(f"the parts of {folder} do not hold the integrator's state (a result saved "
                                "from memory with SimulationResult.save, or written by an older apexseal): "
                                "simulate again, with out= or on the command line")
    per_revolution = int(record["info"].get("samples_per_revolution", 0))
    kept = 0
    for i, entry in enumerate(record["parts"]):  # the first part also holds the initial sample
        if per_revolution == 0 or entry["samples"] != per_revolution + (i == 0):
            break
        kept += 1
    if kept == 0:
        raise ResultFolderError(f"{folder} holds no whole revolution to continue from: simulate again")
    if read is None:
        for entry in record["parts"][:kept]:
            # checked one at a time (run id, sha256, shapes): a long run's parts need not fit in memory together
            part = read_part(folder, entry, run_id, len(record["guard_names"]), list(record["outputs"]),
                             record.get("state_rows"))
        last = (float(part.theta[-1]), part.modes[-1])
    else:
        end = sum(entry["samples"] for entry in record["parts"][:kept]) - 1
        last = (float(read.theta[end]), read.modes[end])
    with np.load(folder / record["parts"][kept - 1]["file"]) as data:
        z = np.array(data["z_end"], float)
        carried = np.array(data["carried"], float) if "carried" in data.files else None
    target = partial_target(folder, record["run_id"])
    killed = target is not None
    newer = folder.with_name(f"{folder.name}.partial-{record['run_id'][:12]}")
    if not killed and newer.exists():
        _not_being_written(newer)
        raise ResultFolderError(f"a continuation of this run was stopped outright and left {newer}: resume that "
                                "folder, which holds more of the run, or remove it")
    if read is None:  # an edited table is named as such (its scene would be blamed on scene.toml)
        check_tables(folder, record)
    # the scene read already, or loaded here (a SceneError becomes a ResultFolderError naming packages)
    scene = read.scene if read is not None and read.scene is not None else scene_of_result(folder, record["info"])
    changed = (scene_changed(folder, scene, record["info"]) if record["info"].get("scene_hash") is not None else
               f"{folder / SCENE_FILE}: result.json records no scene hash")
    if changed:
        raise ResultFolderError(f"{changed}; to run the scene as it reads now, simulate it: apexseal simulate "
                                f"{folder / SCENE_FILE} --out <new folder>")
    return Continuation(source=folder, target=target or folder, record=record,
                        scene=scene, revolutions=kept, parts=list(record["parts"][:kept]), z=z,
                        carried=carried, last=last)


def _not_being_written(folder: Path) -> None:
    """Refuse a folder a running process writes (it holds the folder's lock, runtime/results/folder.py)."""
    if being_written(folder):
        raise ResultFolderError(f"{folder} is being written by a running process: wait for it to end, or stop it")


def _holds_state(path: Path) -> bool:
    try:
        with np.load(path) as data:
            return "z_end" in data.files
    except (OSError, ValueError) as err:
        raise ResultFolderError(f"{path} is missing or unreadable ({err}): the folder is incomplete") from err
