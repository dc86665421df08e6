"""The C compiler: which one (``$APEXSEAL_CC``, else ``$CC``, else ``gcc``), the flag sets, and its identity.

A compiled library's cache key includes the compiler's identity (its version line, the machine and, for
``-march=native``, the architecture gcc resolves it to), so a library is only reused for exactly what built it.
The identity is asked of the compiler once per executable and kept in ``<cache>/lib/compilers.json``
(:func:`compiler_identity`).
"""

from __future__ import annotations

import functools
import json
import os
import platform
import re
import shutil
import signal
import subprocess
from collections.abc import Mapping, Sequence
from pathlib import Path
from types import MappingProxyType

from ..derive.cache import cache_dir
from ..files import atomic_write, content_key, read_json_object, sha256_bytes

#: flag setting -> compiler flags (read-only: a measurement's own set goes through :func:`register_flags`).
#: -ffp-contract=off keeps gcc from fusing a*b+c into FMA instructions under -march=native, so compiled results
#: stay those of CasADi's interpreter.
FLAG_SETS: Mapping[str, tuple[str, ...]] = MappingProxyType({
    "quick": ("-O1",),
    "optimised": ("-O3", "-march=native", "-ffp-contract=off"),
})

#: the flag sets :func:`register_flags` named in this process, by name
_REGISTERED: dict[str, tuple[str, ...]] = {}

#: the start of a registered flag set's name
REGISTERED_PREFIX = "flags-"


class CompilerUnavailable(RuntimeError):
    """No working C compiler (missing, or it failed on the generated code)."""


def compiler() -> str:
    return os.environ.get("APEXSEAL_CC") or os.environ.get("CC") or "gcc"


def flag_list(flags: str) -> tuple[str, ...]:
    """The compiler flags of a flag set: one of :data:`FLAG_SETS`, or a name :func:`register_flags` gave."""
    found = FLAG_SETS.get(flags) or _REGISTERED.get(flags)
    if found is None:
        raise ValueError(f"flags must be one of {', '.join(FLAG_SETS)} or a name register_flags gave "
                         f"({', '.join(_REGISTERED) or 'none yet'}), not {flags!r}")
    return found


def register_flags(flags: Sequence[str]) -> str:
    """Name a flag set of one's own (a measurement's: runtime/bench/levers.py) for every function that takes
    ``flags``; returns the project's name when :data:`FLAG_SETS` has the same flags, else ``flags-`` and the start
    of the sha256 of the flags: the same name in every process and on every machine, for the same flags.

    A library's cache key and ``build.json`` hold the flags themselves, so a registered set's libraries are keyed
    like the project's sets'."""
    flags = tuple(flags)
    if not flags:
        raise ValueError("flags: an empty flag set; give at least one compiler option, e.g. ('-O2',)")
    for f in flags:
        if not isinstance(f, str) or not f.startswith("-") or any(c.isspace() for c in f):
            raise ValueError(f"flags: {f!r} is not one compiler option (a string starting with '-', no spaces)")
    for name, known in FLAG_SETS.items():
        if known == flags:
            return name
    name = REGISTERED_PREFIX + sha256_bytes("\0".join(flags).encode())[:12]
    _REGISTERED[name] = flags
    return name


#: every compiler this process runs, while it runs (:func:`stop_all`)
_RUNNING: set = set()


def run_compiler(cmd: Sequence[str], cwd: Path | None = None, running: set | None = None) -> subprocess.CompletedProcess:
    """Run a compiler command to its end; its process is in ``running`` meanwhile (so that an interrupted build
    can stop the compilers it started, see :func:`stop`), and in the process-wide set of :func:`stop_all`."""
    try:
        # a session of its own: stopping it stops the programs it runs (cc1, as), and a terminal's Ctrl-C reaches
        # this process, which stops it
        proc = subprocess.Popen(list(cmd), cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                start_new_session=True)
    except OSError as exc:  # FileNotFoundError, PermissionError
        raise CompilerUnavailable(f"C compiler {cmd[0]!r} cannot be run ({exc.strerror or exc})") from exc
    if running is not None:
        running.add(proc)
    _RUNNING.add(proc)
    try:
        out, err = proc.communicate()
    except BaseException:  # interrupted while waiting (in the main thread): the compiler goes with it
        _kill(proc)
        proc.wait()
        raise
    finally:
        if running is not None:
            running.discard(proc)
        _RUNNING.discard(proc)
    return subprocess.CompletedProcess(list(cmd), proc.returncode, out, err)


def stop(running: set) -> None:
    """Kill the compilers in ``running`` (a build abandoned by a signal: SIGTERM reaches only this process)."""
    for proc in list(running):
        _kill(proc)


def stop_all() -> None:
    """Kill every compiler this process is running, whichever thread started it: for work abandoned by a signal
    while builds run in worker threads, which the signal does not reach (the preload study builds two libraries
    at once)."""
    stop(_RUNNING)


def _kill(proc: subprocess.Popen) -> None:
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except OSError:  # ended meanwhile
        pass


#: the compiler identities probed before, in :func:`lib_root`: ``{identity key: identity}``
IDENTITIES = "compilers.json"


def _cpu_signature() -> str:
    """What ``-march=native`` resolves from: the CPU's vendor, family, model and feature flags (a cache shared by
    machines with other CPUs gets other keys)."""
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return platform.processor() or "unknown"
    keep = ("vendor_id", "cpu family", "model", "flags")
    return sha256_bytes("\n".join(sorted({ln for ln in text.splitlines() if ln.startswith(keep)})).encode())


def identity_key(cc: str, flags: tuple[str, ...]) -> str | None:
    """The key under which the identity of compiler ``cc`` with ``flags`` is kept: its executable (resolved path,
    size, modification time: an upgrade replaces it), the flags, the machine and, for ``-march=native``, the CPU;
    None when ``cc`` is not an executable found on the PATH."""
    path = shutil.which(cc)
    if path is None:
        return None
    real = os.path.realpath(path)
    try:
        st = os.stat(real)
    except OSError:
        return None
    cpu = _cpu_signature() if "-march=native" in flags else None
    return content_key([real, st.st_size, st.st_mtime_ns, list(flags), platform.machine(), cpu])


def _known_identities() -> dict:
    return read_json_object(lib_root() / IDENTITIES) or {}


@functools.lru_cache(maxsize=8)
def compiler_identity(cc: str, flags: tuple[str, ...]) -> str:
    """The compiler's version line (+ the architecture -march=native means on this machine), part of every library's
    cache key. Probing runs the compiler twice (10-20 ms on the start-up of every process that loads a library),
    so a working compiler's identity is kept in :data:`IDENTITIES` under :func:`identity_key` and read back while
    its executable is unchanged; a compiler that fails is probed again every time."""
    key = identity_key(cc, flags)
    known = _known_identities() if key is not None else {}
    if isinstance(known.get(key), str):
        return known[key]
    ident = _probe_identity(cc, flags)
    if key is not None:
        try:
            lib_root().mkdir(parents=True, exist_ok=True)
            atomic_write(lib_root() / IDENTITIES, json.dumps(_known_identities() | {key: ident}, indent=1,
                                                            sort_keys=True) + "\n")
        except OSError:  # a read-only cache: probed again next time
            pass
    return ident


def _probe_identity(cc: str, flags: tuple[str, ...]) -> str:
    """:func:`compiler_identity` asked of the compiler itself."""
    out = run_compiler([cc, "--version"])
    if out.returncode != 0 or not out.stdout:
        raise CompilerUnavailable(f"C compiler {cc!r} does not work ({(out.stderr or '').strip()[:200]})")
    ident = out.stdout.splitlines()[0].strip() + " | " + platform.machine()
    if "-march=native" in flags:
        target = run_compiler([cc, "-march=native", "-Q", "--help=target"])
        arch = re.search(r"^\s*-march=\s+(\S+)", target.stdout or "", re.M)
        ident += " | march=" + (arch.group(1) if arch else "native-unknown")
    return ident


def lib_root() -> Path:
    return cache_dir() / "lib"
