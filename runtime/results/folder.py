"""A result folder, written as one unit and read back only if its files belong together.

Layout (format ``apexseal-result/2``)::

    <out>/result.json          run id, status, where and why it stopped, the list of parts (samples, sha256)
    <out>/scene.toml           the scene that ran, every value explicit, run id in its first line (re-runnable)
    <out>/pressure.csv         its pressure table (Pa), when the scene has one (its sha256 in result.json's ``tables``)
    <out>/parts/part-00000.npz one per revolution (the first also holds the initial sample); run id inside, the
                               integrator's state after its last sample (``z_end``: a run continues from it) and,
                               for a method that carries more from call to call, what it carried from there
                               (``carried``; the composite: the crank angle since the last contact event)
    <out>/summary.json         (CLI) the designer's numbers, with the run id
    <out>/trajectory.csv       (on request) one row per sample; first line ``# apexseal result <run id>, <n> samples``
    <out>/*.png                (CLI) the paper's figures

Writing: everything goes into the sibling folder ``<out>.partial-<run id>``; each part is written as soon as the
run loop completes it, followed by a progress record (result.json saying status ``interrupted`` and how far the
run got), so a run that is killed (SIGKILL, power loss) leaves a loadable folder that loses at most the
revolution in progress, and the one before it if the kill came while it was being written. A part is written by
a thread while the run integrates the next revolution (CasADi lets go of Python's lock while it integrates, so
the two share the machine's cores); the run loop waits for it before it hands over the next part, so a write
that failed is reported one revolution later, and no part is ever written after one that failed. At the end the
final result.json is written and :meth:`ResultFolder.commit` renames the folder into place: a previous result at
``<out>`` stays intact until then, and is replaced only if it is a result folder (so a mistyped ``--out`` never
deletes a user's files).

Reading: :mod:`.reading`.

A study's report (``apexseal optimise-preload``'s preload.json, preload.md, preload.png, scene.toml) is written by
the same rules: :class:`ReportFolder`, each report written whole beside the folder and renamed into place.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import shutil
import threading
import uuid
from pathlib import Path

import numpy as np

from ...cores import available_cores
from ...files import atomic_open, atomic_write, sha256_bytes, try_lock_folder
from .parts import join
from .reading import FORMAT, SCENE_FILE, UNFINISHED, ResultFolderError, read, read_part
from .result import SimulationResult, StopInfo

PARTS = "parts"
#: files and folders a result folder may hold (anything else makes :func:`check_replaceable` refuse)
KNOWN = {"result.json", "summary.json", "trajectory.csv", "trajectory.npz", PARTS, "scene.toml", "pressure.csv"}
KNOWN_SUFFIXES = (".png", ".svg", ".pdf")
#: parts of a run kept in memory up to this many bytes (about 130 revolutions of the default scene, 2.02 MB each), so that
#: :meth:`ResultFolder.finish` joins them instead of reading the folder back; a longer run is read back
KEEP_BYTES = 256 * 2**20


#: environment variable: ``0`` writes each part in the run's own thread, as on a machine with one core (what the
#: writer thread costs and gives is measured this way: runtime/bench/e2e.py)
WRITE_BEHIND = "APEXSEAL_WRITE_BEHIND"


def write_behind() -> bool:
    """Whether a run's parts are written by a thread beside it: where the process may run on a second core, unless
    ``APEXSEAL_WRITE_BEHIND=0``."""
    return os.environ.get(WRITE_BEHIND, "1").strip() != "0" and available_cores() > 1


class ResultStorageError(OSError):
    """Writing a result failed (disk full, permissions): the message names the folder and what was kept."""

    def __str__(self) -> str:  # the message says the cause in words: no "[Errno 28]" before it (nor twice)
        return self.strerror if self.strerror else super().__str__()


def check_replaceable(target: Path, known: set[str] | frozenset[str] = frozenset(KNOWN),
                      what: str = "an apexseal result") -> None:
    """Refuse to write a result (or ``what``: a study's report, whose files are ``known``) where it would replace
    something that is not one."""
    target = Path(target)
    if not target.exists():
        return
    if not target.is_dir():
        raise ResultFolderError(f"{target} exists and is not a folder: choose another output folder")
    foreign = sorted(p.name for p in target.iterdir()
                     if p.name not in known and p.suffix not in KNOWN_SUFFIXES and not _stray_temporary(p))
    if foreign:
        shown = ", ".join(foreign[:5]) + (", ..." if len(foreign) > 5 else "")
        noun = what.split(" ")[-1]
        raise ResultFolderError(f"{target} holds files that are not part of {what} ({shown}); a {noun} "
                                "replaces its folder as a whole, so choose an empty or new output folder")
    if not os.access(target, os.W_OK):  # renamed aside, it would be replaced all the same: protected by the user
        raise ResultFolderError(f"{target} is write-protected (this user may not write in it), so its "
                                f"{what.split(' ')[-1]} is not replaced: make it writable, or choose another output "
                                "folder")


def _stray_temporary(path: Path) -> bool:
    """A temporary file of :func:`~apexseal.files.atomic_open` (``.<name>.<random>.tmp``) that a killed writer (a
    figure worker stopped mid-file) left behind: part of no result, removed at the commit."""
    return path.name.startswith(".") and path.name.endswith(".tmp") and path.is_file()


def result_at(folder: Path, record: str = "result.json") -> tuple[str | None, str | None]:
    """The run id and status of the result in ``folder`` (or of the report whose JSON record is ``record``), or
    (None, None) where there is none."""
    try:
        data = json.loads((Path(folder) / record).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None, None
    return (data.get("run_id"), data.get("status")) if isinstance(data, dict) else (None, None)


def not_into_a_result(folder: Path, what: str) -> None:
    """Refuse to write ``what`` (a comparison's files, a sweep's) into ``folder`` where it holds a simulation's
    result: they mixed with it, and ``--resume`` then refused the folder for files that are not a result's."""
    if (Path(folder) / "result.json").is_file():
        raise ResultFolderError(f"{folder} holds a simulation's result (result.json): {what} would mix with it; "
                                "allowed: a new or empty folder, or one of your own files")


def kept_aside(target: Path, record: str, found: str | None, run_id: str, status: str, what: str) -> str:
    """Why run ``run_id``, which ended with ``status``, must not replace the folder at ``target`` ("" when it may):
    another run wrote ``target`` while this one ran (``found``: the run id there when this one began), or this
    run did not complete and ``target`` holds a completed ``what`` of another run (``record``: the JSON file with
    its run id and status). A continuation (the same run id) replaces its own."""
    there, their_status = result_at(target, record)
    if there in (None, run_id):
        return ""
    if there != found:
        return f"another run ({there[:12]}) wrote {target} while this one ran"
    if their_status == "completed" and status != "completed":
        return f"this run ended {status}, so the completed {what} at {target} was kept"
    return ""


def move_into_place(source: Path, target: Path, known: set[str] | frozenset[str] = frozenset(KNOWN),
                    what: str = "an apexseal result") -> None:
    """Rename the folder ``source`` to ``target``. A folder at ``target`` (checked to be ``what``: only ``known``
    files) is first renamed aside, beside it, and removed once ``source`` is in place (put back if that rename
    fails): a reader of ``target`` sees the old folder or the new one, never a mixture; a process killed between
    the two renames leaves the old one as ``.<target>.old-<random>``."""
    if not target.exists():
        os.rename(source, target)
        return
    check_replaceable(target, known, what)
    old = target.parent / f".{target.name}.old-{uuid.uuid4().hex[:12]}"
    os.rename(target, old)
    try:
        os.rename(source, target)
    except OSError:
        os.rename(old, target)
        raise
    shutil.rmtree(old, ignore_errors=True)


class KeptAsideWarning(UserWarning):
    """A result that was not moved into place, so as not to replace another run's (see ResultFolder.commit)."""


def _write_bytes(path: Path, data: bytes) -> None:
    """Write through a temporary file, flushed to the disk, and rename (a half-written file never carries the final
    name): :func:`apexseal.files.atomic_write`."""
    atomic_write(path, data, durable=True)


def _json_bytes(data) -> bytes:
    return (json.dumps(data, indent=2, default=_jsonable) + "\n").encode()


def _finite(v):
    """``v`` with every float that is not finite (NaN, inf) replaced by None, in dicts and lists."""
    if isinstance(v, dict):
        return {k: _finite(x) for k, x in v.items()}
    if isinstance(v, list | tuple):
        return [_finite(x) for x in v]
    if isinstance(v, float | np.floating) and not np.isfinite(v):
        return None
    return v


def _jsonable(v):
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, np.ndarray):
        return v.tolist()
    return str(v)


def part_arrays(part: SimulationResult, run_id: str, index: int, z_end: np.ndarray | None = None,
                carried: np.ndarray | None = None) -> dict[str, np.ndarray]:
    arrays = {"run_id": np.array(run_id), "part": np.array(index), "samples": np.array(part.n),
              "theta": part.theta, "time": part.time, "state": part.state, "closed": part.closed,
              "events": part.events, "modes": np.array(part.modes, dtype="U16")}
    arrays.update({f"out_{k}": v for k, v in part.outputs.items()})
    if z_end is not None:
        arrays["z_end"] = np.asarray(z_end, float)
    if carried is not None:
        arrays["carried"] = np.asarray(carried, float)
    return arrays


def figures_declined(info: dict) -> bool:
    """Whether the run whose record's ``info`` this is was asked for no figures (``--no-figures``): its
    continuation draws none either."""
    return info.get("figures") is False


class ResultFolder:
    """Writes one result folder (see the module docstring); the run loop's sink when a run streams to disk."""

    def __init__(self, target: str | Path, run_id: str | None = None, *, background: bool | None = None,
                 _reuse: bool = False) -> None:
        self.target = Path(target)
        self.background = write_behind() if background is None else background  # parts written by a thread
        check_replaceable(self.target)
        self.found = result_at(self.target)[0]  # the run whose result is at the target now (commit() checks it)
        self.kept_aside = ""
        self.run_id = run_id or uuid.uuid4().hex
        self.staging = self.target.parent / f"{self.target.name}.partial-{self.run_id[:12]}"
        try:
            (self.staging / PARTS).mkdir(parents=True, exist_ok=_reuse)
            self._lock = try_lock_folder(self.staging)  # held while this process writes the folder
        except OSError as err:
            raise ResultStorageError(err.errno, f"cannot create the result folder {self.staging}: "
                                     f"{err.strerror}") from err
        if self._lock is None:
            raise ResultFolderError(f"{self.staging} is being written by a running process: wait for it to end, "
                                    "or stop it")
        self.parts: list[dict] = []
        self.tables: dict[str, str] = {}  # files the scene reads beside scene.toml (pressure.csv) -> their sha256
        self.samples = 0
        self.guard_names: tuple[str, ...] = ()
        self.outputs: list[str] = []
        self.last: tuple[float, str] = (0.0, "")
        self.state_rows = 0
        self.info: dict = {}
        #: files the run was asked for beyond its own (trajectory.csv), recorded from the first progress record on,
        #: so that a folder killed before they were written says so (apexseal show) and --resume writes them
        self.asked: tuple[str, ...] = ()
        #: the run was asked for no figures (--no-figures): recorded, so that --resume draws none either
        self.no_figures = False
        self.final, self.status = False, ""
        self.error: ResultStorageError | None = None  # the first storage error, if any
        self.stop_written: StopInfo | None = None  # the stop it makes: at the last sample written
        self.abandoned_on_error = False  # a failed write abandons the folder (a save), rather than ending a run
        self.kept: list[SimulationResult] | None = []  # the parts written, while they fit in KEEP_BYTES
        self.kept_bytes = 0
        self._writer: threading.Thread | None = None  # the thread writing the last part handed over
        self._failure: BaseException | None = None  # its error, until sync() raises it

    @classmethod
    def continuing(cls, cont) -> ResultFolder:
        """The folder of a run that continues ``cont`` (a :class:`~.continuation.Continuation`), under the same
        run id: its whole revolutions are the first parts. A killed run's folder is continued in place (the parts
        after them removed, a progress record that lists only them written first); a result at its target is
        left as it is until :meth:`commit` replaces it, its parts linked (or copied) into the new folder."""
        folder = cls(cont.target, cont.record["run_id"], _reuse=cont.in_place)
        try:
            keep = {e["file"] for e in cont.parts}
            for name in ("scene.toml", "pressure.csv"):
                if not cont.in_place and (cont.source / name).is_file():
                    shutil.copyfile(cont.source / name, folder.staging / name)
            for entry in cont.parts:
                if not cont.in_place:
                    _link(cont.source / entry["file"], folder.staging / entry["file"])
            for path in list((folder.staging / PARTS).iterdir()):
                if f"{PARTS}/{path.name}" not in keep:
                    path.unlink()
            for path in folder.staging.iterdir():  # summary, csv, figures: of the run that stopped
                if path.name not in {PARTS, "result.json", "scene.toml", "pressure.csv"}:
                    path.unlink()
        except OSError as err:
            raise folder._storage_error(folder.staging, err, "the parts of the run to continue") from err
        record = cont.record
        folder.parts = list(cont.parts)
        folder.tables = dict(record.get("tables", {}))
        folder.samples = sum(e["samples"] for e in cont.parts)
        folder.guard_names, folder.outputs = tuple(record["guard_names"]), list(record["outputs"])
        folder.state_rows = int(record["state_rows"])
        folder.last = cont.last
        folder.info = dict(record["info"])
        folder.asked = tuple(folder.info.get("files_asked", ()))
        folder.no_figures = figures_declined(folder.info)
        # the run at the target when the run continued began, not when its continuation did: a result another run
        # wrote there since (a killed run resumed days later) is not this run's to replace; unknown in a record
        # written before it was kept, so then any other run's result at the target is kept
        folder.found = record.get("replaces")
        folder.kept = None  # the earlier parts are on disk only: finish() reads the folder back
        stop = StopInfo(cont.last[0], cont.last[1], f"continuing after {cont.revolutions} revolution(s)")
        folder._store("result.json", _json_bytes(folder._record("interrupted", stop)), "the progress record")
        return folder

    # ------------------------------------------------------------------ writing
    def begin(self, info: dict) -> None:
        """The run's record as known before its first step (method, tolerances, grid, provenance): every progress
        record carries it, so a run killed outright still says how it was run; :meth:`finish` completes it."""
        self.info = self._stamped(info)

    def _stamped(self, info: dict) -> dict:
        """``info`` with the run id and the files the run was asked for (:attr:`asked`)."""
        return (dict(info) | {"run_id": self.run_id} | ({"files_asked": list(self.asked)} if self.asked else {})
                | ({"figures": False} if self.no_figures else {}))

    def append(self, part: SimulationResult, z_end: np.ndarray | None = None,
               carried: np.ndarray | None = None) -> None:
        """Hand one part over (``z_end``: the integrator's state after its last sample, and ``carried``: what the
        integrator carries from there into its next call, if anything; both stored with it): a thread
        writes it, then the progress record that lists it, while the run goes on (without ``background``, it is
        written here). The previous part is waited for first, and its storage error (if any) is raised here; after a
        failed write nothing more is written (a result never has a gap)."""
        self.sync()
        if self.error is not None:
            raise self.error
        if not self.background:  # written here, its error raised here
            self._store_part(part, z_end, carried)
            return
        self._writer = threading.Thread(target=self._write_part, args=(part, z_end, carried),
                                        name="apexseal-result-writer")
        self._writer.start()

    def sync(self) -> None:
        """Wait until every part handed over is written; raise the error of a write that failed and was not
        reported yet (a :class:`ResultStorageError` for a storage failure)."""
        if self._writer is not None:
            self._writer.join()
            self._writer = None
        failure, self._failure = self._failure, None
        if failure is not None:
            raise failure

    def _write_part(self, part: SimulationResult, z_end: np.ndarray | None, carried: np.ndarray | None) -> None:
        """The writer thread: one part, then the progress record; any error is kept for :meth:`sync`."""
        try:
            self._store_part(part, z_end, carried)
        except BaseException as err:  # noqa: BLE001  (raised in the run's thread by sync())
            self._failure = err

    def _store_part(self, part: SimulationResult, z_end: np.ndarray | None = None,
                    carried: np.ndarray | None = None) -> None:
        index = len(self.parts)
        name = f"{PARTS}/part-{index:05d}.npz"
        buf = io.BytesIO()
        np.savez(buf, **part_arrays(part, self.run_id, index, z_end, carried))
        data = buf.getvalue()
        self._store(name, data, "a part")
        self.parts.append({"file": name, "samples": int(part.n), "sha256": sha256_bytes(data)})
        self.kept_bytes += len(data)
        if self.kept is not None:
            self.kept = self.kept + [part] if self.kept_bytes <= KEEP_BYTES else None
        self.samples += part.n
        self.guard_names, self.outputs = tuple(part.guard_names), list(part.outputs)
        self.state_rows = part.state.shape[0]
        if part.n:
            self.last = (float(part.theta[-1]), part.modes[-1])
        stop = StopInfo(self.last[0], self.last[1], f"{UNFINISHED} (killed, or the machine stopped) after "
                        f"{len(self.parts)} completed part(s); the revolution in progress was lost")
        self._store("result.json", _json_bytes(self._record("interrupted", stop)), "the progress record")

    def finish(self, status: str, stop: StopInfo | None, info: dict) -> SimulationResult:
        """Write the final result.json and return the whole result: the parts written, joined (the same arrays
        and record as reading the folder back, which is done when they did not fit in :data:`KEEP_BYTES`). The part
        still being written is waited for; its error, not reported yet, is raised (:meth:`sync`)."""
        self.sync()
        self.info = self._stamped(info)
        if self.error is not None and status == "failed":  # the samples end at the last part written, not where the
            stop = self.stop_written  # run noticed the failure (parts are written behind the integration)
        if not self.parts:
            raise ResultStorageError(self.error.errno if self.error else None,
                                     str(self.error) if self.error else f"no part of the result was written to "
                                     f"{self.staging}")
        record = self._record(status, stop)
        data = _json_bytes(record)
        self._store("result.json", data, "the final record")
        self.final, self.status = True, status
        if self.kept is None:
            return read(self.staging)
        meta = json.loads(data)  # the record as read() would see it (JSON types)
        result = join(self.kept, meta["status"], StopInfo(**meta["stop"]) if meta["stop"] else None, meta["info"])
        self.kept = None
        return result

    def write_json(self, name: str, data: dict) -> None:
        """Another JSON file of the result (summary.json), stamped with the run id; a number that is not finite (a
        leaked fraction of nothing inducted) is written null, as JSON has no NaN (strict parsers refused the file)."""
        self._store(name, _json_bytes(_finite({"run_id": self.run_id} | data)), name)

    def write_scene(self, scene) -> None:
        """scene.toml: the scene that ran with every value explicit (and its pressure table beside it), stamped
        with the run id, so that ``apexseal simulate <folder>/scene.toml`` re-runs this result."""
        from ..scenes.resolved import stamped_toml

        text, extra = stamped_toml(scene, f"result {self.run_id}", f"apexseal simulate {SCENE_FILE}")
        for name, content in extra.items():  # unstamped (a table's own format): result.json records its sha256
            data = content.encode()
            self._store(name, data, name)
            self.tables[name] = sha256_bytes(data)
        self._store(SCENE_FILE, text.encode(), SCENE_FILE)

    def write_csv(self) -> None:
        """trajectory.csv from the parts on disk, part by part (memory does not grow with the run)."""
        from .csv_table import write_csv

        self.sync()
        path = self.staging / "trajectory.csv"
        try:
            with atomic_open(path) as fh:
                write_csv(fh, self.run_id, self.samples, (read_part(self.staging, p, self.run_id)
                                                          for p in self.parts), self.guard_names)
        except OSError as err:
            raise self._storage_error(path, err, "trajectory.csv") from err

    def commit(self) -> Path:
        """Rename the finished folder into place (replacing a previous result there) and return its path.

        A run that did not complete never replaces a completed result of another run, and no run replaces a result
        that another run wrote at the target while it ran: that one stays at the target, and this one in its
        ``.partial-`` folder (loadable, and continued by ``--resume``), whose path is returned, with the reason in
        ``kept_aside``. A continuation (the same run id) replaces its own earlier result."""
        if not self.final:
            raise RuntimeError("commit() before finish(): the folder has no final record")
        target = self.target
        for stray in filter(_stray_temporary, self.staging.iterdir()):  # a figure worker stopped mid-file
            stray.unlink(missing_ok=True)
        self.kept_aside = kept_aside(target, "result.json", self.found, self.run_id, self.status, "result")
        if self.kept_aside:
            self.release()
            return self.staging
        try:
            move_into_place(self.staging, target)
        except OSError as err:
            raise ResultStorageError(err.errno, f"could not move the finished result {self.staging} to {target}: "
                                     f"{err.strerror}; the result is complete in {self.staging}") from err
        finally:
            self.release()
        return target

    def abandon(self) -> None:
        """Remove the unfinished folder (a save that failed: the previous result stays as it was)."""
        try:
            self.sync()
        except Exception:  # noqa: BLE001  (the folder goes anyway)
            pass
        shutil.rmtree(self.staging, ignore_errors=True)
        self.release()

    @contextlib.contextmanager
    def discarded_if_empty(self):
        """Around the run writing this folder: where it raises, the folder is removed if it holds no revolution (a
        crash before the first one, a full disk at it: a folder that only said "killed before its first
        revolution"), and released otherwise (a continuation's folder holds the revolutions it continues)."""
        try:
            yield self
        except BaseException:
            try:
                self.sync()  # a revolution handed to the writer thread is written, and counts, before deciding
            except BaseException:  # noqa: BLE001  (the run's own error is the one to report)
                pass
            if self.parts or self.final:
                self.release()
            else:
                self.abandon()
            raise

    def release(self) -> None:
        """Let go of the folder: another process may continue it from now on (``apexseal simulate --resume``).
        Done by :meth:`commit` and :meth:`abandon`; a run that raised leaves its ``.partial-`` folder released."""
        lock, self._lock = getattr(self, "_lock", None), None
        if lock is not None:
            os.close(lock)

    def __del__(self) -> None:
        self.release()

    # ------------------------------------------------------------------ helpers
    def _record(self, status: str, stop: StopInfo | None) -> dict:
        return {"format": FORMAT, "run_id": self.run_id, "status": status,
                "stop": None if stop is None else vars(stop), "samples": self.samples, "parts": self.parts,
                "state_rows": self.state_rows, "guard_names": list(self.guard_names), "outputs": self.outputs,
                "tables": self.tables, "info": self.info, "replaces": self.found}

    def _store(self, name: str, data: bytes, what: str) -> None:
        path = self.staging / name
        try:
            _write_bytes(path, data)
        except OSError as err:
            raise self._storage_error(path, err, what) from err

    def _storage_error(self, path: Path, err: OSError, what: str) -> ResultStorageError:
        kept = (f"{len(self.parts)} completed part(s), {self.samples} samples, are kept in {self.staging}"
                if self.parts else "nothing of this run was kept (no complete part was written)")
        # nothing of this run replaces the result at the target when no part is kept, or when a failed write
        # abandons the folder (a save); otherwise the commit decides, and says so
        previous = f"; the previous result in {self.target} is unchanged" if self.target.exists() and (
            not self.parts or self.abandoned_on_error) else ""
        error = ResultStorageError(err.errno, f"could not write {what} ({path.name}) to {self.staging}: "
                                   f"{err.strerror or err}; {kept}{previous}")
        if self.error is None:
            self.error = error
            # the run's stop, as result.json records it: where the samples kept end, and no path (the folder is
            # renamed into place after it is written)
            self.stop_written = StopInfo(self.last[0], self.last[1], f"could not write {what} ({path.name}): "
                                         f"{err.strerror or err}; the run ends with the {len(self.parts)} part(s) "
                                         "written before it")
        return error


def _link(src: Path, dst: Path) -> None:
    """``dst`` the same file as ``src`` (a hard link; a copy across file systems): parts are never rewritten."""
    try:
        os.link(src, dst)
    except OSError:
        shutil.copyfile(src, dst)


def save(result: SimulationResult, folder: str | Path, *, csv: bool = False) -> Path:
    """Write an in-memory result as a result folder (one part), as one unit."""
    writer = ResultFolder(folder)
    writer.abandoned_on_error = True
    try:
        if result.scene is not None:
            writer.write_scene(result.scene)
        writer.append(result)
        writer.finish(result.status, result.stop, result.info)
        if csv:
            writer.write_csv()
        return writer.commit()
    except BaseException:
        writer.abandon()
        raise


class ReportFolder:
    """A study's report folder (a few files, e.g. preload.json, preload.md, preload.png and scene.toml), written as
    one unit by the rules of a result folder, so that a report never mixes files of two stages or two studies.

    Each :meth:`write` (the report of the stages done so far: a checkpoint, or the last one) fills a new hidden
    folder beside the target, ``.<out>.writing-<run id>``, and moves it as a whole to ``<out>.partial-<run id>``
    (:func:`move_into_place`: the checkpoint it replaces goes aside, then away). A study killed outright (SIGKILL)
    therefore leaves its last complete checkpoint in ``<out>.partial-<run id>``, and at most a hidden writing folder,
    removed by the next study into ``<out>``. :meth:`commit` moves the last report to ``<out>`` by
    :meth:`ResultFolder.commit`'s rules: a report that did not complete (``status`` other than "completed": a
    signal, a stage refused) never replaces a completed one of another study, and no study replaces a report
    written at ``<out>`` while it ran; such a report stays in ``<out>.partial-<run id>`` (the reason in
    ``kept_aside``). ``<out>`` itself is only ever replaced whole, and only if it holds nothing but ``known`` files.
    The report's JSON ``record`` must carry ``run_id`` and ``status``, as result.json does.
    """

    def __init__(self, target: str | Path, record: str, known, what: str, run_id: str | None = None) -> None:
        self.target = Path(target)
        self.record, self.known, self.what = record, frozenset(known), what
        check_replaceable(self.target, self.known, self.what)
        self.found = result_at(self.target, record)[0]  # the study whose report is at the target now
        self.run_id = run_id or uuid.uuid4().hex
        self.staging = self.target.parent / f"{self.target.name}.partial-{self.run_id[:12]}"
        self.writing = self.target.parent / f".{self.target.name}.writing-{self.run_id[:12]}"
        self.kept_aside = ""
        self._sweep()

    def _sweep(self) -> None:
        """Remove the writing folders that killed studies left beside the target (one being written is locked by
        its writer and left alone)."""
        prefix = f".{self.target.name}.writing-"
        parent = self.target.parent
        for path in (parent.iterdir() if parent.is_dir() else ()):
            if not (path.name.startswith(prefix) and path.is_dir()):
                continue
            lock = try_lock_folder(path)
            if lock is not None:
                try:
                    shutil.rmtree(path, ignore_errors=True)
                finally:
                    os.close(lock)

    def write(self, fill):
        """Call ``fill(folder)`` to write the report's files into a new folder, then make that folder the report in
        ``<out>.partial-<run id>`` as a whole; return what ``fill`` returned. If ``fill`` fails (or the process is
        stopped in it), the previous report there stays as it was."""
        shutil.rmtree(self.writing, ignore_errors=True)
        self.writing.mkdir(parents=True)
        lock = try_lock_folder(self.writing)
        try:
            out = fill(self.writing)
            for stray in filter(_stray_temporary, self.writing.iterdir()):
                stray.unlink(missing_ok=True)
            move_into_place(self.writing, self.staging, self.known, self.what)
        except BaseException:
            shutil.rmtree(self.writing, ignore_errors=True)
            raise
        finally:
            if lock is not None:
                os.close(lock)
        return out

    def save(self, fill, status: str) -> Path:
        """Write a study's one report (``fill``, as :meth:`write`) and move it to ``<out>`` (:meth:`commit`); return
        where it is. A report that could not be written leaves nothing beside ``<out>``; one written but not moved
        into place stays whole in ``<out>.partial-<run id>``, as the ResultStorageError of :meth:`commit` says."""
        try:
            self.write(fill)
        except BaseException:
            self.abandon()
            raise
        return self.commit(status)

    def commit(self, status: str) -> Path:
        """Move the last report written to ``<out>`` and return where it is: ``<out>``, or ``<out>.partial-<run
        id>`` when it is kept aside (see the class docstring; the reason in ``kept_aside``)."""
        self.kept_aside = kept_aside(self.target, self.record, self.found, self.run_id, status, "report")
        if self.kept_aside:
            return self.staging
        try:
            move_into_place(self.staging, self.target, self.known, self.what)
        except OSError as err:
            raise ResultStorageError(err.errno, f"could not move the report {self.staging} to {self.target}: "
                                     f"{err.strerror}; the report is complete in {self.staging}") from err
        return self.target

    def abandon(self) -> None:
        """Remove what this study wrote beside the target (nothing to report): the folder at the target stays."""
        shutil.rmtree(self.writing, ignore_errors=True)
        shutil.rmtree(self.staging, ignore_errors=True)
