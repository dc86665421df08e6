"""apexseal.files: one atomic write with one permission rule, and one content key."""

from __future__ import annotations

import os
import stat

import pytest

from apexseal.files import atomic_open, atomic_write, content_key, read_json_object


@pytest.fixture
def umask_027():
    old = os.umask(0o027)
    try:
        yield
    finally:
        os.umask(old)


def _mode(path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


def test_atomic_write_text_and_bytes_get_the_umask_permissions(tmp_path, umask_027):
    atomic_write(tmp_path / "a" / "t.txt", "é\n")
    atomic_write(tmp_path / "b.bin", b"\x00\x01")
    assert (tmp_path / "a" / "t.txt").read_bytes() == "é\n".encode()
    assert (tmp_path / "b.bin").read_bytes() == b"\x00\x01"
    # what open() would give under this umask (0o666 & ~0o027), not mkstemp's 0o600
    assert _mode(tmp_path / "a" / "t.txt") == 0o640
    assert _mode(tmp_path / "b.bin") == 0o640


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path):
    target = tmp_path / "result.json"
    atomic_write(target, "old\n")
    with pytest.raises(RuntimeError, match="killed"), atomic_open(target) as fh:
        fh.write("half a")
        raise RuntimeError("killed mid-write")
    assert target.read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["result.json"]


def test_atomic_open_refuses_modes_that_do_not_write_a_whole_file(tmp_path):
    with pytest.raises(ValueError, match="mode must be 'w' or 'wb', not 'a'"), atomic_open(tmp_path / "x", "a"):
        pass


def test_content_key_ignores_key_order_and_sees_values():
    assert content_key({"a": 1, "b": [1, 2]}) == content_key({"b": [1, 2], "a": 1})
    assert content_key({"a": 1}) != content_key({"a": 2})


def test_a_digest_is_remembered_only_for_a_file_unchanged_since_before_the_racy_window(tmp_path):
    """sha256_file reads a file once per process while its stat stays the same, and sees every change."""
    from apexseal import files

    path = tmp_path / "source.py"
    path.write_bytes(b"a = 1\n")
    fresh = files.sha256_file(path)
    assert not any(k[1][0] == os.fspath(path) for k in files._DIGESTS)  # written just now: racy, not remembered
    old = path.stat().st_mtime_ns - 10 * files.RACY_NS
    os.utime(path, ns=(old, old))
    assert files.sha256_file(path) == fresh
    # ctime is now recent (utime changes it): still not remembered; remembered once the file is old in both
    assert not any(k[1][0] == os.fspath(path) for k in files._DIGESTS)
    path.write_bytes(b"a = 2\n")  # same size, other bytes, then the old modification time again
    os.utime(path, ns=(old, old))
    assert files.sha256_file(path) != fresh
    assert files.files_digest(tmp_path, ["source.py"]) != files.files_digest(tmp_path, [])


def test_a_remembered_digest_serves_until_the_stat_changes(tmp_path, monkeypatch):
    """With the racy window passed, the second call does not read the file; a change of its stat reads it again."""
    from apexseal import files

    monkeypatch.setattr(files, "RACY_NS", -10**18)  # every file counts as old
    path = tmp_path / "m.json"
    path.write_bytes(b"{}")
    first = files.sha256_file(path)
    reads = []
    real_open = type(path).open
    monkeypatch.setattr(type(path), "open", lambda self, mode="r", *a, **k: (
        reads.append(self) if mode == "rb" else None) or real_open(self, mode, *a, **k))
    assert files.sha256_file(path) == first and reads == []
    path.write_bytes(b"[]")
    assert files.sha256_file(path) != first and reads == [path]


def test_read_json_object_gives_none_for_anything_but_an_object(tmp_path):
    path = tmp_path / "kept.json"
    assert read_json_object(path) is None  # missing
    for text, expected in (('{"a": 1}', {"a": 1}), ("{broken", None), ("[1, 2]", None), ("", None)):
        path.write_text(text)
        assert read_json_object(path) == expected, text


def test_a_write_that_fails_names_the_file(tmp_path):
    """A full disk made a write to an open file fail with "OSError: [Errno 28] No space left on device" naming no
    path; the error of atomic_open names the file it was writing."""
    import errno

    target = tmp_path / "record.json"
    with pytest.raises(OSError) as caught, atomic_open(target) as fh:
        fh.write("{}")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    assert caught.value.errno == errno.ENOSPC and caught.value.filename == str(target)
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("err, says", [
    (PermissionError(13, "Permission denied", "{root}/lib/k.lock"), "the cache folder {root} is not writable "
     "({root}/lib/k.lock: Permission denied); set APEXSEAL_CACHE to a folder you can write"),
    (OSError(28, "No space left on device", "{root}/lib"), "the disk of the cache folder {root} is full "
     "({root}/lib: No space left on device); free some space there or set APEXSEAL_CACHE to a folder on another disk"),
    (OSError(28, "No space left on device"), "the disk of the cache folder {root} is full"),
])
def test_a_failed_write_below_the_cache_is_one_line_naming_folder_path_and_cause(tmp_path, err, says):
    """An unwritable or full cache raised PermissionError or OSError with a traceback naming a temporary file (or
    nothing): below the cache folder it is a CacheError naming the folder, the path, the cause and APEXSEAL_CACHE."""
    from apexseal.files import CacheError, writing_cache

    root = tmp_path / "cache"
    if err.filename is not None:
        err = type(err)(err.errno, err.strerror, err.filename.format(root=root))
    with pytest.raises(CacheError) as caught, writing_cache(root):
        raise err
    assert str(caught.value).startswith(says.format(root=root)) and "\n" not in str(caught.value)
    assert caught.value.errno == err.errno and caught.value.__cause__ is err


def test_a_cache_path_that_is_a_file_is_named_so(tmp_path):
    from apexseal.files import CacheError, writing_cache

    root = tmp_path / "cache"
    root.write_text("")
    with pytest.raises(CacheError, match=f"the cache folder {root} is not a folder \\({root} is a file\\); set "
                                         "APEXSEAL_CACHE"), writing_cache(root):
        (root / "lib").mkdir(parents=True, exist_ok=True)


def test_an_error_outside_the_cache_is_left_as_it_is(tmp_path):
    from apexseal.files import writing_cache

    with pytest.raises(PermissionError) as caught, writing_cache(tmp_path / "cache"):
        raise PermissionError(13, "Permission denied", str(tmp_path / "elsewhere"))
    assert type(caught.value) is PermissionError


def test_a_lock_held_elsewhere_is_waited_for_with_one_progress_line(tmp_path, caplog):
    """A process waiting for another's build lock printed nothing (about 6 s of silence on a cold cache shared by
    two runs): one progress line says what it waits for, and where."""
    import fcntl
    import logging
    import threading
    import time

    from apexseal.files import file_lock

    lock = tmp_path / "key.lock"
    done = []
    with caplog.at_level(logging.INFO, logger="apexseal"), lock.open("a+b") as other:
        fcntl.flock(other.fileno(), fcntl.LOCK_EX)  # another open file: flock makes it wait as another process

        def waiter():
            with file_lock(lock, "libx.so"):
                done.append(True)

        thread = threading.Thread(target=waiter)
        thread.start()
        for _ in range(500):
            if caplog.messages:
                break
            time.sleep(0.01)
        assert not done  # still waiting
        fcntl.flock(other.fileno(), fcntl.LOCK_UN)
        thread.join(10)
    assert done and caplog.messages == [f"waiting for another apexseal process building libx.so in {tmp_path} ..."]
    caplog.clear()
    with caplog.at_level(logging.INFO, logger="apexseal"), file_lock(lock, "libx.so"):
        pass
    assert caplog.messages == []  # a free lock is taken silently


def test_a_lock_file_that_cannot_be_written_is_locked_for_reading(tmp_path, monkeypatch):
    """A read-only or shared cache: its lock files exist but opening them for writing fails; flock needs no more
    than reading, so the lock is taken (a warm run that finds nothing to build needs no write)."""
    import errno
    import pathlib

    from apexseal.files import file_lock

    lock = tmp_path / "key.lock"
    lock.write_bytes(b"")
    real_open = pathlib.Path.open

    def read_only(self, mode="r", *args, **kwargs):
        if "+" in mode or "a" in mode or "w" in mode:
            raise PermissionError(errno.EACCES, "Permission denied", str(self))
        return real_open(self, mode, *args, **kwargs)

    monkeypatch.setattr(pathlib.Path, "open", read_only)
    with file_lock(lock):
        pass
    with pytest.raises(PermissionError), file_lock(tmp_path / "missing.lock"):
        pass
