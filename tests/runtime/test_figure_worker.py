"""The early figure process of ``apexseal simulate``: the same files as drawn in one process, none lost when the
worker dies, nothing left behind when the run ends without figures."""

from __future__ import annotations

import os
import signal

import pytest
from fork_helpers import require_fork

import apexseal
from apexseal.runtime.results.figure_job import write_figures
from apexseal.runtime.results.figure_worker import FigureWorker
from apexseal.runtime.results.figures import force_panels, ports_of
from apexseal.runtime.results.saved_figures import FILES, figure_files


@pytest.fixture(scope="module")
def result(default_scene, default_functions):
    return apexseal.simulate(default_scene, samples_per_revolution=360, flags="quick", rtol=1e-8,
                             functions=default_functions.sx)


def _worker() -> FigureWorker:
    require_fork()  # checked when the test runs: earlier tests may have left threads running
    worker = FigureWorker.start()
    assert worker is not None
    return worker


def _gone(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    return False


@pytest.mark.parametrize("told", [None, "panels", "other panels"])
def test_the_worker_draws_the_same_files(result, default_scene, tmp_path, told):
    """Drawn in the worker the same as in one process: not told what to draw ahead, told (it builds the frames
    until the result arrives, here at once: see the next test for frames built ahead), and told other panels than
    the result has (their frame is not used)."""
    ports = ports_of(default_scene)
    alone = write_figures(result, tmp_path / "one", ports, fork=False)
    worker = _worker()
    pid = worker.pid
    if told is not None:
        panels = force_panels(result.outputs)
        worker.prepare(panels if told == "panels" else panels[:-1], ports)
    drawn = worker.submit(result, tmp_path / "two", ports).finish()
    assert [p.name for p in alone] == [p.name for p in drawn] == list(figure_files(result))
    for a, b in zip(alone, drawn, strict=True):
        assert a.read_bytes() == b.read_bytes(), a.name
    assert _gone(pid) and not worker.path.exists()


def test_a_killed_worker_costs_no_figure(result, default_scene, tmp_path):
    worker = _worker()
    os.kill(worker.pid, signal.SIGKILL)
    paths = worker.submit(result, tmp_path, ports_of(default_scene)).finish()  # drawn here instead
    assert [p.name for p in paths] == list(figure_files(result))
    assert all(p.is_file() and p.stat().st_size > 0 for p in paths)


def test_a_run_without_figures_stops_the_worker(tmp_path):
    require_fork()
    with FigureWorker.started() as worker:
        pid, path = worker.pid, worker.path
        assert path.exists()
    assert _gone(pid) and not path.exists()


def test_the_worker_ends_when_the_pipe_closes():
    """What happens when the run's process dies: the worker reads the end of the pipe and exits by itself."""
    worker = _worker()
    pid, path = worker.pid, worker.path
    worker._close()  # as the death of this process would
    _, status = os.waitpid(pid, 0)
    assert os.WIFEXITED(status) and os.WEXITSTATUS(status) == 0
    assert not path.exists()
    worker.pid = None


def test_the_cli_draws_through_the_worker(tmp_path, monkeypatch):
    """``apexseal simulate`` hands its result to a worker and writes the four figures."""
    from click.testing import CliRunner

    from apexseal.cli import main
    from apexseal.runtime.results import figure_worker

    require_fork()
    submitted = []
    submit = figure_worker.FigureWorker.submit

    def spy(self, *args, **kw):
        submitted.append(self.pid)
        return submit(self, *args, **kw)

    monkeypatch.setattr(figure_worker.FigureWorker, "submit", spy)
    out = tmp_path / "run"
    res = CliRunner().invoke(main, ["simulate", "--out", str(out), "-q", "--revolutions", "1"])
    assert res.exit_code == 0, res.output
    assert len(submitted) == 1
    for name in FILES:
        assert (out / name).stat().st_size > 0, name


def test_a_frame_is_filled_once_and_only_for_what_it_was_built_for(result, default_scene):
    """figures.frames_ahead: Fig. 13's frame fills a result with its panels, once; Fig. 12's needs its ports."""
    from apexseal.runtime.results import figures

    ports = ports_of(default_scene)
    frames = figures.frames_ahead(force_panels(result.outputs), ports)
    assert figures.fig13_forces(result, save_dpi=100, frame=frames["fig13"]) is frames["fig13"].fig
    assert figures.fig13_forces(result, save_dpi=100, frame=frames["fig13"]) is not frames["fig13"].fig
    assert figures.fig12_displacements(result, None, frame=frames["fig12"]) is not frames["fig12"].fig
    assert figures.fig12_displacements(result, ports, frame=frames["fig12"]) is frames["fig12"].fig
    other = figures.frames_ahead(force_panels(result.outputs)[1:], ports)["fig13"]
    assert figures.fig13_forces(result, frame=other) is not other.fig


@pytest.mark.parametrize("fork", [False, True])
def test_frames_built_ahead_draw_the_same_files(result, default_scene, tmp_path, fork):
    """Figures filled into frames built ahead (as the worker builds them while a run integrates; in the worker
    itself a short run's result may arrive first, and then the drawing processes build the frames): the files
    drawn in one process without them, byte for byte."""
    from apexseal.runtime.results.figure_job import FigureJob
    from apexseal.runtime.results.figures import frames_ahead

    if fork:
        require_fork()
    ports = ports_of(default_scene)
    alone = write_figures(result, tmp_path / "one", ports, fork=False)
    frames = frames_ahead(force_panels(result.outputs), ports)
    assert set(frames) == {"fig12", "fig13", "fig14", "modes"}
    framed = FigureJob(result, tmp_path / "two", ports, fork=fork, frames=frames).start().finish()
    for a, b in zip(alone, framed, strict=True):
        assert a.read_bytes() == b.read_bytes(), a.name


def test_frames_ahead_stop_when_told(result, default_scene):
    """The worker stops building frames once the result waits: the costliest first, none after the stop."""
    from apexseal.runtime.results.figures import frames_ahead

    answers = iter([False, True])
    built = frames_ahead(force_panels(result.outputs), ports_of(default_scene), stop=lambda: next(answers))
    assert list(built) == ["fig13"]
    assert frames_ahead(force_panels(result.outputs), None, stop=lambda: True) == {}
