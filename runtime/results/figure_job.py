"""Drawing a run's figures beside the writing of its result: a second process on a second core.

Each figure costs Agg a few tenths of a second of layout and text, whatever the run's length, so the four
figures of a default run take longer than its integration. :class:`FigureJob` forks a child process (it
inherits the result: nothing is copied or pickled) that draws the larger figures while this process writes
summary.json and the rest, then draws the remaining figures itself and waits for the child. Figures are written
atomically into the result's staging folder, so whichever process draws a figure, the folder is the same.

A figure the child did not write (it failed, or was killed) is drawn by this process, so a failure of the
child costs time, never a figure. Where forking is not safe (not Linux, or other threads are running: a
forked child could inherit a lock held by one of them; tqdm's monitor thread excepted) everything is drawn here, in order.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import traceback
from pathlib import Path

from .figures import figure_files, write_figure

#: figures the child draws (the costliest: three polar panels, six panels, the chamber gas figures)
CHILD_SHARE = ("fig12_displacements.png", "fig14_housing_spectrum.png", "pv_diagram.png")


#: threads that may run at the fork, by class name or name prefix: tqdm's monitor of progress bars (it only takes
#: tqdm's own lock, which the child never uses); the worker of dask.distributed's offload executor, which stays,
#: idle, after a sweep's LocalCluster is closed (the child runs no dask code)
HARMLESS_THREADS = ("TMonitor", "Dask-Offload")


def other_threads() -> list[str]:
    """The names of the threads running besides the main thread and the harmless ones."""
    return [t.name for t in threading.enumerate() if t is not threading.main_thread()
            and not any(type(t).__name__ == h or t.name.startswith(h) for h in HARMLESS_THREADS)]


def can_fork() -> bool:
    """True where a child process can be forked safely: Linux, no other thread running (but harmless ones)."""
    return sys.platform.startswith("linux") and hasattr(os, "fork") and not other_threads()


class FigureJob:
    """The figures of ``result`` being drawn into ``folder``: :meth:`start`, other work, then :meth:`finish`."""

    def __init__(self, result, folder: str | Path, ports: dict | None = None, dpi: int = 100,
                 fork: bool | None = None) -> None:
        self.result, self.folder, self.ports, self.dpi = result, Path(folder), ports, dpi
        self.files = figure_files(result)
        self.fork = can_fork() if fork is None else fork and can_fork()
        self.pid: int | None = None

    def start(self) -> FigureJob:
        """Fork the child that draws :data:`CHILD_SHARE` (matplotlib is imported first, once, for both)."""
        self.folder.mkdir(parents=True, exist_ok=True)
        child = [n for n in self.files if n in CHILD_SHARE]
        if not self.fork or not child:
            return self
        import matplotlib.figure  # noqa: F401  (imported before the fork: the child inherits it)

        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid == 0:  # the child: draw, then leave without running the parent's exit handlers
            code = 1
            try:
                for name in child:
                    write_figure(self.result, self.folder, name, self.files[name], self.ports, self.dpi)
                code = 0
            except BaseException:
                traceback.print_exc()
            finally:
                os._exit(code)
        self.pid = pid
        return self

    def cancel(self) -> None:
        """Stop the child, if any, and wait for it (the result is not being written after all)."""
        if self.pid is not None:
            try:
                os.kill(self.pid, signal.SIGKILL)
                os.waitpid(self.pid, 0)
            except (ProcessLookupError, ChildProcessError):
                pass
            self.pid = None

    def finish(self) -> list[Path]:
        """Draw the figures not given to the child, wait for it, draw any it did not write; the paths in the
        order of :func:`.figures.figure_files`."""
        mine = [n for n in self.files if self.pid is None or n not in CHILD_SHARE]
        try:
            for name in mine:
                write_figure(self.result, self.folder, name, self.files[name], self.ports, self.dpi)
        except BaseException:
            self.cancel()
            raise
        if self.pid is not None:
            os.waitpid(self.pid, 0)
            self.pid = None
            return self.draw_missing()  # the child failed or was killed: its figures are drawn here
        return [self.folder / n for n in self.files]

    def draw_missing(self) -> list[Path]:
        """Draw, in this process, every figure not in the folder yet; the paths of all of them."""
        for name in self.files:
            if not (self.folder / name).is_file():
                write_figure(self.result, self.folder, name, self.files[name], self.ports, self.dpi)
        return [self.folder / n for n in self.files]
