"""apexseal.cores: the cores a process may run on, which the parallel parts size their pools by."""

from __future__ import annotations

import os

from apexseal import cores
from apexseal.cores import parallel_threads


def test_cores_follow_the_affinity_and_else_the_machine(monkeypatch):
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 3}, raising=False)
    assert cores.available_cores() == 2
    assert parallel_threads(8) == 2 and parallel_threads(1) == 1
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: set(), raising=False)
    assert cores.available_cores() == 1
    monkeypatch.delattr(os, "sched_getaffinity", raising=False)
    monkeypatch.setattr(os, "cpu_count", lambda: 6)
    assert cores.available_cores() == 6 and parallel_threads(4) == 4
    monkeypatch.setattr(os, "cpu_count", lambda: None)
    assert cores.available_cores() == 1
