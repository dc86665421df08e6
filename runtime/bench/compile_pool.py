"""Compile many CasADi Functions before timing starts: C generated one by one, gcc run in parallel.

``generated.compile.compile_function`` generates, compiles and loads one Function
at a time. The benchmark needs ~25 integrators (one per tolerance: the tolerance is
a constant of the generated C), so it fills the same content-hash cache first,
with ``workers`` compilers at once, the longest to compile first: C generation stays serial (CasADi symbolics
are not thread-safe); only the compiler subprocesses overlap. Afterwards the
engines are built with ``compile_c=True`` and find their libraries in the cache.
Each target (:class:`CompileTarget`, ``methods.compile_target(engine)``) names the model its C embeds or calls
and the library it links against, so the records the pool writes at the station are the engine's own.
Compilation never overlaps a timed run.

The cold compile of one integrator (for the "code generation pays for itself"
estimate) is measured in a private, empty cache, so a warm user cache does not
hide it.
"""

from __future__ import annotations

import contextlib
import os
import resource
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import casadi as ca


@dataclass(frozen=True)
class CompileTarget:
    """A Function to compile and what its station record names: the model whose Functions it embeds or calls
    (a manifest's input hash or a variant's, generated/variant.py; None: it holds no model's) and the compiled
    model library it links against (None: none)."""

    fn: ca.Function
    model_hash: str | None
    link: Path | None = None

    def source(self):
        """The target's C at the station, with its record (``generated.compile.function_source``)."""
        from ...generated.compile import function_source

        return function_source(self.fn, model_hash=self.model_hash, link=self.link)


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def precompile(targets: list[CompileTarget], *, flags: str, workers: int = 2, log=None) -> dict:
    """Compile every target's Function into the cache, its C on the station's record as the engine's would be.

    Returns the phase totals and ``builds``: one record per target, in order
    (C size, compile wall time in this run, ~0 when it was already cached).
    """
    from ...generated.compile import build_function, compile_cost
    from ...generated.compiler import CompilerUnavailable

    jobs, index, seen = [], [], {}
    for target in targets:
        source = target.source()  # at the station, under its record, as the engines do
        digest = source.key_payload["c_sha256"]
        if digest not in seen:
            seen[digest] = len(jobs)
            jobs.append(source)
        index.append(seen[digest])

    def build(source):
        w0 = time.perf_counter()
        try:
            build_function(source, flags=flags)
            err = None
        except CompilerUnavailable as exc:
            err = str(exc)
        return {"name": source.name, "c_sha256": source.key_payload["c_sha256"],
                "c_bytes": source.c_file.stat().st_size, "wall_s": time.perf_counter() - w0, "error": err}

    # the longest to compile first (generated.compile.compile_cost): the pool ends soonest
    order = sorted(range(len(jobs)), key=lambda i: compile_cost(jobs[i].c_file), reverse=True)
    w0, c0 = time.perf_counter(), _children_cpu()
    with ThreadPoolExecutor(max_workers=max(1, workers)) as pool:
        done = dict(zip(order, pool.map(build, [jobs[i] for i in order]), strict=True))
    builds = [done[i] for i in range(len(jobs))]
    total = {"functions": len(jobs), "wall_s": time.perf_counter() - w0, "compiler_cpu_s": _children_cpu() - c0,
             "workers": workers, "builds": [builds[i] for i in index]}
    if log:
        log(f"  compiled {len(jobs)} functions in {total['wall_s']:.1f} s wall "
            f"({total['compiler_cpu_s']:.1f} s compiler CPU, {workers} at a time; cached ones take ~0 s)")
    return total


@contextlib.contextmanager
def private_cache():
    """Point apexseal's cache (``$APEXSEAL_CACHE``) at an empty temporary folder for the block."""
    old = os.environ.get("APEXSEAL_CACHE")
    with tempfile.TemporaryDirectory(prefix="apexseal-cold-") as d:
        os.environ["APEXSEAL_CACHE"] = d
        try:
            yield Path(d)
        finally:
            if old is None:
                os.environ.pop("APEXSEAL_CACHE", None)
            else:
                os.environ["APEXSEAL_CACHE"] = old


def cold_compile(target: CompileTarget, *, flags: str) -> dict:
    """Generate and compile the target from scratch (empty cache): wall and compiler CPU seconds."""
    from ...generated.compile import compile_function

    with private_cache():
        w0, c0 = time.perf_counter(), _children_cpu()
        compile_function(target.fn, flags=flags, model_hash=target.model_hash, link=target.link)
        wall, cpu = time.perf_counter() - w0, _children_cpu() - c0
    return {"function": target.fn.name(), "wall_s": wall, "compiler_cpu_s": cpu, "flags": flags}
