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
