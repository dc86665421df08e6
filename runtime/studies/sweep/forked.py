"""Imported by the fork server that starts a sweep's Dask workers (execute._quiet_forkserver), before it forks any.

A worker whose cluster's start a signal abandoned may be forked just before its parent, the sweep, leaves; it then
fails to read what it was to run (the parent's semaphores are gone: ``FileNotFoundError``, or its pipe is closed:
``EOFError``) and printed that traceback after the sweep's own message. Those two failures, and only while the
worker reads its process object (multiprocessing's ``spawn._main``), end the worker silently; every other error is
printed as before.
"""

from __future__ import annotations

import sys
import traceback

_printed = sys.excepthook


def _parent_left(kind, value, tb) -> bool:
    """True for the failure of a worker whose parent left before it read its process object."""
    if not issubclass(kind, FileNotFoundError | EOFError):
        return False
    frames = traceback.extract_tb(tb)
    return any(f.name == "_main" and f.filename.endswith("spawn.py") for f in frames)


def _excepthook(kind, value, tb) -> None:
    if not _parent_left(kind, value, tb):
        _printed(kind, value, tb)


sys.excepthook = _excepthook
