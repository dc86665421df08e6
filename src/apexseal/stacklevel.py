"""Where a warning about the user's input points: at the user's own line, however deep in apexseal it was raised."""

from __future__ import annotations

import sys


def user_stacklevel() -> int:
    """The ``stacklevel`` for :func:`warnings.warn`, called from the function that warns, that names the first frame
    outside apexseal: the line of the script or notebook that loaded the scene or started the run, whichever of
    apexseal's functions it called (a fixed level named that line through one entry point and its caller through
    another, or Python's own ``sys:1``)."""
    frame, level = sys._getframe(1), 1
    while frame is not None and _inside(frame.f_globals.get("__name__", "")):
        frame, level = frame.f_back, level + 1
    return level


def _inside(module: str) -> bool:
    return module == "apexseal" or module.startswith("apexseal.")
