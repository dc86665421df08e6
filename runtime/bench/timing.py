"""CPU timing: warm-up, repeats, median, CPU budgets, and the machine a result was measured on.

CPU time is ``time.process_time()`` of this process (C compilers run as child
processes and are never inside a timed call). Every point is one warm-up run
(whose result is the one analysed) followed by timed samples; a sample is a
batch of back-to-back runs lasting at least ``min_sample_s`` (on this shared VM
single short calls were seen to come out in 4 ms steps), divided by the batch
size. A warm-up slower than ``slow_run_s`` gets fewer samples, and that count is
kept with the point. A run that exceeds its CPU budget is stopped (SIGVTALRM, checked
between Python bytecodes, so it interrupts Python loops and scipy, and CasADi
calls when they return) and recorded as a failure.
"""

from __future__ import annotations

import contextlib
import math
import os
import platform
import signal
import statistics
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path


class BudgetExceeded(RuntimeError):
    """A run used more CPU time than its budget."""


@contextlib.contextmanager
def cpu_budget(seconds: float | None):
    """Raise :class:`BudgetExceeded` inside the block once it has used ``seconds`` of CPU (main thread only)."""
    if not seconds or threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum, frame):
        raise BudgetExceeded(f"CPU budget of {seconds:g} s exceeded")

    old = signal.signal(signal.SIGVTALRM, handler)
    signal.setitimer(signal.ITIMER_VIRTUAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_VIRTUAL, 0)
        signal.signal(signal.SIGVTALRM, old)


@dataclass
class Timing:
    """CPU (and wall) seconds of the timed runs of one point."""

    cpu_s: list[float] = field(default_factory=list)
    wall_s: list[float] = field(default_factory=list)
    warmup_cpu_s: float | None = None
    warmup_wall_s: float | None = None
    batch: int = 1  # runs per timed sample (cpu_s and wall_s are per run)
    #: "median of n samples after a warm-up", or "one run" for slow runs
    basis: str = ""

    @property
    def median(self) -> float | None:
        if self.cpu_s:
            return statistics.median(self.cpu_s)
        return self.warmup_cpu_s

    def as_dict(self) -> dict:
        d = asdict(self)
        d["median_cpu_s"] = self.median
        d["min_cpu_s"] = min(self.cpu_s) if self.cpu_s else self.warmup_cpu_s
        d["max_cpu_s"] = max(self.cpu_s) if self.cpu_s else self.warmup_cpu_s
        d["n_timed"] = len(self.cpu_s)
        return d


#: most runs in one timed sample
MAX_BATCH = 1000


def timed(fn: Callable[[], object], budget_s: float | None = None) -> tuple[object, float, float]:
    """(result, CPU s, wall s) of one call."""
    with cpu_budget(budget_s):
        c0, w0 = time.process_time(), time.perf_counter()
        out = fn()
        c1, w1 = time.process_time(), time.perf_counter()
    return out, c1 - c0, w1 - w0


def measure(fn: Callable[[], object], *, repeats: int, slow_run_s: float, budget_s: float | None,
            min_sample_s: float = 0.2) -> tuple[object, Timing]:
    """Warm-up run (its result is returned), then timed samples: ``repeats`` if the warm-up took less than
    ``slow_run_s``, 2 if less than 5x that, none (the warm-up is the timing) otherwise. Exceptions propagate."""
    out, c, w = timed(fn, budget_s)
    t = Timing(warmup_cpu_s=c, warmup_wall_s=w)
    n = repeats if c < slow_run_s else (min(2, repeats) if c < 5 * slow_run_s else 0)
    # the batch is sized on the warm-up's wall time too: CPU time can come out as 0 for a short call (it is
    # accounted in ticks on a busy VM), which would otherwise ask for 200000 runs per sample
    t.batch = k = min(MAX_BATCH, max(1, math.ceil(min_sample_s / max(c, w, 1e-5)))) if n else 1

    def batch():
        for _ in range(k):
            fn()

    for _ in range(n):
        _, c, w = timed(batch, budget_s * k if budget_s else None)
        t.cpu_s.append(c / k)
        t.wall_s.append(w / k)
    t.basis = f"median of {n} samples of {k} run(s) after a warm-up" if n else "one run (slow: no repeats)"
    return out, t


def warm_median(fn: Callable[[], object], repeats: int) -> tuple[object, float]:
    """(the warm-up call's result, the median CPU seconds of ``repeats`` further calls): :func:`measure` one call
    per sample, without a budget."""
    out, t = measure(fn, repeats=repeats, slow_run_s=math.inf, budget_s=None, min_sample_s=0.0)
    return out, t.median


# ------------------------------------------------------------------ the machine and the software


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def _git(*args: str) -> str | None:
    try:
        out = subprocess.run(["git", *args], capture_output=True, text=True, check=False,
                             cwd=Path(__file__).resolve().parent)
    except OSError:
        return None
    return out.stdout.strip() if out.returncode == 0 else None


def _version(module: str) -> str | None:
    try:
        from ...versions import distribution_version

        return distribution_version(module)
    except Exception:  # noqa: BLE001
        return None


def machine_info() -> dict:
    """Machine, load, package versions, compiler and git revision, for the JSON and the table."""
    from ...generated.compiler import FLAG_SETS, compiler

    cc = compiler()
    try:
        cc_version = subprocess.run([cc, "--version"], capture_output=True, text=True, check=False).stdout.splitlines()[0]
    except (OSError, IndexError):
        cc_version = None
    status = _git("status", "--porcelain", "--untracked-files=no")
    modified = [line.split(None, 1)[-1] for line in (status or "").splitlines()]
    return {
        "date": time.strftime("%Y-%m-%d %H:%M:%S %Z"),
        "cpu": _cpu_model(),
        "cores": os.cpu_count(),
        "load_average_at_start": list(os.getloadavg()),
        "platform": platform.platform(),
        "python": sys.version.split()[0],
        "packages": {p: _version(p) for p in ("apexseal", "casadi", "numpy", "scipy", "sympy", "matplotlib")},
        "compiler": {"cc": cc, "version": cc_version, "flag_sets": {k: list(v) for k, v in FLAG_SETS.items()}},
        "git": {"commit": _git("rev-parse", "HEAD"), "dirty": bool(status) if status is not None else None,
                "modified": modified[:20]},
        "threads": {k: os.environ.get(k) for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")},
        "timer": "time.process_time() of this process around one call; compilers are child processes, never timed",
    }
