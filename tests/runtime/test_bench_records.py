"""The benchmark compiles nothing behind the station's records: every C file it compiles names the model it was built
from (a manifest's input hash, or a variant's own record), and its flag sets are registered by their flags."""

from __future__ import annotations

import json

import casadi as ca
import pytest

from apexseal.files import sha256_bytes, sha256_file
from apexseal.generated.codegen import serialized
from apexseal.generated.compiler import register_flags
from apexseal.generated.load import load_functions
from apexseal.generated.variant import variant_dir, variant_record


@pytest.fixture
def fresh_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("APEXSEAL_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache"


def _records(cache) -> list[dict]:
    return [json.loads(p.read_text()) for p in sorted((cache / "gen" / "fn").glob("*/function.json"))]


def _builds(cache) -> list[dict]:
    return [json.loads(p.read_text()) for p in sorted((cache / "lib").glob("*/build.json"))]


@pytest.mark.slow
def test_levers_compile_every_variant_under_a_record_naming_its_model(fresh_cache):
    """The levers' loop and erk integrator name the model they embed: the manifest's, or the sympy.cse lowering's
    own record, which says what it was built from and how (the loop's record named no model, and the cse variant
    had no record at all)."""
    from apexseal.generated.variant import sympy_cse_variant
    from apexseal.runtime.bench.levers import compile_variant
    from apexseal.runtime.scenes.scene import load_scene

    scene = load_scene()
    sx = load_functions(scene.effects, scene.assumptions, compiled=False).sx
    cse = sympy_cse_variant(scene.effects, scene.assumptions)
    assert sx.model_hash and cse.model_hash not in (None, sx.model_hash)
    flags = register_flags(("-O0",))  # the quickest build; the measurement's own sets go the same way
    compile_variant(sx, flags, steps=2, rtol=1e-6, erk=False)
    compile_variant(cse, flags, steps=2, rtol=1e-6, n_samples=4)

    records = _records(fresh_cache)
    assert sorted((r["name"], r["model"]) for r in records) == sorted(
        [("fold_step", sx.model_hash), ("fold_step", cse.model_hash), ("apexseal_erk", cse.model_hash)])
    variant = variant_record(cse.model_hash)
    assert variant["of"] == sx.model_hash and variant["how"]["build_functions"] == {"sympy_cse": True}
    assert variant["functions"] == sha256_bytes(serialized(cse.functions().values()).encode())
    for r in records:
        assert r.get("variant") == (None if r["model"] == sx.model_hash else
                                    {"of": variant["of"], "how": variant["how"]})
    assert [b["flags"] for b in _builds(fresh_cache)] == [["-O0"]] * 3


def test_the_library_before_linking_is_a_variant_on_the_station_record(fresh_cache):
    """linking.py's library of the model without the hybrid Functions is built from C at the station, under a
    variant record naming the model it leaves them out of (its C was written to a temporary folder and built under
    a key no record described)."""
    from apexseal.runtime.bench.linking import BEFORE_LIBRARY, before_library

    sx = load_functions(compiled=False).sx
    so = before_library(sx, register_flags(("-O0",)))
    (build,) = _builds(fresh_cache)
    source = build["sources"]
    assert source["kind"] == "variant" and build["so_sha256"] == sha256_file(so)
    record = variant_record(source["variant"])
    assert record["of"] == sx.model_hash and record["how"] == BEFORE_LIBRARY
    folder = variant_dir(source["variant"])
    assert record["library_files"] == source["files"] == {
        name: sha256_file(folder / name) for name in ("casadi_model.c", "casadi_model.h")}
    assert ca.external("rhs_switched", str(so)).n_in() == 4
    with pytest.raises(RuntimeError):  # without the hybrid Functions
        ca.external("hybrid_ode", str(so))


def test_the_benchmarks_compile_targets_name_their_engines_model():
    """What the benchmark pre-compiles carries the model its engine was built for (the pool wrote no model)."""
    from apexseal.runtime.bench.config import METHODS
    from apexseal.runtime.bench.methods import build_engine, compile_target

    sx = load_functions(compiled=False).sx
    for method, value in (("euler-C", 3600), ("erk-C", 1e-6)):
        engine = build_engine(sx, METHODS[method], value, samples=4, span=0.1, flags="quick", compiled=False)
        target = compile_target(engine)
        assert target.fn is (engine.vm if method == "erk-C" else engine.function)
        assert (target.model_hash, target.link) == (sx.model_hash, None)
