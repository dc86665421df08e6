"""compile_function on an integrator, the library cache (tampering, concurrency), the no-compiler fallback."""

from __future__ import annotations

import json
import multiprocessing as mp
import os
import subprocess
import sys
import warnings

import casadi as ca
import numpy as np
import pytest

from apexseal.generated import compiler as comp
from apexseal.generated.compile import CompilerFallbackWarning, compile_function
from apexseal.generated.load import load_functions
from apexseal.generated.manifest import StaleArtefactWarning


def bouncing_ball(name: str = "ball") -> ca.Function:
    """A small erk integrator with a zero-crossing event and a transition (restitution as parameter)."""
    h = ca.SX.sym("x", 2)
    t = ca.SX.sym("t")
    e = ca.SX.sym("p")
    idx = ca.SX.sym("index")
    dae = {"x": h, "t": t, "p": e, "ode": ca.vertcat(h[1], -9.81), "zero": h[0]}
    tr = ca.Function("tr", {"index": idx, "t": t, "x": h, "p": e, "post_x": ca.vertcat(h[0], -e * h[1])},
                     ca.event_in(), ca.event_out())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return ca.integrator(name, "erk", dae, 0, np.linspace(0, 3, 31)[1:],
                             {"transition": tr, "reltol": 1e-9, "abstol": 1e-12, "max_events": 100})


@pytest.fixture
def fresh_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("APEXSEAL_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache"


def test_compile_function_erk_integrator(fresh_cache):
    F = bouncing_ball()
    C = compile_function(F, flags="quick")
    assert C.class_name() != F.class_name()  # an external, not the VM integrator
    want = np.array(F(x0=[5, 0], p=0.8)["xf"])
    got = np.array(C(x0=[5, 0], p=0.8)["xf"])
    np.testing.assert_allclose(got, want, rtol=1e-14, atol=1e-14)
    assert len(list((fresh_cache / "lib").glob("*/fn_ball.so"))) == 1
    compile_function(F, flags="quick")  # a cache hit: nothing new
    assert len(list((fresh_cache / "lib").glob("*/fn_ball.so"))) == 1


def _tiny(name: str) -> ca.Function:
    x = ca.SX.sym("x", 2)
    return ca.Function(name, [x], [ca.sin(x[0]) * x[1] + 3])


def test_modified_library_is_rebuilt(fresh_cache):
    f = _tiny("tiny")
    compile_function(f, flags="quick")
    (so,) = (fresh_cache / "lib").glob("*/fn_tiny.so")
    so.write_bytes(so.read_bytes()[:-16])  # truncated / tampered
    with pytest.warns(StaleArtefactWarning, match="does not match its build record"):
        g = compile_function(f, flags="quick")
    assert float(g([0.5, 2.0])) == pytest.approx(np.sin(0.5) * 2 + 3, rel=1e-15)


def _compile_in_child(cache: str, q) -> None:
    import os

    os.environ["APEXSEAL_CACHE"] = cache
    g = compile_function(_tiny("raced"), flags="quick")
    q.put(float(g([0.5, 2.0])))


def test_two_processes_compile_at_once(fresh_cache):
    ctx = mp.get_context("spawn")
    q = ctx.Queue()
    procs = [ctx.Process(target=_compile_in_child, args=(str(fresh_cache), q)) for _ in range(2)]
    for p in procs:
        p.start()
    for p in procs:
        p.join(60)
        assert p.exitcode == 0
    assert [q.get(timeout=5) for _ in procs] == [np.sin(0.5) * 2 + 3] * 2
    assert len(list((fresh_cache / "lib").glob("*/fn_raced.so"))) == 1
    assert not list((fresh_cache / "lib").glob(".build-*"))  # no temporary build folders left


@pytest.mark.parametrize("cc", ["/nonexistent/gcc", "false"])
def test_no_compiler_falls_back_to_sx(monkeypatch, params, cc):
    monkeypatch.setenv("APEXSEAL_CC", cc)
    comp.compiler_identity.cache_clear()
    with pytest.warns(CompilerFallbackWarning, match="slower per evaluation"):
        L = load_functions(flags="quick")
    assert not L.compiled and L.library is None
    x = np.array([1e-6, -2e-6, 1e-3, 0.01, -0.02, 3.0])
    u = np.array([3e5, 1e5])
    np.testing.assert_array_equal(np.array(L.c.rhs_switched(0.4, x, params, u)),
                                  np.array(L.sx.rhs_switched(0.4, x, params, u)))
    f = _tiny("nocc")
    with pytest.warns(CompilerFallbackWarning):
        assert compile_function(f, flags="quick") is f


def test_bench_precompile_fills_the_entry_compile_function_finds(fresh_cache):
    """The benchmark's parallel pre-compilation and compile_function share one C file name and cache key, and
    the pool's record names the model of what it compiled (it named none, and kept None after a run named it)."""
    from apexseal.runtime.bench.compile_pool import CompileTarget, precompile

    f = _tiny("shared_key")
    model = "d" * 64
    total = precompile([CompileTarget(f, model), CompileTarget(f, model)], flags="quick", workers=1)
    assert total["functions"] == 1 and [b["error"] for b in total["builds"]] == [None, None]
    (function_record,) = (fresh_cache / "gen" / "fn").glob("*/function.json")
    assert json.loads(function_record.read_text())["uses"] == [{"model": model}]
    (record,) = (fresh_cache / "lib").glob("*/build.json")
    stamp = record.stat().st_mtime_ns
    g = compile_function(f, flags="quick", model_hash=model)
    assert json.loads(function_record.read_text())["uses"] == [{"model": model}]
    assert list((fresh_cache / "lib").glob("*/build.json")) == [record] and record.stat().st_mtime_ns == stamp
    assert float(g([0.5, 2.0])) == pytest.approx(np.sin(0.5) * 2 + 3, rel=1e-15)


def test_bench_precompile_starts_the_longest_build_first_and_reports_in_target_order(fresh_cache, monkeypatch):
    """The pool starts its builds longest to compile first (compile_cost, as a library's own files), and its
    records stay in the order of the targets."""
    from apexseal.generated import compile as build
    from apexseal.runtime.bench.compile_pool import CompileTarget, precompile

    x = ca.SX.sym("x", 8)
    small, big = _tiny("small_one"), ca.Function("big_one", [x], [ca.sum1(ca.cumsum(ca.sin(x) * ca.cos(x)) ** 3)])
    started = []
    real = build.build_function

    def recording(source, *, flags):
        started.append(source.name)
        return real(source, flags=flags)

    monkeypatch.setattr(build, "build_function", recording)
    total = precompile([CompileTarget(small, None), CompileTarget(big, None)], flags="quick", workers=1)
    assert [b["name"] for b in total["builds"]] == ["small_one", "big_one"]
    sizes = {b["name"]: b["c_bytes"] for b in total["builds"]}
    assert sizes["big_one"] > sizes["small_one"] and started == ["big_one", "small_one"]


def test_a_flag_set_of_ones_own_is_registered_under_a_name_its_flags_give(fresh_cache):
    """A measurement's flag set is named by :func:`compiler.register_flags`, from its flags: the same name in
    another process (whose string hashes differ) and the project's name for the project's flags; the project's
    sets cannot be changed in place (the levers' sets were written into them under ``hash()``'s keys)."""
    flags = ("-O0", "-fno-math-errno")
    name = comp.register_flags(flags)
    code = f"from apexseal.generated.compiler import register_flags; print(register_flags({flags!r}))"
    other = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                           env=os.environ | {"PYTHONHASHSEED": "12345"})
    assert other.stdout.strip() == name != comp.register_flags(("-O0",))
    assert comp.flag_list(name) == flags and name not in comp.FLAG_SETS
    assert comp.register_flags(["-O1"]) == "quick"
    with pytest.raises(TypeError):
        comp.FLAG_SETS[name] = flags
    compile_function(_tiny("own_flags"), flags=name)
    (record,) = (fresh_cache / "lib").glob("*/build.json")
    assert json.loads(record.read_text())["flags"] == list(flags)
    for bad in ((), ("O2",), ("-O2 -g",)):
        with pytest.raises(ValueError, match="flags"):
            comp.register_flags(bad)
    with pytest.raises(ValueError, match="register_flags"):
        comp.flag_list("flags-000000000000")


@pytest.fixture
def probes(fresh_cache, monkeypatch):
    """The compiler runs :func:`compiler.compiler_identity` makes, counted (its in-process cache cleared around)."""
    runs = []
    real_run = comp.run_compiler

    def counted(cmd, cwd=None):
        runs.append(list(cmd))
        return real_run(cmd, cwd)

    monkeypatch.setattr(comp, "run_compiler", counted)
    comp.compiler_identity.cache_clear()
    yield runs
    comp.compiler_identity.cache_clear()


def _fake_compiler(path, version: str, mtime_s: int):
    path.write_text(f"#!/bin/sh\necho '{version}'\n")
    path.chmod(0o755)
    os.utime(path, (mtime_s, mtime_s))
    return str(path)


def test_a_compilers_identity_is_probed_once_per_executable(probes, tmp_path, fresh_cache):
    """The identity is kept in the cache's compilers.json and read back by the next process (here: with the
    in-process cache cleared); an executable replaced (another size or time) is probed again."""
    cc = _fake_compiler(tmp_path / "fakecc", "fakecc 1.0", 1_700_000_000)
    first = comp.compiler_identity(cc, ("-O1",))
    assert first.startswith("fakecc 1.0 | ") and probes == [[cc, "--version"]]
    comp.compiler_identity.cache_clear()
    assert comp.compiler_identity(cc, ("-O1",)) == first and len(probes) == 1
    assert first in (fresh_cache / "lib" / comp.IDENTITIES).read_text()
    _fake_compiler(tmp_path / "fakecc", "fakecc 2.0", 1_700_000_100)  # upgraded in place
    comp.compiler_identity.cache_clear()
    assert comp.compiler_identity(cc, ("-O1",)).startswith("fakecc 2.0 | ") and len(probes) == 2
    comp.compiler_identity.cache_clear()  # another flag set is another key
    comp.compiler_identity(cc, ("-O2",))
    assert len(probes) == 3


def test_a_failing_compiler_is_never_kept(probes, fresh_cache):
    for _ in range(2):
        comp.compiler_identity.cache_clear()
        with pytest.raises(comp.CompilerUnavailable, match="does not work"):
            comp.compiler_identity("false", ("-O1",))
    assert len(probes) == 2 and not (fresh_cache / "lib" / comp.IDENTITIES).exists()


def test_a_parallel_build_starts_the_file_that_takes_longest(tmp_path, monkeypatch):
    """The model library's four files compile two at a time; in order of size the composite's template (a quarter
    of casadi_model.c's bytes, but loops that -O3 unrolls and vectorises: the longest to compile) started last and
    the build took the time of its longest file plus the first to finish. compile_cost weighs the loops, and the
    build starts the files in its order."""
    from pathlib import Path

    from apexseal.generated import compile as build

    folder = Path(build.__file__).parent / "default"
    files = sorted(folder.glob("*.c"))
    costs = {p.name: build.compile_cost(p) for p in files}
    assert max(costs, key=costs.get) == "apexseal_composite.c", costs
    assert max(files, key=lambda p: p.stat().st_size).name == "casadi_model.c"  # what the size alone started first
    loops = tmp_path / "loops.c"
    loops.write_text("void f(double* x) { for (int i = 0; i < 4; i++) x[i] = 0; for(int j=0;j<2;j++) x[j] = 1; }\n")
    assert build.compile_cost(loops) == loops.stat().st_size + 2 * build.LOOP_BYTES

    started = []

    def record(one, items, threads, stop):
        started.extend(p.name for p in items)
        raise RuntimeError("recorded")

    monkeypatch.setattr(build, "_abandonable_map", record)
    with pytest.raises(RuntimeError, match="recorded"):
        build._compile_all("cc", ("-O1",), files, tmp_path, tmp_path / "lib.so")
    assert started == sorted(costs, key=costs.get, reverse=True)
