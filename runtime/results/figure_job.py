"""Drawing a run's figures beside the writing of its result: a second process on a second core.

Each figure costs Agg a few tenths of a second of layout and text, whatever the run's length, so the four
figures of a default run take longer than its integration. :class:`FigureJob` forks a child process (it
inherits the result: nothing is copied or pickled), and the two share the figures out as they go: each takes the
next figure not yet taken, in :data:`ORDER` (costliest first), by creating its claim file (``O_CREAT | O_EXCL``,
atomic) in a private temporary folder. So the child draws while this process writes summary.json and the rest,
and whichever process finishes a figure first takes the next one: the longest figure never waits behind two
others, whatever the machine. Figures are written atomically into the result's staging folder, so whichever
process draws a figure, the folder is the same.

A figure the child did not write (it failed, or was killed) is drawn by this process, so a failure of the
child costs time, never a figure. Where forking is not safe (not Linux, or other threads are running: a
forked child could inherit a lock held by one of them; the idle ones of :data:`HARMLESS_THREADS` excepted)
everything is drawn here, in order.
"""

from __future__ import annotations

import os
import shutil
import signal
import sys
import tempfile
import threading
import traceback
from pathlib import Path

from .result import SimulationResult
from .saved_figures import figure_files, write_figure

#: the order in which the two processes take the figures: costliest first (docs/performance.md, one process:
#: Fig. 13's seven panels, Fig. 12's three polar panels, then the gas figures, Fig. 14, the modes), so that the
#: last figure to finish is a short one
ORDER = ("fig13_forces.png", "fig12_displacements.png", "pv_diagram.png", "fig11_pressures.png",
         "fig14_housing_spectrum.png", "mode_timeline.png")


#: threads that may run at the fork, by class name or name prefix: tqdm's monitor of progress bars (it only takes
#: tqdm's own lock, which the child never uses); the worker of dask.distributed's offload executor, which stays,
#: idle, after a sweep's LocalCluster is closed (the child runs no dask code)
HARMLESS_THREADS = ("TMonitor", "Dask-Offload")


def other_threads() -> list[str]:
    """The names of the threads running besides the main thread and the harmless ones."""
    return [t.name for t in threading.enumerate() if t is not threading.main_thread()
            and not any(type(t).__name__ == h or t.name.startswith(h) for h in HARMLESS_THREADS)]


def reap(pid: int | None, kill: bool = False) -> None:
    """Wait for the child process ``pid`` (None: nothing to wait for), killed first if ``kill``; a child that is
    gone already is not an error."""
    if pid is None:
        return
    try:
        if kill:
            os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
    except (ProcessLookupError, ChildProcessError):
        pass


def can_fork() -> bool:
    """True where a child process can be forked safely: Linux, no other thread running (but harmless ones)."""
    return sys.platform.startswith("linux") and hasattr(os, "fork") and not other_threads()


class FigureJob:
    """The figures of ``result`` being drawn into ``folder``: :meth:`start`, other work, then :meth:`finish`."""

    def __init__(self, result, folder: str | Path, ports: dict | None = None, dpi: int = 100,
                 fork: bool | None = None, frames: dict | None = None) -> None:
        self.result, self.folder, self.ports, self.dpi = result, Path(folder), ports, dpi
        self.frames = frames or {}  # figure kind -> a frame built ahead (figures.frames_ahead)
        self.files = figure_files(result)
        self.fork = can_fork() if fork is None else fork and can_fork()
        self.pid: int | None = None
        self.claims: Path | None = None

    def start(self) -> FigureJob:
        """Fork the child that takes figures in :data:`ORDER` (matplotlib is imported first, once, for both)."""
        self.folder.mkdir(parents=True, exist_ok=True)
        if not self.fork or len(self.files) < 2:
            return self
        import matplotlib.figure  # noqa: F401  (imported before the fork: the child inherits it)

        self.claims = Path(tempfile.mkdtemp(prefix="apexseal-figure-claims-"))
        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid == 0:  # the child: draw, then leave without running the parent's exit handlers
            code = 1
            try:
                self._draw_claimed()
                code = 0
            except BaseException:
                traceback.print_exc()
            finally:
                os._exit(code)
        self.pid = pid
        return self

    def _claim(self, name: str) -> bool:
        """True if this process takes figure ``name`` (always, without a child)."""
        if self.claims is None:
            return True
        try:
            os.close(os.open(self.claims / name, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
        except FileExistsError:
            return False
        return True

    def _draw_claimed(self) -> None:
        order = sorted(self.files, key=lambda n: ORDER.index(n) if n in ORDER else len(ORDER))
        for name in order:
            if self._claim(name):
                kind = self.files[name]
                write_figure(self.result, self.folder, name, kind, self.ports, self.dpi, self.frames.get(kind))

    def _end(self, kill: bool) -> None:
        """Wait for the child (killed first if ``kill``) and remove the claims."""
        reap(self.pid, kill)
        self.pid = None
        if self.claims is not None:
            shutil.rmtree(self.claims, ignore_errors=True)
            self.claims = None

    def cancel(self) -> None:
        """Stop the child, if any, and wait for it (the result is not being written after all)."""
        self._end(kill=True)

    def finish(self) -> list[Path]:
        """Draw the figures the child has not taken, wait for it, draw any it did not write; the paths in the
        order of :func:`.saved_figures.figure_files`."""
        try:
            self._draw_claimed()
        except BaseException:
            self.cancel()
            raise
        self._end(kill=False)
        return self.draw_missing()  # the child failed or was killed: its figures are drawn here

    def draw_missing(self) -> list[Path]:
        """Draw, in this process, every figure not in the folder yet; the paths of all of them."""
        for name in self.files:
            if not (self.folder / name).is_file():
                write_figure(self.result, self.folder, name, self.files[name], self.ports, self.dpi)
        return [self.folder / n for n in self.files]


def write_figures(result: SimulationResult, folder: str | Path, ports: dict | None = None, dpi: int = 100,
                  *, fork: bool = False) -> list[Path]:
    """Draw the four figures of a run (six with the chamber gas model: Fig. 11 pressures and the p-V diagram)
    and save them as PNG files in ``folder`` (created if missing). ``fork=True`` draws some of them in a second
    process (:class:`.figure_job.FigureJob`; ``apexseal simulate`` starts one before it writes the result)."""
    return FigureJob(result, folder, ports, dpi, fork=fork).start().finish()
