"""Where a command's wall time goes: named stages timed back to back (``apexseal simulate --timings``).

Timing a stage is two ``time.perf_counter()`` calls, so the command always
records its stages and prints them only when asked. ``startup`` is the time from
the process's start (read from /proc on Linux; not measured elsewhere) to the
command's first line: the interpreter and the CLI's own imports.
"""

from __future__ import annotations

import contextlib
import json
import os
import time


def process_age() -> float | None:
    """Seconds since this process started (Linux: /proc/self/stat against /proc/uptime), else None."""
    try:
        with open("/proc/self/stat") as fh:
            fields = fh.read().rsplit(")", 1)[1].split()
        with open("/proc/uptime") as fh:
            uptime = float(fh.read().split()[0])
        return uptime - int(fields[19]) / os.sysconf("SC_CLK_TCK")  # field 22 of stat: starttime in clock ticks
    except (OSError, ValueError, IndexError):
        return None


class Stopwatch:
    """Stages in the order they ran, each with its wall seconds."""

    def __init__(self):
        self.t0 = time.perf_counter()
        age = process_age()
        self.stages: dict[str, float] = {"startup": age} if age is not None else {}

    @contextlib.contextmanager
    def stage(self, name: str):
        w0 = time.perf_counter()
        try:
            yield
        finally:
            self.stages[name] = self.stages.get(name, 0.0) + time.perf_counter() - w0

    def add(self, name: str, seconds: float) -> None:
        self.stages[name] = self.stages.get(name, 0.0) + seconds

    def split(self, inner: str, parts: dict[str, float]) -> None:
        """Replace stage ``inner`` by ``parts`` (timed inside it) and what is left of it (``<inner> (other)``)."""
        total = self.stages.pop(inner, 0.0)
        rest = total - sum(parts.values())
        for k, v in parts.items():
            self.add(k, v)
        if rest > 0.0005:
            self.add(f"{inner} (other)", rest)

    @property
    def total(self) -> float:
        """Wall seconds from the process start (or the stopwatch's start) to now."""
        return time.perf_counter() - self.t0 + self.stages.get("startup", 0.0)

    def report(self) -> str:
        total = self.total
        width = max(len(k) for k in self.stages) if self.stages else 8
        lines = [f"timings (wall, s; total {total:.2f} s from process start):"]
        lines += [f"  {k:<{width}} {v:8.3f}  {100 * v / total:5.1f} %" for k, v in self.stages.items()]
        lines += [f"  {'unaccounted':<{width}} {total - sum(self.stages.values()):8.3f}",
                  "timings-json " + json.dumps({"stages": self.stages, "total_s": total})]
        return "\n".join(lines)
