"""Files that other processes may read while we write them: content hashes, atomic writes, locks.

Every file apexseal writes for someone else to read (a derivation in the cache, a generated C file and its
manifest, a compiled library's build record, a result, a benchmark report) goes through :func:`atomic_write`
or :func:`atomic_open`: the data is written to a uniquely named temporary file in the destination folder and
renamed over the destination with ``os.replace``, so a reader (or a run killed half-way) sees either the old
file or the new one, never a half-written one.

Permission rule (one for every file): a file gets the permissions ``open()`` would give it, ``0o666`` minus the
process's umask (``0o644`` under the usual umask 022), so that results and shared caches are readable by
others exactly as any file the user writes. ``tempfile.mkstemp`` alone would leave them ``0o600``.
"""

from __future__ import annotations

import errno
import fcntl
import hashlib
import json
import os
import tempfile
import time
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any


def path_argument(name: str, value: Any, expected: str) -> Path:
    """``value``, an argument naming a file or folder, as a Path: a TypeError naming ``name`` for anything but a str
    or Path, a ValueError for a path no file system can hold (a NUL character; ``os`` would raise "embedded null
    byte" without saying which argument)."""
    if not isinstance(value, str | Path):
        raise TypeError(f"{name} = {value!r}: expected {expected}")
    if "\0" in str(value):
        raise ValueError(f"{name} = {value!r}: a path cannot contain a NUL character; allowed: {expected}")
    return Path(value)


def sha256_bytes(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


#: digests of files computed in this process, under the files' identity and stat (see :func:`remembered`)
_DIGESTS: dict[tuple, str] = {}
#: a file modified less than this long (ns) before it is hashed is never remembered: a second change within its
#: timestamp's resolution could leave size and modification time as they were (git's "racily clean" files)
RACY_NS = 2_000_000_000


def stat_key(path: Path) -> tuple:
    """A file's path and stat (device, inode, size, modification and change times): what changes when it does."""
    st = os.stat(path)
    return (os.fspath(path), st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns)


def remembered(key: tuple, paths: list[Path], compute) -> str:
    """``compute()``, remembered for this process while none of ``paths`` changes its stat (device, inode, size,
    modification and change times): every simulation of a sweep or a notebook checks the same sources and
    artefacts against their manifest, and a file is read and hashed once instead of once per run."""
    stats = (key, *(stat_key(p) for p in paths))
    hit = _DIGESTS.get(stats)
    if hit is not None:
        return hit
    digest = compute()
    if settled(stats[1:]):
        _DIGESTS[stats] = digest
    return digest


def settled(stats) -> bool:
    """Every :func:`stat_key` of ``stats`` older than the racy window: what is computed from those files may be
    remembered by their stat."""
    now = time.time_ns()
    return all(now - s[4] > RACY_NS and now - s[5] > RACY_NS for s in stats)


def sha256_file(path: Path) -> str:
    def compute() -> str:
        h = hashlib.sha256()
        with Path(path).open("rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
        return h.hexdigest()

    return remembered(("sha256_file",), [Path(path)], compute)


def files_digest(root: Path, names: Iterable[str]) -> str:
    """The sha256 of the named files below ``root``, each as its relative name followed by its bytes, in order."""
    names = list(names)
    paths = [Path(root) / name for name in names]

    def compute() -> str:
        h = hashlib.sha256()
        for name, path in zip(names, paths, strict=True):
            h.update(name.encode())
            h.update(path.read_bytes())
        return h.hexdigest()

    return remembered(("files_digest", *names), paths, compute)


def read_json_object(path: Path) -> dict | None:
    """The JSON object in ``path``, or None if the file is missing, unreadable or holds anything else: how every
    cache of apexseal's reads what a process before it kept (a broken entry is rebuilt, never an error)."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def content_key(payload: Any) -> str:
    """The sha256 of a JSON-able record (keys sorted): the one way apexseal names cached content."""
    return sha256_bytes(json.dumps(payload, sort_keys=True).encode())


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


#: errors of the file system rather than of the data: a full disk or quota, a read-only or failing device
DISK_ERRNOS = (errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EIO)


class CacheError(OSError):
    """Something must be written to the cache folder (``$APEXSEAL_CACHE``) and cannot be: one line naming the
    folder, the path and the cause, and what to do (:func:`cache_error`); ``errno`` is the cause's."""


def cache_error(err: OSError, root: Path) -> CacheError:
    """``err``, an error of writing below the cache folder ``root``, as the :class:`CacheError` a user reads."""
    root = Path(root)
    path = err.filename if err.filename is not None else root
    cause = err.strerror or str(err)
    advice = "set APEXSEAL_CACHE to a folder you can write"
    if err.errno in (errno.EACCES, errno.EPERM, errno.EROFS):
        head = f"the cache folder {root} is not writable"
    elif err.errno in (errno.ENOSPC, errno.EDQUOT):
        head = f"the disk of the cache folder {root} is full"
        advice = "free some space there or set APEXSEAL_CACHE to a folder on another disk"
    elif err.errno in (errno.ENOTDIR, errno.EEXIST):
        blocker = next((p for p in (Path(path), *Path(path).parents) if p.exists() and not p.is_dir()), None)
        head, cause = f"the cache folder {root} is not a folder", f"{blocker or path} is a file"
        path = None
    else:
        head = f"cannot write to the cache folder {root}"
    where = f"{path}: {cause}" if path is not None else cause
    out = CacheError(f"{head} ({where}); {advice}")
    out.errno = err.errno
    return out


class TemporaryFolderError(OSError):
    """The temporary folder (``TMPDIR``) cannot take what a compiler writes there (a full disk or quota, a
    read-only device): one line naming the folder, the compiler's line and what to do (:func:`temporary_folder_error`).
    Not a :class:`CacheError`: the cache folder may have room to spare."""


def temporary_folder_error(code: int, folder: Path, said: str) -> TemporaryFolderError:
    """The :class:`TemporaryFolderError` of the OS error ``code`` in the temporary ``folder``, quoting ``said``."""
    head = (f"the disk of the temporary folder {folder} is full" if code in (errno.ENOSPC, errno.EDQUOT)
            else f"the temporary folder {folder} is not writable")
    out = TemporaryFolderError(f"{head} ({os.strerror(code)}; the compiler said: {said}); free some space there "
                               "or set TMPDIR to a folder on another disk")
    out.errno = code
    return out


def inside(path, root: Path) -> bool:
    """``path`` is ``root`` or below it."""
    try:
        return os.path.commonpath([os.path.abspath(path), os.path.abspath(root)]) == os.path.abspath(root)
    except ValueError:  # another drive
        return False


@contextmanager
def writing_cache(root: Path) -> Iterator[None]:
    """Inside the block, an ``OSError`` of a path below the cache folder ``root`` (or of no path: a write to an
    open file) is raised as the :class:`CacheError` of :func:`cache_error`, never as a traceback of an OS error
    naming a temporary file or nothing."""
    try:
        yield
    except (CacheError, TemporaryFolderError):
        raise
    except OSError as err:
        if err.filename is not None and not inside(err.filename, root):
            raise
        raise cache_error(err, root) from err


@contextmanager
def atomic_open(path: Path, mode: str = "w", *, durable: bool = False) -> Iterator[IO]:
    """Open a temporary file beside ``path`` for writing (``mode`` "w" or "wb"); it replaces ``path`` on success.

    On an exception the temporary file is removed and ``path`` is left as it was. ``durable=True`` also flushes
    the data to the disk (``fsync``) before the rename, for files that must survive a power loss (a result's
    parts and records).
    """
    if mode not in ("w", "wb"):
        raise ValueError(f"atomic_open: mode must be 'w' or 'wb', not {mode!r}")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        text = {"encoding": "utf-8", "newline": ""} if mode == "w" else {}
        with os.fdopen(fd, mode, **text) as fh:
            yield fh
            if durable:
                fh.flush()
                os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except OSError as err:
        Path(tmp).unlink(missing_ok=True)
        if err.filename is None and err.errno is not None:  # a write to the open file (a full disk): name the file
            raise OSError(err.errno, err.strerror, os.fspath(path)) from err
        raise
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def atomic_write(path: Path, data: bytes | str, *, durable: bool = False) -> None:
    """Write ``data`` to ``path`` atomically (see :func:`atomic_open`)."""
    with atomic_open(path, "w" if isinstance(data, str) else "wb", durable=durable) as fh:
        fh.write(data)


def try_lock_folder(path: Path) -> int | None:
    """An exclusive ``flock`` on the folder ``path``, held until the returned descriptor is closed or the process
    ends, however it ends (a killed process holds none); None while another holder has it."""
    fd = os.open(path, os.O_RDONLY | os.O_DIRECTORY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(fd)
        return None
    except OSError:  # a file system without locks: the folder goes unlocked, as before locks were taken
        pass
    return fd


def _lock_file(path: Path) -> IO:
    """``path`` opened for a lock: created if needed; an existing one that cannot be written (a read-only or shared
    cache) is opened for reading, which ``flock`` needs no more than."""
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        return path.open("a+b")
    except OSError as err:
        if err.errno not in (errno.EACCES, errno.EPERM, errno.EROFS) or not path.is_file():
            raise
        return path.open("rb")


@contextmanager
def file_lock(path: Path, what: str | None = None) -> Iterator[None]:
    """An exclusive ``fcntl`` lock on ``path`` (created if needed), held for the ``with`` block. When another
    process holds it, one progress line says so before waiting: "waiting for another apexseal process building
    ``what`` in <the lock's folder> ..." (``what``: the lock file's name if not given)."""
    path = Path(path)
    with _lock_file(path) as fh:
        try:
            fcntl.flock(fh.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            from .progress import announce

            announce(f"waiting for another apexseal process building {what or path.name} in {path.parent} ...")
            fcntl.flock(fh.fileno(), fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh.fileno(), fcntl.LOCK_UN)
