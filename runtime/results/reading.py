"""Reading a result folder back (:mod:`.folder` writes it), only if its files belong together.

result.json must be of this format; every part must carry the same run id, the recorded sample count and
sha256, and shapes that agree; summary.json and trajectory.csv, if present, must name the same run, and a table
the scene reads (pressure.csv) must have the sha256 result.json records. A mixed
folder is refused with the file and the mismatch named. A folder its run still writes (it holds the folder's
lock) reads as what it had written, and says so.
"""

from __future__ import annotations

import io
import json
import os
import re
from pathlib import Path

import numpy as np

from ...files import sha256_bytes, try_lock_folder
from .parts import join
from .result import SimulationResult, StopInfo

FORMAT = "apexseal-result/2"
#: the resolved scene of a result (runtime/scenes/resolved.py)
SCENE_FILE = "scene.toml"


class ResultFolderError(ValueError):
    """A folder that is not a complete, self-consistent result (or cannot be replaced by one)."""


def _began(folder: Path) -> str:
    """The run id in the first line of ``folder``'s scene.toml, as a run writes it before its first step ("" when
    there is none)."""
    try:
        with (folder / SCENE_FILE).open(encoding="utf-8") as fh:
            first = fh.readline()
    except (OSError, UnicodeDecodeError):
        return ""
    words = first.lstrip("# ").split()
    return words[2].rstrip(",") if len(words) > 2 and words[:2] == ["apexseal", "result"] else ""


#: the start of the stop reason of the progress record a run writes after each part (its final record replaces it)
UNFINISHED = "the run ended without its final record"


def _still_written(folder: Path, stop: StopInfo | None, parts: int) -> StopInfo | None:
    """The stop of a folder read back: a progress record (:data:`UNFINISHED`) of a folder whose writer still holds
    its lock says that the run goes on, not that it was killed."""
    if stop is None or not stop.reason.startswith(UNFINISHED):
        return stop
    if not being_written(folder):
        return stop
    return StopInfo(stop.theta, stop.mode, f"the run is still going on (a running process writes {folder}): this is "
                    f"what it had written when read, {parts} completed part(s); the revolution in progress is not in "
                    "it yet")


#: the report files of the studies, which write folders of their own (not results): file -> what the folder is
STUDY_REPORTS = {"preload.md": "a preload study's report (`apexseal optimise-preload`): read preload.md, or "
                               "preload.json for its numbers",
                 "results.parquet": "a sweep's folder (`apexseal sweep`): its table is results.csv (or "
                                    "results.parquet), one row per point; `apexseal sweep STUDY --scene-of N` "
                                    "writes point N's scene to simulate it alone",
                 "calibration.json": "a calibration's report (`apexseal calibrate`): read calibration.json"}


#: the folder a run writes beside its target and a run killed outright leaves there (runtime/results/folder.py:
#: ``<out>.partial-<run id>``)
PARTIAL = re.compile(r"^(?P<name>.+)\.partial-(?P<run>[0-9a-f]{12})$")


def _what_else(folder: Path) -> str:
    """``"; it is <what>"`` for a study's folder (:data:`STUDY_REPORTS`), else ``""``."""
    what = next((w for name, w in STUDY_REPORTS.items() if (folder / name).is_file()), None)
    return f"; it is {what}" if what else ""


def being_written(folder: Path) -> bool:
    """Whether a running process holds the lock of ``folder`` (a run's, runtime/results/folder.py); False for what
    is no folder."""
    if not folder.is_dir():
        return False
    fd = try_lock_folder(folder)
    if fd is None:
        return True
    os.close(fd)
    return False


def read_record(folder: Path) -> dict:
    path = folder / "result.json"
    if not path.is_file():
        began = _began(folder)
        if began:  # scene.toml is written before the first step: a run killed before its first part
            raise ResultFolderError(f"{folder} holds no result: run {began} began here and was killed before it wrote "
                                    "its first revolution, so there is nothing to load or continue; simulate the "
                                    f"scene again ({folder / SCENE_FILE}) and delete this folder")
        if PARTIAL.match(folder.name) and folder.is_dir() and {p.name for p in folder.iterdir()} <= {"parts"} and \
                not any((folder / "parts").iterdir() if (folder / "parts").is_dir() else ()):
            raise ResultFolderError(f"{folder} holds no result: a run was killed here before it wrote anything (an "
                                    "empty parts/), so there is nothing to load or continue; delete this folder")
        partials = sorted(folder.parent.glob(f"{folder.name}.partial-*")) if folder.name else []
        running = [p for p in partials if being_written(p)]
        if running:  # a run into ``folder`` that is still going: not a killed one's
            raise ResultFolderError(
                f"{folder} {'has no result.json' if folder.exists() else 'does not exist'} yet: a running process is "
                f"writing its result in {', '.join(str(p) for p in running)} (moved to {folder} when the run ends); "
                "wait for it to end, or stop it (Ctrl-C or SIGTERM keep what it computed)")
        if partials:  # a run into ``folder`` killed outright left its revolutions beside it
            raise ResultFolderError(
                f"{folder} {'has no result.json' if folder.exists() else 'does not exist'}: a run into it was killed "
                f"and left what it computed in {', '.join(str(p) for p in partials)}: load or resume that folder "
                f"(apexseal.resume({str(partials[-1])!r}), apexseal simulate --resume {partials[-1]})")
        if not folder.exists():
            raise ResultFolderError(f"{folder} does not exist: no result.json, not a result folder")
        raise ResultFolderError(f"{folder} is not a result folder: it has no result.json{_what_else(folder)}")
    try:
        meta = json.loads(path.read_text())
    except (OSError, ValueError) as err:
        raise ResultFolderError(f"{path} is unreadable: {err}") from err
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise ResultFolderError(f"{path} is not an {FORMAT} record (a result written by an older apexseal, whose "
                                "files cannot be checked to belong together: simulate again)")
    return meta


def read_part(folder: Path, entry: dict, run_id: str, guards: int | None = None,
              outputs: list[str] | None = None, state_rows: int | None = None) -> SimulationResult:
    """One part, checked: run id, sample count, sha256, shapes."""
    path = folder / entry["file"]
    try:
        data = path.read_bytes()
    except OSError as err:
        raise ResultFolderError(f"{path} is missing or unreadable ({err.strerror}): the folder is incomplete") from err
    if sha256_bytes(data) != entry["sha256"]:
        raise ResultFolderError(f"{path} is not the file result.json recorded (sha256 differs): the folder mixes files "
                                "of different runs, or a file was changed")
    with np.load(io.BytesIO(data)) as d:
        if str(d["run_id"]) != run_id:
            raise ResultFolderError(f"{path} belongs to run {d['run_id']}, result.json to run {run_id}: mixed folder")
        arrays = {k: d[k] for k in d.files}
    n = int(arrays["samples"])
    names = outputs if outputs is not None else [k[4:] for k in arrays if k.startswith("out_")]
    g = guards if guards is not None else arrays["closed"].shape[0]
    s = state_rows if state_rows is not None else arrays["state"].shape[0]
    expect = {"theta": (n,), "time": (n,), "state": (s, n), "closed": (g, n), "events": (g, n), "modes": (n,)}
    expect |= {f"out_{k}": (n,) for k in names}
    for key, shape in expect.items():
        if key not in arrays:
            raise ResultFolderError(f"{path} has no array {key!r}: the folder is inconsistent")
        if arrays[key].shape != shape:
            raise ResultFolderError(f"{path}: {key} has shape {arrays[key].shape}, expected {shape} ({n} samples, "
                                    f"{g} guards)")
    if n != entry["samples"]:
        raise ResultFolderError(f"{path} holds {n} samples, result.json records {entry['samples']}")
    return SimulationResult(arrays["theta"], arrays["time"], arrays["state"], arrays["closed"], arrays["events"],
                            {k: arrays[f"out_{k}"] for k in names}, (), [str(m) for m in arrays["modes"]])


def read(folder: str | Path) -> SimulationResult:
    """The result in ``folder`` (a committed result, or the ``.partial-`` folder a killed run left), checked."""
    folder = Path(folder)
    meta = read_record(folder)
    run_id = meta["run_id"]
    guards = list(meta["guard_names"])
    parts = [read_part(folder, e, run_id, len(guards), list(meta["outputs"]), meta.get("state_rows"))
             for e in meta["parts"]]
    total = sum(p.n for p in parts)
    if total != meta["samples"]:
        raise ResultFolderError(f"{folder}: the parts hold {total} samples, result.json records {meta['samples']}")
    if not parts:
        raise ResultFolderError(f"{folder}: result.json lists no part (the run was killed before its first sample "
                                "was written)")
    for name in ("summary.json", "trajectory.csv", SCENE_FILE):
        check_stamp(folder / name, run_id)
    check_tables(folder, meta)
    for p in parts:
        p.guard_names = tuple(guards)
    stop = _still_written(folder, StopInfo(**meta["stop"]) if meta["stop"] else None, len(parts))
    result = join(parts, meta["status"], stop, meta["info"])
    result.info.setdefault("run_id", run_id)
    if (folder / SCENE_FILE).is_file():
        import warnings

        from apexseal.stacklevel import user_stacklevel

        try:
            result.scene = scene_of_result(folder, result.info)
        except ResultFolderError as err:  # the samples stay readable (a range narrowed since, a package missing)
            warnings.warn(f"{err}\nresult.scene is None: the samples are read without their scene",
                          SceneChangedWarning, stacklevel=user_stacklevel())
        changed = result.scene is not None and scene_changed(folder, result.scene, result.info)
        if changed:
            warnings.warn(f"{changed}: result.scene is the scene as the file reads now", SceneChangedWarning,
                          stacklevel=user_stacklevel())
    theta = result.theta
    if theta.size > 1 and not (np.diff(theta) > 0).all():
        raise ResultFolderError(f"{folder}: the parts do not follow each other (crank angle not increasing)")
    return result


def check_tables(folder: Path, record: dict) -> None:
    """The files the scene reads beside scene.toml (its pressure table), each as result.json ``record`` recorded it
    (recorded since tables were checked; older folders: not)."""
    for name, digest in record.get("tables", {}).items():
        _check_table(folder / name, digest)


def _check_table(path: Path, digest: str) -> None:
    """A file the scene reads beside scene.toml (its pressure table), as result.json recorded it: a table carries
    no run id, so another run's table, or an edited one, is told by its sha256."""
    try:
        data = path.read_bytes()
    except OSError as err:
        raise ResultFolderError(f"{path} is missing or unreadable ({err.strerror}): the folder is incomplete, and "
                                f"its {SCENE_FILE} names it") from err
    if sha256_bytes(data) != digest:
        raise ResultFolderError(f"{path} is not the file result.json recorded (sha256 differs): the folder mixes "
                                f"files of different runs, or the table was changed since the run; its "
                                f"{SCENE_FILE} would not re-run this result")


class SceneChangedWarning(UserWarning):
    """A result's scene.toml is not the scene its run computed (:func:`scene_changed`), or does not load here (a
    range narrowed since the run, a submodel's package missing: :func:`scene_of_result`), and the result is read
    without it."""


def scene_changed(folder: Path, scene, info: dict) -> str | None:
    """Why ``scene``, loaded from ``folder``'s scene.toml, is not the scene the run computed (its content hash is not
    the one result.json records), or None when it is (or the record names none)."""
    recorded = info.get("scene_hash")
    if recorded is None or scene.content_hash() == recorded:
        return None
    from apexseal.derive.submodels.registry import installed
    from apexseal.generated.manifest import input_hash

    model, now = info.get("model_hash"), input_hash(scene.effects, scene.assumptions)
    packages = ", ".join(f"{name} from {dist}" for name, dist in installed().items())
    if model and model != now:  # a key a submodel added, or a default it changed, is read at today's value
        why = (f"edited since, or the model changed since the run, model hash {model[:12]}, now {now[:12]}: the "
               "derivation, a submodel or the generator; a scene key a submodel added since, or a default it "
               "changed, counts in the scene's hash")
    else:
        why = "edited since, or written by an earlier apexseal whose hash counted the pressure table's unit?" + \
              (f" or read with other submodels installed now: {packages}" if packages else "")
    return (f"{folder / SCENE_FILE} is not the scene the run computed (its content hash differs from the one "
            f"result.json records: {why})")


def scene_of_result(folder: Path, info: dict):
    """The result's scene.toml, loaded; a ResultFolderError naming the folder when it does not load here (a submodel
    of the run's that this process lacks: its package, from the result's versions, is named)."""
    from apexseal.derive.submodels.registry import installed

    from ..scenes.errors import SceneError
    from ..scenes.scene import load_scene

    try:
        return load_scene(folder / SCENE_FILE)
    except SceneError as err:
        here = installed()
        missing = [f"{k.removeprefix('submodel ')} ({v})" for k, v in info.get("versions", {}).items()
                   if k.startswith("submodel ") and k.removeprefix("submodel ") not in here]
        hint = (f"; the run was made where submodels this process lacks were installed: {', '.join(missing)}: if "
                f"the scene names their keys, install them to read it" if missing else "")
        raise ResultFolderError(f"{folder}: its {SCENE_FILE} does not load here{hint}\n{err}") from err


def check_stamp(path: Path, run_id: str) -> None:
    if not path.exists():
        return
    try:
        if path.suffix == ".json":
            found = json.loads(path.read_text()).get("run_id")
        else:
            with open(path) as fh:
                head = fh.readline()
            found = head.split()[3].rstrip(",") if head.startswith("# apexseal result ") else None
    except (OSError, ValueError, AttributeError, IndexError) as err:  # no run of its own to name: "run None" was
        why = err.strerror if isinstance(err, OSError) and err.strerror else str(err) or type(err).__name__
        raise ResultFolderError(f"{path} is unreadable ({why}): not a file of this result (run {run_id}); simulate "
                                f"again, or remove {path.name}") from err
    if found is None:
        raise ResultFolderError(f"{path} names no run: not a file of this result (run {run_id}); mixed folder "
                                f"(simulate again, or remove {path.name})")
    if found != run_id:
        raise ResultFolderError(f"{path} belongs to run {found}, result.json to run {run_id}: mixed folder "
                                f"(simulate again, or remove {path.name})")
