"""How many cores this process may run on: what the parallel parts (compilations, sweeps, the preload study's
threaded maps) size their pools by."""

from __future__ import annotations

import os

#: the most worker processes a sweep's LocalCluster may be asked for (``--workers``, ``run_sweep(workers=...)``)
MAX_WORKERS = 4096


def available_cores() -> int:
    """The cores this process may be scheduled on (its CPU affinity, where the system reports it; else the
    machine's count), at least 1."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return os.cpu_count() or 1


def parallel_threads(n: int) -> int:
    """Workers for ``n`` independent tasks (compilations, integrations): one per core this process may run on, at
    most ``n``, at least 1."""
    return max(1, min(n, available_cores()))
