"""Compile generated C into shared libraries, cached by content, and load them with ``casadi.external``.

Cache: ``derive.cache.cache_dir() / "lib" / <key> /`` (``$APEXSEAL_CACHE`` moves it),
holding the library and ``build.json`` (key, flags, compiler, the library's sha256).
The key is a sha256 over the sources' hashes (for a model: the manifest's input
hash and file hashes), the flag set, the compiler's identity and, for
``-march=native``, the CPU architecture gcc resolves it to; so a library is only
reused for exactly what it was built from (the compiler and its identity: generated/compiler.py).

Builds are safe with concurrent processes: an ``fcntl`` lock per key serialises
builders, objects and the library are built in a uniquely named temporary folder,
and the library is moved in with ``os.replace``. A library whose sha256 differs
from its ``build.json``, or whose C on disk is not the C its key names, is rebuilt with a warning, never used
(the C of a run Function is restored first, :func:`function_source`): the C on disk is what runs. Build folders a killed
compile left behind are swept: those of the same key under its lock, any other
one older than :data:`ABANDONED_AFTER`.

Compiler: ``$APEXSEAL_CC``, else ``$CC``, else ``gcc``. When it is missing or fails,
callers fall back to CasADi's interpreted SX Functions with a
:class:`CompilerFallbackWarning` that says what that costs. A compiler that fails because it cannot write (a
full disk, a read-only file system) is no missing compiler: that is a :class:`~apexseal.files.CacheError`, as is
any other write below the cache that fails; a warm cache is only read, so a read-only or shared one serves every
run whose artefacts it holds.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import tempfile
import time
import warnings
from collections.abc import Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import casadi as ca

from ..cores import parallel_threads
from ..derive.cache import cache_dir
from ..files import (
    DISK_ERRNOS,
    atomic_write,
    content_key,
    file_lock,
    inside,
    read_json_object,
    sha256_bytes,
    sha256_file,
    temporary_folder_error,
    writing_cache,
)
from ..progress import stage
from .codegen import write_c
from .compiler import CompilerUnavailable, compiler, compiler_identity, flag_list, lib_root, run_compiler, stop, stop_all
from .functions import EXTERNAL_OPTIONS, ModelFunctions
from .manifest import StaleArtefactError, StaleArtefactWarning, verify
from .variant import VARIANT_LIBRARY, VARIANT_RECORD, variant_dir, variant_record

#: the model library's file name; unique per cache key, because an integrator that links against it finds it by
#: that name, and a process that loaded one model's library would otherwise hand it to another model's integrator
MODEL_LIBRARY = "libapexseal_model_{key}.so"

FALLBACK_COST = (
    "CasADi's interpreted SX Functions are used instead, which are about 4-10x slower per evaluation: an Euler step "
    "of this model's rhs_switched costs ~2.1 us interpreted vs ~0.35-0.55 us compiled (docs/codegen.md), and a "
    "revolution of the default scene at scaled error 1e-6 with erk ~3.5 s vs ~0.47 s CPU (docs/bench/table.md). Install "
    "gcc or point APEXSEAL_CC at a working C compiler."
)


class CompilerFallbackWarning(RuntimeWarning):
    """Compiled code was asked for but the interpreted Functions are used."""


#: a temporary build folder older than this (s) belongs to a compile that was killed
ABANDONED_AFTER = 24 * 3600.0


def sweep_build_folders(key: str) -> list[Path]:
    """Remove the build folders of ``key`` (call with its lock held) and every build folder older than
    :data:`ABANDONED_AFTER`; return what was removed."""
    removed = []
    now = time.time()
    for folder in lib_root().glob(".build-*"):
        try:
            stale = folder.name.startswith(f".build-{key[:16]}-") or now - folder.stat().st_mtime > ABANDONED_AFTER
        except OSError:
            continue
        if stale and folder.is_dir():
            shutil.rmtree(folder, ignore_errors=True)
            removed.append(folder)
    return removed


def source_hashes(key_payload: dict, sources: Sequence[Path]) -> dict[Path, str]:
    """The sha256 each of a library's C files must have: the one its key names (a model's or a variant's ``files``,
    a run Function's ``c_sha256``)."""
    files = key_payload.get("files")
    if isinstance(files, dict):
        return {src: files.get(src.name) for src in sources}
    return {src: key_payload.get("c_sha256") for src in sources}


def _edited(expected: Mapping[Path, str]) -> list[Path]:
    """The C files whose content is not the one the library's key names."""
    return [src for src, digest in expected.items() if not (src.is_file() and sha256_file(src) == digest)]


def _valid(so: Path, record_path: Path, key: str, expected: Mapping[Path, str]) -> bool:
    """The library is the one its build record describes, built from the C on disk (rechecked on every load: the
    C files are small, and their hashes are remembered for the process while their stat is unchanged)."""
    record = read_json_object(record_path) or {}
    return (record.get("key") == key and so.is_file() and sha256_file(so) == record.get("so_sha256")
            and not _edited(expected))


def disk_error(stderr: str, folder: Path) -> OSError | None:
    """The OS error a compiler reports when it cannot write its output (a full disk, a quota, a read-only or
    failing device), as an ``OSError`` of ``folder`` quoting the compiler's line; None for any other failure.
    A line that names a file of the temporary folder (gcc's assembler files) outside ``folder`` is that folder's
    :class:`~apexseal.files.TemporaryFolderError`: the cache's disk may have room."""
    for code in DISK_ERRNOS:
        line = next((ln.strip() for ln in stderr.splitlines() if os.strerror(code) in ln), None)
        if line is None:
            continue
        said = line[-300:]
        temp = Path(tempfile.gettempdir())
        named = [Path(p) for p in re.findall(r"(?<![\w.])(/[^\s:'\"]+)", line)]
        if any(inside(p, temp) for p in named) and not any(inside(p, folder) for p in named):
            return temporary_folder_error(code, temp, said)
        return OSError(code, f"{os.strerror(code)}; the compiler said: {said}", os.fspath(folder))
    return None


def _failed(cc: str, what: str, stderr: str, folder: Path) -> Exception:
    """The error of a compiler run that failed: a :func:`disk_error`, else :class:`CompilerUnavailable`."""
    return disk_error(stderr, folder) or CompilerUnavailable(f"{cc} failed {what}: {stderr.strip()[-600:]}")


#: what one loop of a C file costs gcc -O3 beside its straight-line code, in bytes of that code: CasADi's C is
#: straight-line, and the composite's template (27.6 kB, 61 loops, unrolled and vectorised) took longer than the
#: default model's casadi_model.c (125 kB, none): 2.9 s against 2.2 s (gcc 12, -O3 -march=native, one core)
LOOP_BYTES = 2000
_LOOP = re.compile(rb"\bfor\s*\(")


def compile_cost(source: Path) -> int:
    """An estimate of the time the compiler takes on ``source``, for the order of a parallel build: its size, and
    :data:`LOOP_BYTES` for each of its loops. Started longest first, the default model library (four files, two at
    a time) built in the time of its longest file instead of that plus the first to finish (docs/codegen.md)."""
    data = source.read_bytes()
    return len(data) + LOOP_BYTES * len(_LOOP.findall(data))


def _compile_all(cc: str, flags: tuple[str, ...], sources: list[Path], build_dir: Path, target: Path,
                 link: Sequence[str] = (), order_by=compile_cost) -> None:
    """Compile every source to an object in parallel, the largest ``order_by`` first (the longest to compile: the
    build ends soonest), then link them (and the ``link`` arguments) into ``target``."""
    sources = sorted(sources, key=order_by, reverse=True)
    includes = sorted({f"-I{p.parent}" for p in sources})

    running: set = set()  # the compilers of this build, stopped if it is abandoned

    def one(src: Path) -> Path:
        obj = build_dir / (src.stem + ".o")
        out = run_compiler([cc, *flags, "-fPIC", *includes, "-c", str(src), "-o", str(obj)], running=running)
        if out.returncode != 0:
            raise _failed(cc, f"on {src.name}", out.stderr, build_dir)
        return obj

    objects = _abandonable_map(one, sources, parallel_threads(len(sources)), lambda: stop(running))
    out = run_compiler([cc, "-shared", *[str(o) for o in objects], "-o", str(target), *link, "-lm"])
    if out.returncode != 0:
        raise _failed(cc, f"to link {target.name}", out.stderr, build_dir)


def link_arguments(library: Path, lib_dir: Path) -> list[str]:
    """Linker arguments for a library that calls ``library`` (the model library of the cache): found at load time
    through a run path relative to the caller's own folder, so the cache still works after it moved."""
    stem = library.name.removeprefix("lib").removesuffix(".so")
    rel = os.path.relpath(library.parent, lib_dir)
    return [f"-L{library.parent}", f"-l{stem}", f"-Wl,-rpath,$ORIGIN/{rel}"]


def build_library(key_payload: dict, sources: list[Path], name: str, *, flags: str, link: Path | None = None) -> Path:
    """The cached library built from ``sources`` (building it if missing or modified), linked against the
    library ``link`` when given (its sha256 must be in ``key_payload``); ``{key}`` in ``name`` becomes the
    start of the cache key. A cached library is only read (no lock, no write); what must be built and cannot be
    written raises :class:`~apexseal.files.CacheError`; a C file that is not the one the key names,
    :class:`~.manifest.StaleArtefactError` (it is never compiled under that key)."""
    cc = compiler()
    fl = flag_list(flags)
    key = content_key({**key_payload, "flags": list(fl), "compiler": compiler_identity(cc, fl), "cc": cc})
    name = name.format(key=key[:16])
    lib_dir = lib_root() / key
    so, record = lib_dir / name, lib_dir / "build.json"
    expected = source_hashes(key_payload, sources)
    if _valid(so, record, key, expected):
        return so
    with writing_cache(cache_dir()), file_lock(lib_root() / f"{key}.lock", name):
        if _valid(so, record, key, expected):  # another process built it while we waited
            return so
        edited = _edited(expected)
        if edited:
            raise StaleArtefactError(edited[0].parent, [f"{edited[0].name} is not the C the library {name} is built "
                                                        "from (modified since it was generated)"])
        if so.exists():
            warnings.warn(f"compiled library {so} does not match its build record (modified or partial); rebuilding",
                          StaleArtefactWarning, stacklevel=3)
        sweep_build_folders(key)
        build_dir = Path(tempfile.mkdtemp(dir=lib_root(), prefix=f".build-{key[:16]}-"))
        try:
            with stage(f"compiling {name} ({len(sources)} C file{'s' if len(sources) != 1 else ''}, {cc} "
                       f"{' '.join(fl)}; first use, cached afterwards)"):
                _compile_all(cc, fl, sources, build_dir, build_dir / name,
                             link_arguments(link, lib_dir) if link is not None else ())
            lib_dir.mkdir(parents=True, exist_ok=True)
            os.replace(build_dir / name, so)
        finally:
            shutil.rmtree(build_dir, ignore_errors=True)
        atomic_write(record, json.dumps({"key": key, "so": name, "so_sha256": sha256_file(so), "flags": list(fl),
                                         "compiler": compiler_identity(cc, fl), "sources": key_payload}, indent=2) + "\n")
    return so


def compile_library(source_dir: Path | str, *, flags: str = "optimised", manifest=None) -> Path:
    """Compile a folder written by :func:`.generate.generate` (after :func:`.manifest.verify`) into the cache.

    Raises :class:`.manifest.StaleArtefactError` for stale or modified artefacts and
    :class:`CompilerUnavailable` when no compiler works. ``manifest``: the folder's manifest as the caller
    verified it (trusted) already.
    """
    source_dir = Path(source_dir)
    manifest = manifest or verify(source_dir, trusted=True)
    payload = {"kind": "model", "input_hash": manifest.input_hash, "files": manifest.files}
    return build_library(payload, [source_dir / f for f in manifest.c_files], MODEL_LIBRARY, flags=flags)


def load_externals(library: Path, names: Sequence[str]) -> dict[str, ca.Function]:
    """One ``casadi.external`` per Function name, all from the same library (Jacobians are found by name), with
    the options :data:`.functions.EXTERNAL_OPTIONS` gives it."""
    return {name: ca.external(name, str(library), EXTERNAL_OPTIONS.get(name, {})) for name in names}


def fallback(reason: str | Exception, *, stacklevel: int = 3) -> None:
    """Warn that the interpreted Functions stand in for compiled ones; a compiler that failed because a signal
    stopped the work (Ctrl-C reaches the compiler too) is no missing compiler: the interruption goes on."""
    from ..signals import StopSignals

    StopSignals.raise_pending()
    warnings.warn(f"no compiled C: {reason}. {FALLBACK_COST}", CompilerFallbackWarning, stacklevel=stacklevel)


@dataclass(frozen=True)
class FunctionSource:
    """The generated C of one CasADi Function at the station and what names its compiled library in the cache."""

    name: str  # the Function's name (the symbol the library exports)
    c_file: Path
    key_payload: dict  # build_library's key payload: kind, name, the C's sha256 (and the linked library's)
    link: Path | None = None  # the compiled model library whose symbols the C declares extern

    @property
    def library_name(self) -> str:
        return self.c_file.stem + ".so"


FUNCTION_RECORD = "function.json"


def function_dir(c_sha256: str) -> Path:
    """The station's folder of one generated run Function (an integrator, a fold, a shooting function)."""
    return cache_dir() / "gen" / "fn" / c_sha256


def generate_c(fn: ca.Function, stem: str, folder: str, *, derivatives: bool = False) -> Path:
    """Write the CasADi C of ``fn`` (and ``fn.jacobian()``) to ``folder/stem.c``.

    CasADi 3.8.2 cannot generate an integrator whose DAE calls a ``casadi.external`` as it stands: the
    integrator's reference counting names every Function it holds, among them ``daeF``, which its C never
    calls, and ``FunctionInternal::codegen_name`` raises "Function 'daeF' not found" for a Function that was
    not added to the generator (casadi/core/function_internal.cpp; docs/codegen.md). Such a Function is added
    first, and generation is retried, until CasADi finds every one.
    """
    extra: list[ca.Function] = []
    while True:
        cg = ca.CodeGenerator(f"{stem}.c")
        for f in extra:
            cg.add(f)
        try:
            cg.add(fn)
            if derivatives:
                cg.add(fn.jacobian())
        except RuntimeError as exc:
            missing = re.search(r"Function '(\w+)' not found", str(exc))
            name = missing.group(1) if missing else None
            if name is None or not fn.has_function(name) or name in {f.name() for f in extra}:
                raise
            extra.append(fn.get_function(name))
        else:
            cg.generate(folder + os.sep)
            return Path(folder) / f"{stem}.c"


#: the comment CasADi writes above the declarations of the symbols a generated C file calls but does not define
EXTERN_BLOCK = "/* External functions */"


def extern_symbols(c_source: str) -> list[str]:
    """The functions a CasADi C file declares without defining them (those of a linked library)."""
    if EXTERN_BLOCK not in c_source:
        return []
    block = c_source.split(EXTERN_BLOCK, 1)[1].split("\n\n", 1)[0]
    return re.findall(r"^int (\w+)\(const casadi_real\*\* arg", block, re.M)


def function_source(fn: ca.Function, *, derivatives: bool = False, model_hash: str | None = None,
                    link: Path | None = None) -> FunctionSource:
    """Generate the C of ``fn`` (and of ``fn.jacobian()`` with ``derivatives``) at the station.

    The C goes to :func:`function_dir` with its record (``function.json``: the C's sha256, the input hash
    of the model manifest whose Functions the C embeds or calls, ``model``, and with ``link``, the compiled
    model library it calls and the symbols it declares extern), so what is compiled is always on the
    station's record. A ``model_hash`` that names a model variant no manifest describes (:mod:`.variant`)
    brings the variant's record, what it was built from and how (``variant``). Two models whose integrators
    have the same C (it calls the model library, whose sizes alone it embeds) share the file: ``uses`` lists
    every (model, library) it was generated for, so each library built from it is on the record, not only the
    last one's. The one place that decides a
    Function's C file and cache key: :func:`compile_function` and the benchmark's parallel pre-compilation both
    build from it, so they fill and find the same entries. Every caller names the model it compiles
    (None: a Function that holds no model's).
    A C file that calls symbols it does not define needs ``link``.
    """
    stem = "fn_" + re.sub(r"\W", "_", fn.name())
    with tempfile.TemporaryDirectory(prefix="apexseal-fn-") as tmp:
        data = generate_c(fn, stem, tmp, derivatives=derivatives).read_bytes()
    digest = sha256_bytes(data)
    externs = extern_symbols(data.decode())
    if externs and link is None:
        raise ValueError(f"the C of {fn.name()} calls {', '.join(externs[:3])}... of a library: pass link=")
    folder = function_dir(digest)
    src = folder / f"{stem}.c"
    earlier = read_json_object(folder / FUNCTION_RECORD) or {}
    record = {"format": "apexseal-function/1", "name": fn.name(), "files": {src.name: digest}, "model": model_hash,
              "derivatives": derivatives}
    variant = variant_record(model_hash)
    if variant is not None:
        record["variant"] = {"of": variant["of"], "how": variant["how"]}
    payload = {"kind": "function", "name": fn.name(), "c_sha256": digest}
    use = {"model": model_hash}
    if link is not None:
        linked = {"library": link.name, "so_sha256": sha256_file(link), "extern": externs}
        record["links"] = linked
        payload["links"] = {"library": link.name, "so_sha256": linked["so_sha256"]}
        use |= {"library": link.name, "so_sha256": linked["so_sha256"]}
    uses = [u for u in earlier.get("uses", []) if isinstance(u, dict) and u != use]
    record["uses"] = sorted([*uses, use], key=lambda u: json.dumps(u, sort_keys=True))
    with writing_cache(cache_dir()):  # an entry as it should be is only read: a read-only cache serves it
        on_disk = sha256_file(src) if src.is_file() else None
        if on_disk != digest:
            if on_disk is not None:
                warnings.warn(f"generated C {src} was modified (its sha256 is not the one its folder is named by); "
                              "restoring it", StaleArtefactWarning, stacklevel=3)
            atomic_write(src, data)
        if record != earlier:
            atomic_write(folder / FUNCTION_RECORD, json.dumps(record, indent=2) + "\n")
    return FunctionSource(fn.name(), src, payload, link)


def build_function(source: FunctionSource, *, flags: str) -> Path:
    """The cached library of a :class:`FunctionSource` (built if missing)."""
    return build_library(source.key_payload, [source.c_file], source.library_name, flags=flags, link=source.link)


def build_function_libraries(sources: Sequence[FunctionSource], *, flags: str) -> list[Path]:
    """The libraries of several sources, built at once (a thread each). A signal abandons them together: the
    worker threads, which the signal does not reach, are not waited for, and every compiler is killed (they ran to
    their ends, tens of seconds after a Ctrl-C)."""
    return _abandonable_map(lambda s: build_function(s, flags=flags), sources, max(1, len(sources)), stop_all)


def _abandonable_map(fn, items: Sequence, workers: int, stop_compilers) -> list:
    """``fn`` over ``items`` in ``workers`` threads, waited for as a ``with`` block waits. A signal
    (``KeyboardInterrupt`` in this thread, which the workers do not get) abandons them instead: ``stop_compilers``
    kills the compilers they wait for, and nothing is waited for (the workers' compilers ran to their ends, tens of
    seconds after a Ctrl-C)."""
    pool, abandoned = ThreadPoolExecutor(max_workers=workers), False
    try:
        return list(pool.map(fn, items))
    except KeyboardInterrupt:
        abandoned = True
        pool.shutdown(wait=False, cancel_futures=True)  # no further compiler starts, then those running go
        stop_compilers()
        raise
    finally:
        pool.shutdown(wait=not abandoned)


def compile_function(fn: ca.Function, *, flags: str = "optimised", derivatives: bool = False,
                     model_hash: str | None = None, link: Path | None = None) -> ca.Function:
    """Generate C for a run Function (e.g. an ``erk`` integrator with events) at the station, compile, load it.

    The library is cached by the sha256 of the generated C (which embeds the model's Functions or, with
    ``link``, calls those of the compiled model library ``link`` and links against it), the flags and the
    compiler. ``derivatives=True`` also generates ``fn.jacobian()`` so the external has an exact Jacobian.
    With no working compiler, returns ``fn`` itself and warns.
    """
    try:
        so = build_function(function_source(fn, derivatives=derivatives, model_hash=model_hash, link=link),
                            flags=flags)
    except CompilerUnavailable as exc:
        fallback(exc)
        return fn
    return ca.external(fn.name(), str(so))


def compiled_or_interpreted(library_source: Path, names: Sequence[str], sx: Mapping[str, ca.Function], *,
                            flags: str) -> tuple[dict[str, ca.Function], Path | None]:
    """Externals from the compiled library of ``library_source``, or ``sx`` with a fallback warning."""
    try:
        so = compile_library(library_source, flags=flags)
    except CompilerUnavailable as exc:
        fallback(exc, stacklevel=4)
        return dict(sx), None
    return load_externals(so, names), so


def variant_library(fns: ModelFunctions, *, flags: str) -> Path:
    """The compiled library of a variant's Functions (the C :func:`.codegen.write_c` writes for them, into
    :func:`variant_dir`, its file hashes added to the record), built under a cache key that names the variant."""
    record = variant_record(fns.model_hash)
    if record is None:
        raise ValueError(f"model_hash: {fns.model_hash!r} names no variant on record; make one with record_variant")
    folder = variant_dir(record["hash"])
    with writing_cache(cache_dir()), file_lock(folder / ".lock", f"the C of variant {record['hash'][:12]}"):
        staging = Path(tempfile.mkdtemp(dir=folder, prefix=".staging-"))
        try:
            written = write_c(fns, staging)
            names = sorted({*written, *(name.removesuffix(".c") + ".h" for name in written)})
            files = {name: sha256_file(staging / name) for name in names}
            for name in names:
                os.replace(staging / name, folder / name)
        finally:
            shutil.rmtree(staging, ignore_errors=True)
        if record.get("library_files") != files:
            atomic_write(folder / VARIANT_RECORD, json.dumps(record | {"library_files": files}, indent=2) + "\n")
    payload = {"kind": "variant", "variant": record["hash"], "files": files}
    return build_library(payload, [folder / name for name in sorted(written)], VARIANT_LIBRARY, flags=flags)
