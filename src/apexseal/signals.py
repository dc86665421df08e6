"""SIGINT, SIGTERM and SIGHUP during a run: noted, never raised inside a CasADi call, acted on between calls.

Python runs a signal handler between bytecodes, and CasADi polls for pending signals inside its own calls: a
``KeyboardInterrupt`` raised there surfaces as a CasADi error (``NotImplementedError: Wrong number or type of
arguments``, ``SystemError: DM.__array__ returned a result with an exception set``) and loses the run. Inside
:class:`StopSignals` both signals only set a flag (and tell the running engine to stop at its next check, see
``Engine.deadline``); the run loop reads the flag between integrator calls, keeps every completed revolution and
ends with status ``interrupted``. A second signal while the result is written is noted too, so the writing
finishes (the folder is committed as one unit, runtime/results/folder.py). A signal that the process was started
with ignored (a job a shell put in the background ignores SIGINT, so that Ctrl-C in the terminal leaves it running)
is not caught: it stays ignored, as Python itself leaves it.

Outside the main thread signals cannot be caught: there the context catches nothing and Ctrl-C raises
``KeyboardInterrupt`` as usual (the run loop still catches it between calls). What stops the work there is a
:meth:`StopSignals.request` from another thread (a sweep's point on a Dask worker, stopped by its sweep): the
instances nested in that thread share its outermost one, as those of the main thread share the active one.
"""

from __future__ import annotations

import contextlib
import math
import signal
import threading

#: the signals that end a process as ``kill`` does (a library call redelivers them once its result is kept): what
#: ``kill``, ``timeout`` and batch schedulers send, and the hang-up of a terminal or ssh session that closed
ENDING = (signal.SIGTERM,) + ((signal.SIGHUP,) if hasattr(signal, "SIGHUP") else ())
#: the signals a run catches: Ctrl-C, and the ending ones
CAUGHT = (signal.SIGINT,) + ENDING


def _main() -> bool:
    """True in the main thread, the one Python runs signal handlers in."""
    return threading.current_thread() is threading.main_thread()


#: per thread other than the main one: ``outer``, its outermost :class:`StopSignals` (which nested ones share)
_thread = threading.local()


class StopSignals:
    """Context manager: while inside, SIGINT/SIGTERM/SIGHUP are recorded in ``received`` instead of raising.

    Nested uses share the outermost instance (the CLI wraps run and save, the run loop wraps itself).
    """

    _active: StopSignals | None = None

    def __init__(self, *, raising: bool = False, redeliver_term: bool = False) -> None:
        #: when this is the outermost instance, end the process with a SIGTERM (or SIGHUP) it caught once its block
        #: is left (the run's result kept): for a library call (``apexseal.simulate``), so that a script looping over
        #: runs stops as a batch scheduler asks, not only its current run (the CLI exits with 143 or 129 itself)
        self.redeliver_term = redeliver_term
        #: what was kept, said on stderr before a redelivered signal ends the process (set by the library call)
        self.farewell = ""
        #: also raise ``KeyboardInterrupt`` (after noting the signal) while True: for work that a signal abandons
        #: wherever it is, IPOPT's iterations among it (a study; the caller tells an interruption from the error
        #: it turned into by ``requested``), and that writes what it had once this is set back to False
        self.raising = raising
        self.received: list[int] = []
        #: the signals the operating system delivered (not those :meth:`request` was asked for): only these are
        #: redelivered
        self.delivered: list[int] = []
        self._previous: dict[int, object] = {}
        self._engines: list = []
        self._outer: StopSignals | None = None

    def __enter__(self) -> StopSignals:
        if StopSignals._active is not None:  # nested (in another thread too: it sees the main thread's signals)
            self._outer = StopSignals._active
            return self._outer
        if not _main():  # signals reach the main thread only: an instance here catches none and is never the active
            outer = getattr(_thread, "outer", None)  # one, so that the main thread's, entered later, still catches
            if outer is not None:  # them; the thread's nested instances share its outermost (request() reaches them)
                self._outer = outer
                return outer
            _thread.outer = self
            return self
        for s in CAUGHT:
            if signal.getsignal(s) is signal.SIG_IGN:  # ignored by whoever started the process (a shell's
                continue  # background job, a runner): it stays ignored, as Python leaves an ignored SIGINT
            self._previous[s] = signal.signal(s, self._note)
        StopSignals._active = self
        return self

    def __exit__(self, *exc) -> None:
        if self._outer is None and getattr(_thread, "outer", None) is self:
            _thread.outer = None
        if self._outer is not None or StopSignals._active is not self:
            return
        for s, handler in self._previous.items():
            signal.signal(s, handler)
        caught = set(self._previous)
        self._previous.clear()
        StopSignals._active = None
        ending = [s for s in self.delivered if s in ENDING and s in caught]
        if self.redeliver_term and ending and signal.getsignal(ending[0]) not in (signal.SIG_IGN, None):
            if self.farewell:  # the process ends without a traceback: one line says what was kept
                import sys

                try:
                    print(f"apexseal: {signal.Signals(ending[0]).name}: {self.farewell}; ending the process",
                          file=sys.stderr, flush=True)
                except (OSError, ValueError):  # no terminal any more (a SIGHUP), a closed pipe: the signal all the same
                    pass
            signal.raise_signal(ending[0])  # its handler now: by default the process ends, as it was asked

    def _note(self, signum, frame) -> None:
        self.delivered.append(signum)
        self.request(signum)
        if self.raising:
            raise KeyboardInterrupt

    def request(self, signum: int = signal.SIGTERM) -> None:
        """Stop the work inside as the signal ``signum`` would: noted, and the watched engines stop at their next
        deadline check. From another thread too: how a sweep stops its points on Dask workers, where no signal
        reaches the thread that runs them (runtime/studies/sweep/point.py)."""
        self.received.append(signum)
        for engine in list(self._engines):  # engines that check their deadline inside a call stop at the next check
            engine.deadline = -math.inf

    def ignore_after(self) -> None:
        """On leaving, ignore further SIGINT/SIGTERM instead of restoring the previous handlers: for a process that
        exits once its interrupted run is written (the CLI), so that a Ctrl-C pressed again while it reports and
        exits cannot turn its exit code 130 into a death by signal. A handler that does nothing, not SIG_IGN: a
        command run in a process that goes on (``apexseal.cli.main`` from Python) would leave it ignoring the
        signals, and its later runs, and the processes it starts, leave an ignored signal ignored: the command line
        gives them back, or ignores them outright as the process exits (:func:`command_scope`)."""
        target = self._outer or self
        for s in target._previous:
            target._previous[s] = _unheeded

    @classmethod
    def raise_pending(cls) -> None:
        """Raise ``KeyboardInterrupt`` when the active instance has caught a signal: for work that failed, maybe
        because of it (a compiler that got the terminal's Ctrl-C), and is to be abandoned, not reported."""
        if cls.pending():
            raise KeyboardInterrupt

    @classmethod
    def pending(cls) -> bool:
        """True when the active instance (of the main thread) has caught a signal: for a search that stops at one."""
        return _main() and cls._active is not None and cls._active.requested

    @classmethod
    @contextlib.contextmanager
    def abandoning(cls):
        """Work with nothing to keep yet (deriving, generating or compiling a model): inside the block a signal
        caught by the active :class:`StopSignals` raises ``KeyboardInterrupt`` at once, as does one it caught
        before the block, instead of letting the work run to its end. Its caches are written atomically, so
        abandoning it leaves nothing half done. Without an active instance the block runs as it is (a
        signal acts as Python's default handler makes it)."""
        active = cls._active if _main() else None  # another thread's work: left to run as it is
        if active is None:
            yield
            return
        cls.raise_pending()
        raising, active.raising = active.raising, True
        try:
            yield
        finally:
            active.raising = raising

    def watch(self, engine) -> None:
        """Stop ``engine`` at its next deadline check when a signal arrives."""
        if engine is not None:
            self._engines.append(engine)

    @contextlib.contextmanager
    def watching(self, engine):
        """:meth:`watch` ``engine`` inside the block only (an engine made for one search: the outermost instance,
        which nested ones share, would keep it for the whole run otherwise)."""
        self.watch(engine)
        try:
            yield engine
        finally:
            if engine in self._engines:
                self._engines.remove(engine)

    @property
    def requested(self) -> bool:
        return bool(self.received)

    def reason(self) -> str:
        """The stop reason of a run that a signal ended."""
        return f"interrupted by {self.sender()}; every completed integrator call is kept"

    def sender(self) -> str:
        """Who stopped the work, in words: ``the user (Ctrl-C, SIGINT)`` or ``SIGTERM (kill, ...)``."""
        first = self.received[0]
        if first == signal.SIGINT:
            return "the user (Ctrl-C, SIGINT)"
        if first == getattr(signal, "SIGHUP", None):
            return "SIGHUP (its terminal or session closed)"
        return f"{signal.Signals(first).name} (kill, timeout or a batch scheduler)"

    def exit_code(self) -> int:
        """The shell's convention for a process ended by a signal: 128 + its number."""
        return 128 + int(self.received[0]) if self.received else 0


def interactive() -> bool:
    """A session a person types into: the Python prompt (``python -i`` too), IPython, a Jupyter kernel."""
    import sys

    if getattr(sys, "ps1", None) or sys.flags.interactive:
        return True
    ipython = sys.modules.get("IPython")  # imported by a library is not a session: a running shell is
    return ipython is not None and getattr(ipython, "get_ipython", lambda: None)() is not None


class RunInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped ``apexseal.simulate``, ``apexseal.resume`` or a study of the library (``optimise_preload``,
    ``run_sweep``, ``calibrate``) in a script: raised once what it computed is kept (and written, with ``out``),
    so that the script stops as Ctrl-C asks instead of going on to its next design with a partial result;
    ``result`` is that run (status ``interrupted``) or the study's report (its stopped state said in it). A
    ``KeyboardInterrupt``: a script that does not catch it ends as Ctrl-C ends it."""

    def __init__(self, message: str, result) -> None:
        super().__init__(message)
        self.result = result


def _unheeded(signum, frame) -> None:
    """A signal handler that does nothing (:meth:`StopSignals.ignore_after`)."""


@contextlib.contextmanager
def command_scope(exiting: bool):
    """Around a command of the command line: the signals it stopped heeding (:meth:`StopSignals.ignore_after`) get
    back the handlers they had before it in a process that goes on (the command run from Python, click's test
    runner: a Ctrl-C there stops the next run again), and are ignored outright in one that exits with the
    command's code (``exiting``: the console script). Python's finalization sets a signal with a Python handler
    back to its default action (a Ctrl-C then would end the process by the signal, not with its exit code 130) and
    leaves an ignored one ignored."""
    before = {s: signal.getsignal(s) for s in CAUGHT} if _main() else {}
    try:
        yield
    finally:
        for s, handler in before.items():
            if signal.getsignal(s) is _unheeded:
                signal.signal(s, signal.SIG_IGN if exiting else handler)


@contextlib.contextmanager
def handling(signum: int, handler):
    """``handler`` for ``signum`` inside the block, the previous one restored after it (nothing changes outside the
    main thread, where signals cannot be handled)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signum, handler)
    try:
        yield
    finally:
        signal.signal(signum, previous)


@contextlib.contextmanager
def held(signum: int):
    """``signum`` blocked in this thread inside the block, and delivered (to the handler in force) when the block
    ends if it arrived meanwhile: not lost (a thread started before the block, which does not block it, takes it at
    once, for the same Python handler, run by this thread). What the block starts inherits the block: the threads
    it creates keep the signal blocked for their life, and the processes they start keep it blocked after
    ``exec``, so never see it (a Dask LocalCluster's workers, started from its event loop's thread: a terminal's
    Ctrl-C reaches the whole process group, and each worker printed a ``KeyboardInterrupt`` traceback).
    Where threads cannot block signals (no ``pthread_sigmask``: Windows) the signal is ignored inside the block
    instead, which those processes inherit too (Python keeps an ignored SIGINT ignored), and one that arrives
    there is lost. Nothing changes outside the main thread, where signals cannot be handled."""
    if not _main():
        yield
        return
    if not hasattr(signal, "pthread_sigmask"):
        with handling(signum, signal.SIG_IGN):
            yield
        return
    before = signal.pthread_sigmask(signal.SIG_BLOCK, {signum})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)  # a pending one is delivered now

