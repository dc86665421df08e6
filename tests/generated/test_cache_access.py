"""The artefact cache when it cannot be written (read-only, shared, a file, a full disk) and when its C is edited.

Unwritability is emulated in-process (the writes and the lock raise what the operating system raises), so the tests
bite when they run as root too.
"""

from __future__ import annotations

import errno
import subprocess
import tempfile
import warnings

import casadi as ca
import pytest

from apexseal.files import CacheError, TemporaryFolderError
from apexseal.generated import compile as comp
from apexseal.generated.manifest import StaleArtefactError, StaleArtefactWarning


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("APEXSEAL_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache"


def _function(name: str) -> ca.Function:
    x = ca.SX.sym("x")
    return ca.Function(name, [x], [3 * x + 1])


def _unwritable(monkeypatch) -> list:
    """Every write and lock of the compile cache fails as in a folder this user cannot write; the attempts."""
    tried = []

    def refuse(path, *args, **kwargs):
        tried.append(path)
        raise PermissionError(errno.EACCES, "Permission denied", str(path))

    monkeypatch.setattr(comp, "atomic_write", refuse)
    monkeypatch.setattr(comp, "file_lock", refuse)
    return tried


def test_a_warm_entry_is_only_read(cache, monkeypatch):
    """A fully warm run on a read-only or shared cache crashed: function_source rewrote function.json on every
    run. An entry that is as it should be is read, neither rewritten nor locked."""
    f = _function("warm")
    assert float(comp.compile_function(f, flags="quick")(2.0)) == 7.0
    tried = _unwritable(monkeypatch)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no fallback either
        assert float(comp.compile_function(f, flags="quick")(2.0)) == 7.0
    assert tried == []


def test_what_must_be_built_in_an_unwritable_cache_is_one_clear_error(cache, monkeypatch):
    """An unwritable (empty) cache raised PermissionError on a temporary file: a CacheError names the cache
    folder, the path, the cause and APEXSEAL_CACHE, and there is no fallback to the interpreted Functions."""
    _unwritable(monkeypatch)
    with warnings.catch_warnings(), pytest.raises(CacheError) as caught:
        warnings.simplefilter("error")
        comp.compile_function(_function("cold"), flags="quick")
    message = str(caught.value)
    assert message.startswith(f"the cache folder {cache} is not writable ({cache}{'/'}gen/fn/")
    assert message.endswith(": Permission denied); set APEXSEAL_CACHE to a folder you can write")


def test_a_cache_path_that_is_a_file_is_one_clear_error(tmp_path, monkeypatch):
    blocker = tmp_path / "cache"
    blocker.write_text("")
    monkeypatch.setenv("APEXSEAL_CACHE", str(blocker))
    with pytest.raises(CacheError, match=f"^the cache folder {blocker} is not a folder \\({blocker} is a file\\)"):
        comp.compile_function(_function("file"), flags="quick")


def _full_compile(monkeypatch, written, name: str, expected: type) -> OSError:
    """The error of compiling a Function with a compiler whose object step fails as gcc's assembler does on a full
    disk, naming the file it could not write (``written(cmd)``)."""
    real = comp.run_compiler

    def full(cmd, *args, **kwargs):
        if "-c" in cmd:
            return subprocess.CompletedProcess(cmd, 1, "", f"{written(cmd)}: Fatal error: can't write 5 bytes to "
                                               "section .text: 'No space left on device'\n")
        return real(cmd, *args, **kwargs)

    monkeypatch.setattr(comp, "run_compiler", full)
    with warnings.catch_warnings(), pytest.raises(expected) as caught:
        warnings.simplefilter("error")
        comp.compile_function(_function(name), flags="quick")
    assert caught.value.errno == errno.ENOSPC
    return caught.value


def test_a_full_disk_is_no_missing_compiler(cache, monkeypatch):
    """gcc failing with "No space left on device" was reported as CompilerUnavailable, and the run fell back to
    the interpreted Functions (4-10x slower) before it crashed on an OSError naming no path: it is a CacheError
    naming the build folder and the compiler's line, with no fallback."""
    message = str(_full_compile(monkeypatch, lambda cmd: cmd[cmd.index("-o") + 1], "full", CacheError))
    assert message.startswith(f"the disk of the cache folder {cache} is full ({cache}/lib/.build-")
    assert "No space left on device; the compiler said: " in message and "APEXSEAL_CACHE" in message
    assert not list((cache / "lib").glob(".build-*"))  # the build folder is removed


def test_a_full_temporary_folder_is_not_the_cache_s_disk(cache, tmp_path, monkeypatch):
    """gcc writes its assembler files to TMPDIR: a full TMPDIR was reported as the cache's disk being full, with
    advice to move APEXSEAL_CACHE (which had room). It names the temporary folder and TMPDIR."""
    temp = tmp_path / "tmp"
    temp.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(temp))
    err = _full_compile(monkeypatch, lambda cmd: f"{temp}/ccAbC123.s", "tmpfull", TemporaryFolderError)
    assert not isinstance(err, CacheError)
    message = str(err)
    assert message.startswith(f"the disk of the temporary folder {temp} is full (No space left on device; the "
                              f"compiler said: {temp}/ccAbC123.s: Fatal error")
    assert message.endswith("set TMPDIR to a folder on another disk") and "APEXSEAL_CACHE" not in message


def test_a_full_disk_while_writing_an_entry_names_it(cache, monkeypatch):
    """A write to the cache that fails on a full disk raised OSError naming no path."""
    def full(path, data, **kwargs):
        from apexseal.files import atomic_open

        with atomic_open(path, "wb" if isinstance(data, bytes) else "w") as fh:
            fh.write(data)
            raise OSError(errno.ENOSPC, "No space left on device")  # what a full disk's write raises: no path

    monkeypatch.setattr(comp, "atomic_write", full)
    with pytest.raises(CacheError, match=f"^the disk of the cache folder {cache} is full \\({cache}/gen/fn/.*\\.c: "
                                         "No space left on device\\)"):
        comp.compile_function(_function("fullc"), flags="quick")


def test_an_edited_c_file_is_flagged_and_never_runs(cache):
    """With its library cached, an edited gen/fn/*/fn_*.c was restored without a word, and build_library never
    checked the C on disk against the c_sha256 its key names: the edit is flagged and undone, and a library whose
    C on disk is not that C is not used (nor compiled under that key)."""
    f = _function("edited")
    comp.compile_function(f, flags="quick")
    source = comp.function_source(f)
    original = source.c_file.read_bytes()
    source.c_file.write_bytes(original + b"\n/* edited */\n")
    with pytest.raises(StaleArtefactError, match="fn_edited.c is not the C the library"):
        comp.build_function(source, flags="quick")
    with pytest.warns(StaleArtefactWarning, match="was modified"):
        g = comp.compile_function(f, flags="quick")
    assert source.c_file.read_bytes() == original and float(g(2.0)) == 7.0


def test_the_cli_reports_an_unusable_cache_in_one_line(tmp_path):
    """A run with APEXSEAL_CACHE naming a file ended in a traceback: one error line, exit code 1."""
    import os

    from apexseal.cli import command

    blocker = tmp_path / "cache"
    blocker.write_text("")
    env = dict(os.environ, APEXSEAL_CACHE=str(blocker))
    proc = subprocess.run(command("simulate", "-n", "1", "-q", "--no-figures", "--out", str(tmp_path / "run")),
                          capture_output=True, text=True, env=env, timeout=600, cwd=tmp_path)
    assert proc.returncode == 1, proc.stderr
    assert "Traceback" not in proc.stderr
    assert f"Error: the cache folder {blocker} is not a folder ({blocker} is a file); set APEXSEAL_CACHE" in proc.stderr


def test_generate_into_a_full_disk_is_one_error_line(tmp_path, monkeypatch):
    """`apexseal generate --out <a full disk>` ended in a traceback of OSError naming no path."""
    from click.testing import CliRunner

    from apexseal.cli import main
    from apexseal.generated import generate as gen

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(gen, "generate", full)
    monkeypatch.setenv("APEXSEAL_CACHE", str(tmp_path / "cache"))
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["generate", "--out", str(out), "--no-compile"])
    assert r.exit_code == 1 and "Traceback" not in r.output, r.output
    assert f"Error: cannot write the generated artefacts to {out} ({out}: No space left on device)" in r.output
