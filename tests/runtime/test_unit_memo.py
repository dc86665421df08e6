"""Unit conversions remembered between processes: a warm scene load gives the same scene without pint, and a
damaged memo file is ignored and rewritten; so is a damaged file of pint's own cache."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import pytest

LOAD = textwrap.dedent("""
    import sys
    import apexseal

    scene = apexseal.load_scene()
    print(scene.content_hash(), "pint" in sys.modules)
""")


def _load(cache) -> tuple[str, bool]:
    env = dict(os.environ, APEXSEAL_CACHE=str(cache))
    proc = subprocess.run([sys.executable, "-c", LOAD], capture_output=True, text=True, timeout=300, env=env)
    assert proc.returncode == 0, proc.stderr[-2000:]
    digest, pint = proc.stdout.split()
    return digest, pint == "True"


def test_second_load_reads_no_unit_with_pint_and_gives_the_same_scene(tmp_path):
    first, pint_first = _load(tmp_path)
    files = list((tmp_path / "units").glob("conversions-*.json"))
    assert pint_first and len(files) == 1
    memo = json.loads(files[0].read_text())["entries"]
    assert json.dumps(["str", "3.06 mm", "m", None]) in memo and memo[json.dumps(["str", "3.06 mm", "m", None])] == 0.00306
    second, pint_second = _load(tmp_path)
    assert second == first and not pint_second


def test_a_damaged_memo_is_ignored_and_rewritten(tmp_path):
    first, _ = _load(tmp_path)
    (path,) = (tmp_path / "units").glob("conversions-*.json")
    path.write_text("{ not json")
    again, pint = _load(tmp_path)
    assert again == first and pint  # read with pint again ...
    assert isinstance(json.loads(path.read_text()), dict)  # ... and remembered anew
    assert _load(tmp_path) == (first, False)


def test_a_memo_edited_by_hand_is_discarded(tmp_path, monkeypatch):
    """The memo's entries were used unchecked: a value edited by hand in conversions-*.json silently changed every
    scene that read it. The file holds the sha256 of its entries; one that does not match is discarded whole (the
    quantity is read by pint again, and the memo written anew)."""
    from apexseal.runtime.scenes import unit_memo
    from apexseal.runtime.scenes.units import parse_quantity

    monkeypatch.setenv("APEXSEAL_CACHE", str(tmp_path))
    monkeypatch.setattr(unit_memo, "_memo", None)
    monkeypatch.setattr(unit_memo, "_added", {})
    key = unit_memo.key_of("7 mm", "m", None)
    assert parse_quantity("7 mm", "m") == pytest.approx(0.007)
    unit_memo.flush()
    (path,) = (tmp_path / "units").glob("conversions-*.json")
    data = json.loads(path.read_text())
    assert data["entries"][key] == pytest.approx(0.007)
    data["entries"][key] = 0.7  # a hand edit, its hash left as it was
    path.write_text(json.dumps(data))
    monkeypatch.setattr(unit_memo, "_memo", None)  # as a new process reads it
    assert unit_memo.lookup(key) is None
    assert parse_quantity("7 mm", "m") == pytest.approx(0.007)
    unit_memo.flush()
    monkeypatch.setattr(unit_memo, "_memo", None)
    assert unit_memo.lookup(key) == pytest.approx(0.007)  # written anew, with a matching hash


def test_a_rejected_value_is_not_remembered():
    """Only conversions that succeed are kept: an error is always pint's current message."""
    from apexseal.runtime.scenes import unit_memo
    from apexseal.runtime.scenes.units import QuantityError, parse_quantity

    with pytest.raises(QuantityError, match="wrong unit"):
        parse_quantity("3 kg", "m", key="seal.Ws")
    assert unit_memo.lookup(unit_memo.key_of("3 kg", "m", None)) is None
    assert parse_quantity("3 mm", "m") == 0.003
    assert unit_memo.lookup(unit_memo.key_of("3 mm", "m", None)) == 0.003


PINT = textwrap.dedent("""
    from apexseal.runtime.scenes.units import registry

    print(registry().Quantity("3 mm").to("m").magnitude)
""")


def test_a_pint_cache_cut_short_by_a_killed_process_is_rebuilt(tmp_path):
    """pint's cache library writes its pickles in place: a file left empty by a killed process would make every
    later registry fail to load ("EOFError: Ran out of input"); it is emptied and written again instead."""
    env = dict(os.environ, APEXSEAL_CACHE=str(tmp_path))

    def convert() -> str:
        proc = subprocess.run([sys.executable, "-c", PINT], capture_output=True, text=True, timeout=300, env=env)
        assert proc.returncode == 0, proc.stderr[-2000:]
        return proc.stdout.strip()

    assert convert() == "0.003"
    pickles = list((tmp_path / "pint").rglob("*.pickle"))
    assert pickles
    for p in pickles:
        p.write_bytes(b"")
    assert convert() == "0.003"
    assert all(p.stat().st_size > 0 for p in (tmp_path / "pint").rglob("*.pickle"))
