"""The condition of the tests that draw figures in a forked process."""

from __future__ import annotations

import os
import sys

import pytest

from apexseal.runtime.results import figure_job


def require_fork() -> None:
    """Skip where forking is not available (not Linux); on Linux a thread left running by an earlier test in this
    process would make the code draw without forking, so it fails the test, naming the thread, instead of letting
    the test skip silently (as it did under pytest-xdist after a sweep's LocalCluster)."""
    if not (sys.platform.startswith("linux") and hasattr(os, "fork")):
        pytest.skip("forking is Linux-only here")
    assert figure_job.can_fork(), f"threads left running by earlier tests block forking: {figure_job.other_threads()}"
