"""A process that gets matplotlib ready while the run integrates, then draws the run's figures.

Importing matplotlib and loading its fonts costs a new process 0.4-0.5 s, as much as drawing two figures
(docs/performance.md). ``apexseal simulate`` forks a :class:`FigureWorker` before it reads the scene: the worker
imports matplotlib on the second core while the first one loads the model and integrates, then waits. Once the
model is loaded, :meth:`FigureWorker.prepare` tells it what the figures will show (Fig. 13's force panels, the
ports), and the worker builds the four figures' frames (:func:`.figures.frames_ahead`: axes, texts and tick
objects, without data) while the run integrates, and only then: once the result waits, the frames not built yet
are left to the two drawing processes, which build them side by side. When the result is there,
:meth:`FigureWorker.submit` hands it over (pickled to a private temporary file: a pipe would block the run until
the worker has finished importing) and the worker fills the frames and saves the figures as
:class:`.figure_job.FigureJob` does, forking once more so that two processes draw. :meth:`FigureWorker.finish`
waits for it and draws whatever figure it did not write in this process, so a failed or killed worker costs
time, never a figure.

A run that ends without figures (a failure before the result, an interruption) stops the worker
(:meth:`FigureWorker.cancel`); if this process dies instead, the worker reads the end of the pipe and exits.
The worker only forks where :func:`.figure_job.can_fork` says it is safe; elsewhere :meth:`FigureWorker.start`
returns None and the figures are drawn as before.
"""

from __future__ import annotations

import os
import pickle
import select
import signal
import sys
import tempfile
import traceback
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from .figure_job import FigureJob, can_fork, reap
from .saved_figures import figure_view

#: the byte that tells the worker a result is waiting in its file
_GO = b"g"
#: the byte before the frames' description (its length in 4 bytes, then its pickle)
_FRAMES = b"f"


def _warm() -> None:
    """What a first figure costs besides drawing: matplotlib's import, its Agg canvas and its font cache, the
    modules that draw the figures."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from . import plots  # noqa: F401  (with .figures, .decimate, .summary)

    fig = Figure(figsize=(1, 1))
    fig.text(0.5, 0.5, "0")
    FigureCanvasAgg(fig).draw()


class FigureWorker:
    """A forked process that draws a run's figures: :meth:`start` early, :meth:`submit`, then :meth:`finish`."""

    def __init__(self, pid: int, write_fd: int, path: Path) -> None:
        self.pid, self._fd, self.path = pid, write_fd, path
        self.job: tuple | None = None

    @classmethod
    def start(cls) -> FigureWorker | None:
        """Fork the worker (it imports matplotlib and waits), or None where forking is not safe."""
        if not can_fork():
            return None
        fd, name = tempfile.mkstemp(prefix="apexseal-figures-", suffix=".pickle")
        os.close(fd)
        read_fd, write_fd = os.pipe()
        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid == 0:  # the worker never returns: it leaves through os._exit, without the parent's exit handlers
            os.close(write_fd)
            _serve(read_fd, Path(name))
        os.close(read_fd)
        return cls(pid, write_fd, Path(name))

    @classmethod
    @contextmanager
    def started(cls, enabled: bool = True) -> Iterator[FigureWorker | None]:
        """``with FigureWorker.started() as worker:``: the worker (None if not ``enabled`` or not safe to
        fork), stopped on leaving unless a result was submitted to it."""
        worker = cls.start() if enabled else None
        try:
            yield worker
        finally:
            if worker is not None and worker.job is None:
                worker.cancel()

    def prepare(self, panels: list[str], ports: dict | None) -> None:
        """Tell the worker what the figures will show, Fig. 13's force ``panels`` (:func:`.figures.force_panels`)
        and the scene's ``ports``: it builds their frames while the run integrates. A frame that does not fit the
        result after all is not used (the figure is drawn as without it)."""
        if self._fd is None:
            return
        spec = pickle.dumps((list(panels), ports), protocol=pickle.HIGHEST_PROTOCOL)
        try:  # a few hundred bytes: the pipe takes them at once
            os.write(self._fd, _FRAMES + len(spec).to_bytes(4, "little") + spec)
        except OSError:  # the worker is gone: finish() draws everything here
            pass

    def submit(self, result, folder: str | Path, ports: dict | None = None, dpi: int = 100) -> FigureWorker:
        """Hand the result over: the worker draws its figures into ``folder`` while this process goes on."""
        self.job = (result, Path(folder), ports, dpi)
        # only what the figures read: the hand-over (pickled here, unpickled there) is on the run's critical path;
        # and without its scene: the figures take the ports as given, and unpickling a Scene would import the scene
        # machinery (pydantic models, ~130 modules, 0.35 s) in the worker, which forked before this process had it
        light = figure_view(result)
        try:
            with open(self.path, "wb") as fh:
                pickle.dump((light, *self.job[1:]), fh, protocol=pickle.HIGHEST_PROTOCOL)
            os.write(self._fd, _GO)
        except OSError:  # the worker is gone: finish() draws everything here
            pass
        self._close()
        return self

    def cancel(self) -> None:
        """No figures after all: the worker is stopped (it holds nothing worth keeping) and waited for."""
        self._close()
        self._wait(kill=True)

    def finish(self) -> list[Path]:
        """Wait for the worker, draw here any figure it did not write; the figure paths (as
        :meth:`.figure_job.FigureJob.finish`)."""
        if self.job is None:
            raise RuntimeError("FigureWorker.finish() before submit()")
        self._wait()
        return FigureJob(*self.job, fork=False).draw_missing()

    def _close(self) -> None:
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def _wait(self, kill: bool = False) -> None:
        if self.pid is None:
            return
        reap(self.pid, kill)
        self.pid = None
        self.path.unlink(missing_ok=True)


def _read(fd: int, n: int) -> bytes:
    """``n`` bytes from the pipe ``fd`` (fewer only at its end)."""
    data = b""
    while len(data) < n:
        more = os.read(fd, n - len(data))
        if not more:
            break
        data += more
    return data


def _serve(read_fd: int, path: Path) -> None:
    """The worker: warm matplotlib, build the frames when told what they show, wait for the go, draw (two
    processes), leave."""
    code = 1
    try:
        if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:  # ignored by the run's process: here too
            signal.signal(signal.SIGINT, signal.SIG_DFL)  # Ctrl-C stops the run; the worker just ends
        _warm()
        frames = None
        go = _read(read_fd, 1)
        if go == _FRAMES:
            from .figures import frames_ahead

            spec = pickle.loads(_read(read_fd, int.from_bytes(_read(read_fd, 4), "little")))
            # built only while the run integrates: once the result waits on the pipe (a short run), the two drawing
            # processes build the frames left, side by side, instead of this one building them all in turn
            frames = frames_ahead(*spec, stop=lambda: bool(select.select([read_fd], [], [], 0)[0]))
            go = _read(read_fd, 1)
        if go == _GO:
            with open(path, "rb") as fh:
                result, folder, ports, dpi = pickle.load(fh)
            path.unlink(missing_ok=True)
            FigureJob(result, folder, ports, dpi, fork=True, frames=frames).start().finish()
        code = 0
    except BaseException:
        traceback.print_exc()
    finally:
        path.unlink(missing_ok=True)
        os._exit(code)
