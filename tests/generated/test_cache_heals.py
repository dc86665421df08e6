"""Caches that heal: a derivation entry of the wrong type is rebuilt; a derivation missed by two processes at once
is derived once; build folders of killed compiles are swept."""

from __future__ import annotations

import os
import pickle
import time

import casadi as ca
import pytest

from apexseal.derive import cache as derive_cache
from apexseal.derive import model as derive_model_mod
from apexseal.derive.effects import Effects
from apexseal.generated import compile as comp


def test_a_cache_entry_of_the_wrong_type_is_rebuilt(tmp_path, monkeypatch):
    real = derive_cache.cached_model(Effects.only("spring"))  # from the session's cache (derived once if cold)
    monkeypatch.setenv("APEXSEAL_CACHE", str(tmp_path))
    calls = []
    monkeypatch.setattr(derive_model_mod, "derive_model", lambda *a: calls.append(a) or real)
    key = derive_cache.derivation_key(Effects.only("spring"), derive_cache.Assumptions())
    path = tmp_path / "derive" / f"{key}.pkl"
    path.parent.mkdir(parents=True)
    path.write_bytes(pickle.dumps({"a valid pickle": "of the wrong type"}))
    got = derive_cache.cached_model(Effects.only("spring"))
    assert isinstance(got, derive_model_mod.DerivedModel) and len(calls) == 1
    with path.open("rb") as fh:
        assert isinstance(pickle.load(fh), derive_model_mod.DerivedModel)  # the entry was overwritten
    derive_cache.cached_model(Effects.only("spring"))
    assert len(calls) == 1  # and is a hit from now on


def test_processes_missing_the_same_derivation_at_once_derive_it_once(tmp_path, monkeypatch):
    """Two test processes (or a sweep's workers) that missed the same model derived it side by side, each for the
    whole derivation (the chamber gas model's took some 30 s then); a lock per key now lets the first derive it while the
    other waits, says so, and reads it. Threads stand for the processes: each takes the lock through a file of its
    own opening, as a process does."""
    import threading

    real = derive_cache.cached_model(Effects.only("spring"))  # from the session's cache (derived once if cold)
    monkeypatch.setenv("APEXSEAL_CACHE", str(tmp_path))
    calls, started = [], threading.Event()

    def slow_derivation(*args):
        calls.append(args)
        started.set()
        time.sleep(0.5)
        return real

    monkeypatch.setattr(derive_model_mod, "derive_model", slow_derivation)
    got = []
    first = threading.Thread(target=lambda: got.append(derive_cache.cached_model(Effects.only("spring"))))
    first.start()
    assert started.wait(30)
    second = derive_cache.cached_model(Effects.only("spring"))  # misses, waits for the lock, then hits
    first.join()
    assert len(calls) == 1
    assert isinstance(second, derive_model_mod.DerivedModel) and isinstance(got[0], derive_model_mod.DerivedModel)
    assert second.effects == got[0].effects == Effects.only("spring")


def test_build_folders_of_killed_compiles_are_swept(tmp_path, monkeypatch):
    monkeypatch.setenv("APEXSEAL_CACHE", str(tmp_path))
    x = ca.SX.sym("x")
    f = ca.Function("swept", [x], [2 * x])
    comp.compile_function(f, flags="quick")  # the cache's key folder exists; find the key of this build
    (key_dir,) = [p for p in (tmp_path / "lib").iterdir() if p.is_dir() and not p.name.startswith(".")]
    same = tmp_path / "lib" / f".build-{key_dir.name[:16]}-killed"
    old = tmp_path / "lib" / ".build-0123456789abcdef-killed"
    fresh = tmp_path / "lib" / ".build-fedcba9876543210-running"
    for folder in (same, old, fresh):
        folder.mkdir()
    os.utime(old, (time.time() - 2 * comp.ABANDONED_AFTER,) * 2)
    removed = comp.sweep_build_folders(key_dir.name)
    assert sorted(removed) == sorted([same, old])
    assert fresh.exists()  # a build that may still be running is left alone


def test_a_rebuild_sweeps_the_folder_its_killed_build_left(tmp_path, monkeypatch):
    monkeypatch.setenv("APEXSEAL_CACHE", str(tmp_path))
    x = ca.SX.sym("x")
    f = ca.Function("rebuilt", [x], [3 * x])
    comp.compile_function(f, flags="quick")
    (key_dir,) = [p for p in (tmp_path / "lib").iterdir() if p.is_dir() and not p.name.startswith(".")]
    left = tmp_path / "lib" / f".build-{key_dir.name[:16]}-killed"
    left.mkdir()
    for p in key_dir.iterdir():  # as if the killed build never finished
        p.unlink()
    g = comp.compile_function(f, flags="quick")
    assert float(g(2.0)) == pytest.approx(6.0)
    assert not left.exists()
