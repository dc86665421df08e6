"""Progress of the long stages (derivation, code generation, compilation, integration) on stderr.

Stages report through the ``apexseal`` logger at INFO level: ``stage("compiling the integrator")`` logs the
start and, at the end, the elapsed time. Nothing is printed unless a handler is installed: the command line
installs one (``-q`` leaves it out), the API with ``simulate(..., progress=True)`` or :func:`enabled`.
"""

from __future__ import annotations

import logging
import sys
import threading
import time
from contextlib import contextmanager

log = logging.getLogger("apexseal")


@contextmanager
def stage(what: str):
    """Report ``what ...`` at the start and ``what: done in 1.2 s`` at the end, or ``what: abandoned after 1.2 s``
    when an interruption (or, naming it, an error that no signal caused) leaves it (used on the cold paths only: a
    cached derivation or library is silent)."""
    t0 = time.perf_counter()
    log.info("%s ...", what)
    try:
        yield
    except BaseException as exc:
        from .signals import StopSignals

        # a signal caught meanwhile is the cause (a compiler it stopped fails with CompilerUnavailable)
        why = "" if isinstance(exc, KeyboardInterrupt) or StopSignals.pending() else f" ({type(exc).__name__})"
        log.info("%s: abandoned after %.1f s%s", what, time.perf_counter() - t0, why)
        raise
    log.info("%s: done in %.1f s", what, time.perf_counter() - t0)


def announce(message: str) -> None:
    """One progress line (e.g. "compiling the erk integrator (first use; cached afterwards) ...")."""
    log.info("%s", message)


_handler: logging.Handler | None = None


def enable(on: bool = True) -> None:
    """Install (or remove) the stderr handler of the ``apexseal`` logger at INFO level."""
    global _handler
    if on and _handler is None:
        _handler = logging.StreamHandler(sys.stderr)
        _handler.setFormatter(logging.Formatter("apexseal: %(message)s"))
        log.addHandler(_handler)
        log.setLevel(logging.INFO)
        log.propagate = False
    elif not on and _handler is not None:
        log.removeHandler(_handler)
        _handler = None
        log.propagate = True


@contextmanager
def enabled(on: bool):
    """Progress reports on stderr inside the block when ``on`` (nothing changes when off or already on)."""
    if not on or _handler is not None:
        yield
        return
    enable(True)
    try:
        yield
    finally:
        enable(False)


#: this thread's listeners of a run's progress (:func:`following_runs`): a Dask worker runs points in its own threads
_following = threading.local()


@contextmanager
def following_runs(listener):
    """Inside the block, ``listener(done, total)`` is called in this thread after each integrator call of a run,
    with the revolutions done (a fraction within a revolution) and asked (a sweep shows its long points' progress
    this way, runtime/studies/sweep/point.py)."""
    stack = _following.__dict__.setdefault("listeners", [])
    stack.append(listener)
    try:
        yield
    finally:
        stack.remove(listener)


def advanced(done: float, total: int) -> None:
    """A run of this thread has done ``done`` of its ``total`` revolutions: tell the listeners of :func:`following_runs`."""
    for listener in getattr(_following, "listeners", ()):
        listener(done, total)


#: s between two lines of a progress bar in a log (stderr not a terminal)
LOG_INTERVAL = 10.0


class LogLines:
    """A log's stream for a tqdm bar: each redraw a line of its own. tqdm redraws a bar in place, starting each
    redraw with a carriage return, which a log file keeps: a run's log held one line of every redraw."""

    def __init__(self, stream) -> None:
        self.stream = stream

    def write(self, text: str) -> None:
        for line in text.replace("\r", "\n").split("\n"):
            if line.strip():  # the spaces that clear a bar's last redraw, the bare returns between redraws
                self.stream.write(line.rstrip() + "\n")

    def flush(self) -> None:
        self.stream.flush()


def bar_output() -> dict:
    """tqdm's ``file`` and ``mininterval`` for a bar on stderr: on a terminal a bar redrawn in place (at most every
    0.1 s); in a log a line at most every :data:`LOG_INTERVAL` s (:class:`LogLines`)."""
    if sys.stderr.isatty():
        return {"file": sys.stderr, "mininterval": 0.1}
    return {"file": LogLines(sys.stderr), "mininterval": LOG_INTERVAL}
