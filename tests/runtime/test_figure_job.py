"""A run's figures drawn partly in a forked process: the same files as drawn in one process, and none lost
when the child fails."""

from __future__ import annotations

import os

import pytest
from fork_helpers import require_fork

import apexseal
from apexseal.runtime.results import figure_job
from apexseal.runtime.results.figure_job import write_figures
from apexseal.runtime.results.figures import ports_of
from apexseal.runtime.results.saved_figures import figure_files


@pytest.fixture(scope="module")
def result(default_scene, default_functions):
    return apexseal.simulate(default_scene, samples_per_revolution=360, flags="quick", rtol=1e-8,
                             functions=default_functions.sx)


def test_forked_drawing_writes_the_same_files(result, default_scene, tmp_path):
    require_fork()
    ports = ports_of(default_scene)
    alone = write_figures(result, tmp_path / "one", ports, fork=False)
    forked = write_figures(result, tmp_path / "two", ports, fork=True)
    assert [p.name for p in alone] == [p.name for p in forked] == list(figure_files(result))
    for a, b in zip(alone, forked, strict=True):
        assert a.read_bytes() == b.read_bytes(), a.name


def test_a_failing_child_costs_no_figure(result, default_scene, tmp_path, monkeypatch, capfd):
    require_fork()
    parent = os.getpid()
    draw = figure_job.write_figure

    def only_in_the_parent(*args, **kw):
        if os.getpid() != parent:
            raise RuntimeError("the child fails")
        return draw(*args, **kw)

    monkeypatch.setattr(figure_job, "write_figure", only_in_the_parent)
    job = figure_job.FigureJob(result, tmp_path, ports_of(default_scene), fork=True).start()
    assert job.pid is not None
    paths = job.finish()
    assert all(p.is_file() and p.stat().st_size > 0 for p in paths)
    assert [p.name for p in paths] == list(figure_files(result))
    assert "the child fails" in capfd.readouterr().err


def test_the_two_processes_share_the_figures_out_costliest_first(result, default_scene, tmp_path, monkeypatch):
    """Each figure is drawn once, by whichever process takes it first; the child draws some of them, the parent
    the rest; the parent starts with the costliest (figure_job.ORDER); no claim file is left behind."""
    require_fork()
    log = tmp_path / "drawn.log"
    draw = figure_job.write_figure

    def logged(result, folder, name, *args, **kw):
        with open(log, "a") as fh:  # one short line per write: appends from two processes do not interleave
            fh.write(f"{os.getpid()} {name}\n")
        return draw(result, folder, name, *args, **kw)

    monkeypatch.setattr(figure_job, "write_figure", logged)
    job = figure_job.FigureJob(result, tmp_path / "figs", ports_of(default_scene), fork=True).start()
    claims = job.claims
    assert claims is not None and claims.is_dir()
    paths = job.finish()
    drawn = [line.split() for line in log.read_text().splitlines()]
    assert sorted(name for _, name in drawn) == sorted(figure_files(result))  # each once
    by = {pid for pid, _ in drawn}
    assert len(by) == 2 and str(os.getpid()) in by  # both processes drew
    mine = [name for pid, name in drawn if pid == str(os.getpid())]
    assert mine[0] in figure_job.ORDER[:2]  # the parent began with one of the two costliest
    assert all(p.is_file() for p in paths) and not claims.exists()


def test_an_idle_dask_offload_thread_does_not_stop_forking_and_another_thread_does():
    """dask.distributed keeps its offload executor's thread after a LocalCluster closes (a sweep in this process):
    it is harmless at the fork; a thread of any other name is not."""
    import threading

    stop = threading.Event()
    dask_like = threading.Thread(target=stop.wait, name="Dask-Offload_0", daemon=True)
    other = threading.Thread(target=stop.wait, name="a-users-thread", daemon=True)
    dask_like.start()
    try:
        assert "Dask-Offload_0" not in figure_job.other_threads()
        other.start()
        assert "a-users-thread" in figure_job.other_threads() and not figure_job.can_fork()
    finally:
        stop.set()
        dask_like.join()
        if other.is_alive():
            other.join()
