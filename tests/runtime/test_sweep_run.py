"""Sweeps end to end: serial and LocalCluster agree digit by digit, nothing is lost or computed twice when a sweep
is interrupted or a worker is killed, failed points are recorded, one compiled library serves every point."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
from sweep_helpers import LIGHT, light_study, stable

from apexseal.cli import command
from apexseal.runtime.studies.sweep import read_results, run_sweep


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    """The light study run serially in this process: the reference table."""
    out = tmp_path_factory.mktemp("serial") / "out"
    report = run_sweep(light_study(), out, workers=1, quiet=True)
    assert report.complete and report.computed == 16 and not report.interrupted
    return report


def test_a_point_s_plausibility_warning_is_in_its_row_and_the_command_names_the_point(tmp_path, monkeypatch):
    """A sweep printed a point's implausible-penetration warning once (Python's filter), or from a worker, without
    saying which point it came from: each point's run warnings are its row's ``warnings``, and the command says which
    points warned."""
    from click.testing import CliRunner

    from apexseal.cli import main

    text = LIGHT.replace('[parameters."spring.ks"]\nfrom = "3e3 N/m"\nto = "2e4 N/m"\npoints = 4\nscale = "log"',
                         '[parameters."contacts.kg1"]\nvalues = ["1e9 N/m", "1.05e6 N/m"]')
    text = text.replace('values = ["1 mm", "2 mm", "3 mm", "4 mm"]', 'values = ["2 mm"]')
    (tmp_path / "soft.toml").write_text(text)
    monkeypatch.chdir(tmp_path)
    r = CliRunner().invoke(main, ["sweep", "soft.toml", "--workers", "1", "--out", "o", "--no-figures", "-q"])
    assert r.exit_code == 0, r.output
    df = read_results(tmp_path / "o")
    assert df.loc[0, "warnings"] == "" and df.loc[1, "warnings"].startswith("implausible penetration: i1")
    assert "1 point warned of an implausible run (the warnings column): point 1; point 1: implausible" in r.output


def test_serial_sweep_writes_one_row_per_point_with_units_and_scene_hashes(serial):
    df = read_results(serial.folder)
    assert list(df["point"]) == list(range(16))
    assert (df["status"] == "completed").all(), df[["status", "stop"]]
    units = df.attrs["units"]
    assert units["spring.ks"] == "N/m" and units["spring.delta_s"] == "m" and units["friction_power.total"] == "W"
    assert units["housing_force.max"] == "N" and units["x.max_at"] == "deg" and units["wall_time_s"] == "s"
    st = light_study()
    row = df.iloc[5]
    scene = st.scene.with_overrides(**{"spring.ks": row["spring.ks"], "spring.delta_s": row["spring.delta_s"]})
    assert row["scene_hash"] == scene.content_hash()
    assert df["scene_hash"].nunique() == 16
    assert (df["revolutions"] == 1.0).all()
    # the quantities are those of the run summary of the same scene
    import apexseal
    from apexseal.runtime.results.summary import summarise

    s = summarise(apexseal.simulate(scene, max_wall_time=60))
    assert row["friction_power.total"] == s["mean_friction_power_W"]["total"]
    assert row["housing_force.max"] == s["housing_force_N"]["max"]
    assert row["events.total"] == s["events_total"]
    # the design varies what it should: preload raises friction power at fixed stiffness
    fixed = df[df["spring.ks"] == df["spring.ks"].max()].sort_values("spring.delta_s")
    assert fixed["friction_power.total"].is_monotonic_increasing
    assert df["feasible"].dtype == bool
    assert df["feasible"].tolist() == list((df["liftoff_fraction"] <= 0) & (df["friction_power.total"] <= 35))


@pytest.mark.slow  # 9 s of a 2-core test process: in the second step, to keep the default suite under 10 min
def test_local_cluster_with_two_workers_gives_the_serial_table_to_the_last_digit(serial, tmp_path):
    report = run_sweep(light_study(), tmp_path / "dask", workers=2, quiet=True)
    assert report.where == "LocalCluster" and report.workers == 2 and report.complete
    assert report.table["worker"].nunique() == 2  # both workers did points
    pd.testing.assert_frame_equal(stable(report.table), stable(serial.table), check_exact=True)


@pytest.mark.slow
def test_a_killed_worker_loses_nothing_and_no_point_is_written_twice(serial, tmp_path):
    from dask.distributed import Client

    from apexseal.runtime.studies.sweep.execute import local_cluster

    rows: list[int] = []
    with local_cluster(2) as cluster, Client(cluster) as client:
        pids = client.run(os.getpid)
        victim = next(iter(pids.values()))

        def on_row(row):
            rows.append(row["point"])
            if len(rows) == 3:
                os.kill(victim, signal.SIGKILL)  # mid-sweep: points are in flight on both workers

        report = run_sweep(light_study(), tmp_path / "killed", client=client, quiet=True, on_row=on_row)
        assert victim not in client.run(os.getpid).values()  # the worker really died (the nanny restarted it)
    assert sorted(rows) == list(range(16))  # every point arrived exactly once
    assert report.complete and report.computed == 16
    pd.testing.assert_frame_equal(stable(report.table), stable(serial.table), check_exact=True)


def _wait_for_points(out, proc, count: int, timeout: float = 120.0) -> None:
    """Until the sweep writing ``out`` has ``count`` finished points (or has ended, or ``timeout`` s passed)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None:
        if len(list((out / "points").glob("point-*.parquet"))) >= count:
            return
        time.sleep(0.05)


def test_an_interrupted_sweep_resumes_without_recomputing_or_losing_anything(serial, tmp_path):
    study = tmp_path / "light.toml"
    study.write_text(LIGHT)
    out = tmp_path / "out"
    cmd = command("sweep", str(study), "--workers", "1", "--out", str(out), "-q")
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    parts = out / "points"
    _wait_for_points(out, proc, 4)
    proc.send_signal(signal.SIGINT)  # Ctrl-C
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 130, stdout + stderr
    assert "interrupted" in stdout + stderr
    before = {p.name: (p.stat().st_mtime_ns, p.read_bytes()) for p in parts.glob("point-*.parquet")}
    assert 4 <= len(before) < 16
    partial = read_results(out)  # the table written at the interruption holds every finished point
    assert len(partial) == len(before) and not list(parts.glob(".*.tmp"))

    report = run_sweep(light_study(), out, workers=1, quiet=True)
    assert report.skipped == len(before) and report.computed == 16 - len(before)
    after = {p.name: (p.stat().st_mtime_ns, p.read_bytes()) for p in parts.glob("point-*.parquet")}
    assert {k: after[k] for k in before} == before  # nothing done was recomputed or rewritten
    pd.testing.assert_frame_equal(stable(report.table), stable(serial.table), check_exact=True)
    again = run_sweep(light_study(), out, workers=1, quiet=True)
    assert again.computed == 0 and again.skipped == 16


@pytest.mark.slow
def test_sigterm_stops_a_dask_sweep_as_ctrl_c_does(tmp_path):
    """SIGTERM (kill, timeout, a batch scheduler) to a sweep on a LocalCluster: exit 143 (128 + SIGTERM, as a run's;
    it was 130, Ctrl-C's), every finished point in results.parquet. It used to kill the process outright, with no
    table written and nothing said."""
    study = tmp_path / "light.toml"
    study.write_text(LIGHT)
    out = tmp_path / "out"
    proc = subprocess.Popen(command("sweep", str(study), "--workers", "2", "--out", str(out), "-q", "--no-figures"),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    parts = out / "points"
    _wait_for_points(out, proc, 2)
    proc.send_signal(signal.SIGTERM)
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 143, stdout + stderr
    assert "interrupted" in stderr and "Traceback" not in stderr, stderr
    finished = len(list(parts.glob("point-*.parquet")))
    assert 2 <= finished < 16 and len(read_results(out)) == finished


@pytest.mark.slow
def test_ctrl_c_on_the_terminal_stops_a_dask_sweep_without_the_workers_tracebacks(tmp_path):
    """A terminal's Ctrl-C reaches the whole process group: each worker printed a KeyboardInterrupt traceback
    (68 lines for two workers) before the sweep's own message. The workers now start with SIGINT ignored."""
    study = tmp_path / "light.toml"
    study.write_text(LIGHT)
    out = tmp_path / "out"
    def foreground():  # as a command typed at a terminal: Ctrl-C acts (a job started in the background ignores it)
        signal.signal(signal.SIGINT, signal.SIG_DFL)

    proc = subprocess.Popen(command("sweep", str(study), "--workers", "2", "--out", str(out), "-q", "--no-figures"),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=foreground)
    _wait_for_points(out, proc, 2)
    os.killpg(proc.pid, signal.SIGINT)  # what a terminal does
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 130, stdout + stderr
    assert "Traceback" not in stderr and "interrupted: run the same command again" in stderr, stderr


#: a sweep command of four points (``apexseal`` with this script's arguments) that gets the signal SIGNAL at a
#: moment of its LocalCluster's life (HOOK): SIGINT to the whole process group, as a terminal's Ctrl-C; SIGTERM to
#: the sweep's process, as kill
SIGNALLED_SWEEP = """
import os
import signal
import sys
import threading

def signal_it():
    (os.killpg(0, SIGNAL) if SIGNAL == signal.SIGINT else os.kill(os.getpid(), SIGNAL))

if __name__ == "__main__":  # each worker imports this script again: nothing to do there
    from apexseal.cli import console

HOOK
    sys.argv[0] = "apexseal"
    console()
"""
#: 0.2 s after the cluster started its first worker process, while the cluster starts (a worker takes a second
#: or more to import Dask and register)
AT_WORKER_START = """
    import multiprocessing.process

    start = multiprocessing.process.BaseProcess.start
    sent = []

    def started(self):
        start(self)
        if "Dask Worker" in self.name and not sent:
            sent.append(SIGNAL)
            threading.Timer(0.2, signal_it).start()

    multiprocessing.process.BaseProcess.start = started
"""
#: as the cluster is closed, every point done
AT_CLOSE = """
    from distributed.deploy.spec import SpecCluster

    close = SpecCluster.close

    def closing(self, *args, **kwargs):
        signal_it()
        return close(self, *args, **kwargs)

    SpecCluster.close = closing
"""
ONE_DELTA = {'values = ["1 mm", "2 mm", "3 mm", "4 mm"]': 'values = ["2 mm"]'}


def _signalled_sweep(tmp_path, hook: str, signum: int):
    """Run :data:`SIGNALLED_SWEEP` with ``hook`` in a session of its own, as a command typed at a terminal; its
    exit status, stdout and stderr, once none of its processes is left (zombies aside), and its folder."""
    study = tmp_path / "light.toml"
    study.write_text(LIGHT.replace(*next(iter(ONE_DELTA.items()))))
    script = tmp_path / "signalled.py"
    script.write_text(SIGNALLED_SWEEP.replace("HOOK", hook).replace("SIGNAL", f"signal.{signal.Signals(signum).name}"))
    out = tmp_path / "out"

    def foreground():  # as a command typed at a terminal: Ctrl-C acts (a job started in the background ignores it)
        signal.signal(signal.SIGINT, signal.SIG_DFL)

    proc = subprocess.Popen([sys.executable, str(script), "sweep", str(study), "--workers", "2", "--out", str(out),
                             "-q", "--no-figures"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=foreground)
    try:
        stdout, stderr = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    deadline = time.monotonic() + 10  # the workers end with their nanny, as after a signal during the points
    while _live_in_session(proc.pid) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert _live_in_session(proc.pid) == []
    return proc.returncode, stdout, stderr, out


def _live_in_session(session: int) -> list[int]:
    """The processes still alive (zombies aside) in the session ``session``."""
    import psutil

    live = []
    for pid in psutil.pids():
        try:
            if os.getsid(pid) == session and psutil.Process(pid).status() != psutil.STATUS_ZOMBIE:
                live.append(pid)
        except (OSError, psutil.Error):  # ended meanwhile
            pass
    return live


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["ctrl-c", "sigterm"])
def test_a_signal_while_the_dask_workers_start_stops_the_sweep_as_one_during_the_points(tmp_path, signum):
    """A signal while the sweep's LocalCluster started its workers was not handled as one during the points: a
    Ctrl-C was lost (the sweep ignored SIGINT then, for the workers to inherit the ignore) and the sweep ran to its
    end with exit status 0; a SIGTERM abandoned the cluster halfway through its start, and the process ended with
    an ``AssertionError: Status.init`` traceback from Dask's atexit hook. Now the signal is noted, the start
    finishes, the cluster is closed before any point is submitted, and the command ends as after a signal during
    the points: 130 or 143, no traceback (no worker's KeyboardInterrupt either: they start with SIGINT blocked), no
    process left, the folder a consistent, resumable study of no point yet."""
    code, stdout, stderr, out = _signalled_sweep(tmp_path, AT_WORKER_START, signum)
    assert code == 128 + signum, stdout + stderr
    assert "Traceback" not in stderr and "interrupted: run the same command again" in stderr, stderr
    assert "interrupted: 0 of 4 points" in stdout and "(LocalCluster)" in stdout, stdout
    assert read_results(out).empty  # the table is written, of no point: the same study resumes from it
    report = run_sweep(light_study(**ONE_DELTA), out, workers=1, quiet=True)
    assert report.complete and report.computed == 4 and report.skipped == 0


@pytest.mark.slow
def test_a_signal_while_the_cluster_closes_after_the_last_point_is_said_and_exits_as_interrupted(tmp_path):
    """A SIGTERM while the sweep closed its LocalCluster, every point done, was noted and then forgotten: the
    command said nothing of it and exited with status 0, as if no signal had come. Now it says so in one line and
    exits with 143, as a sweep stopped by a signal does (every point kept: nothing to compute again)."""
    code, stdout, stderr, out = _signalled_sweep(tmp_path, AT_CLOSE, signal.SIGTERM)
    assert code == 143, stdout + stderr
    assert "Traceback" not in stderr and "done: 4 of 4 points" in stdout, stdout + stderr
    assert "interrupted by SIGTERM (kill, timeout or a batch scheduler) once every point was done" in stderr, stderr
    assert len(read_results(out)) == 4


@pytest.mark.skipif(not hasattr(signal, "pthread_sigmask"), reason="threads cannot block signals here")
def test_a_sigint_held_while_the_workers_start_reaches_its_handler_after_and_never_the_threads_started():
    """The sweep ignored SIGINT while its LocalCluster started (so that the workers inherited the ignore), and a
    Ctrl-C in those seconds was lost. ``held`` blocks it instead: the threads started inside keep it blocked (the
    workers they start inherit that), and one that arrived inside reaches the handler, at the latest when the
    block ends."""
    import threading

    from apexseal.signals import handling, held

    got, blocked = [], []
    with handling(signal.SIGINT, lambda signum, frame: got.append(signum)):
        with held(signal.SIGINT):
            thread = threading.Thread(target=lambda: blocked.append(signal.pthread_sigmask(signal.SIG_BLOCK, [])))
            thread.start()
            thread.join()
            os.kill(os.getpid(), signal.SIGINT)  # (a thread of pytest's, started before, may take it at once)
        time.sleep(0.05)  # (the handler runs at the next bytecode check)
    assert got == [signal.SIGINT] and signal.SIGINT in blocked[0]
    assert signal.SIGINT not in signal.pthread_sigmask(signal.SIG_BLOCK, [])


def test_no_more_workers_start_than_points_are_left_and_more_than_cores_is_said(tmp_path, monkeypatch):
    """`sweep -w 1000` started a thousand worker processes for 16 points on two cores (and took minutes to): the
    LocalCluster gets no more workers than points left to run, and the cap is said, in a warning and the report;
    more workers than cores is allowed, with a warning."""
    from apexseal.runtime.studies.sweep import execute
    from apexseal.runtime.studies.sweep.execute import WorkersWarning

    started = []

    def cluster_of(todo, args, record, study, n, scheduler, client, shown):  # no processes: what was asked
        started.append(n)
        return "LocalCluster", n, True

    monkeypatch.setattr(execute, "_dask", cluster_of)
    monkeypatch.setattr(execute, "available_cores", lambda: 2)
    with pytest.warns(WorkersWarning) as caught:
        report = run_sweep(light_study(), tmp_path / "out", workers=1000, quiet=True)
    said = [str(w.message) for w in caught]
    assert started == [16] and report.workers == 16 and report.workers_asked == 1000
    assert "workers = 1000: 16 points left to run, so the LocalCluster starts 16 workers" in said[0], said
    assert "16 worker processes on 2 cores" in said[1] and "--workers 2 is as fast" in said[1], said
    assert "on 16 workers (LocalCluster; 1000 asked, as many as points left)" in report.describe()
    started.clear()
    run_sweep(light_study(), tmp_path / "two", workers=2, quiet=True)  # as many as the cores: nothing said
    assert started == [2]


def test_a_signal_stops_the_points_running_on_a_dask_cluster_not_only_the_sweep(tmp_path, sigterm_redelivered):
    """SIGTERM while a long point runs on a cluster (a client's own, as on a shared cluster): the sweep returned,
    but the point ran on to its end (minutes), holding its worker; now it stops at its run's next check as a
    serial sweep's point does, the point not started is cancelled, and the finished one is kept."""
    from dask.distributed import Client

    from apexseal.runtime.studies.sweep.execute import local_cluster

    study = light_study(**{'"operation.revolutions" = 1': "", '"spring.ks"]': '"operation.revolutions"]',
                           'from = "3e3 N/m"\nto = "2e4 N/m"\npoints = 4\nscale = "log"': "values = [1, 100000, 99999]",
                           '"1 mm", "2 mm", "3 mm", "4 mm"': '"2 mm"', '"60 s"': '"300 s"'})
    assert [p.key for p in study.parameters] == ["operation.revolutions", "spring.delta_s"]

    def on_row(row):  # the first, short point is written: the next, long one runs on the only worker
        os.kill(os.getpid(), signal.SIGTERM)

    with local_cluster(1) as cluster, Client(cluster) as client:
        report = run_sweep(study, tmp_path / "out", client=client, quiet=True, on_row=on_row)
        assert report.interrupted and list(report.table["point"]) == [0]
        assert (report.table["status"] == "completed").all()
        assert list(read_results(tmp_path / "out")["point"]) == [0]  # the table on disk: resumable
        # the worker is free again: the long point was stopped, not left to run out its 300 s budget
        assert client.submit(os.getpid, pure=False).result(timeout=30) > 0
    assert sigterm_redelivered == [signal.SIGTERM]  # then it ends the process, as the signal asked


@pytest.mark.slow
def test_a_signal_while_a_dask_sweep_writes_a_point_keeps_that_point(tmp_path, signalled_in, sigterm_redelivered):
    """SIGTERM while the row of a finished point was written raised there (KeyboardInterrupt), and the point was
    lost; now the signal is noted, the row written whole, and the sweep stops after it."""
    from apexseal.runtime.studies.sweep.store import Store

    signalled_in(Store, "write")
    rows = []
    report = run_sweep(light_study(), tmp_path / "out", workers=2, quiet=True, on_row=lambda r: rows.append(r["point"]))
    assert report.interrupted and report.where == "LocalCluster"
    assert 1 <= len(rows) < 16 and sorted(rows) == sorted(report.table["point"])
    assert sorted(read_results(tmp_path / "out")["point"]) == sorted(rows)
    assert sigterm_redelivered == [signal.SIGTERM]  # then it ends the process, as the signal asked


def test_a_second_sweep_into_a_folder_being_written_is_refused(tmp_path):
    """Two sweeps at once into one folder mixed their rows (and results.parquet named the other study)."""
    from apexseal.runtime.studies.sweep.store import Store, StoreError

    first = Store(tmp_path / "o")
    first.open(light_study())
    with pytest.raises(StoreError, match="being written by another sweep"):
        run_sweep(light_study(**{"points = 4": "points = 2"}), tmp_path / "o", workers=1, quiet=True)
    first.close()
    assert run_sweep(light_study(**{"points = 4": "points = 2"}), tmp_path / "o", workers=1, quiet=True,
                     resume=False).complete


def test_reading_a_killed_or_running_sweep_reads_its_finished_points(tmp_path):
    """A sweep killed outright (SIGKILL) leaves its points but no results.parquet: reading it raised a bare
    FileNotFoundError, then one saying where the points are; a running sweep could not be looked at. Its table is
    read from the points' part-files, with a warning, the same columns and units as the table's but feasible."""
    from apexseal.runtime.studies.sweep.store import PartialResultsWarning

    out = tmp_path / "o"
    whole = run_sweep(light_study(**{"points = 4": "points = 2"}), out, workers=1, quiet=True).table
    table = read_results(out)
    (out / "results.parquet").unlink()  # as if killed before the table was written
    with pytest.warns(PartialResultsWarning, match=r"not written yet .* read from the 8 finished point\(s\) in"):
        partial = read_results(out)
    pd.testing.assert_frame_equal(partial, whole.drop(columns="feasible"), check_exact=True)
    assert partial.attrs["units"] == {c: u for c, u in table.attrs["units"].items() if c != "feasible"}
    (out / "study.json").unlink()  # no record of the study's units: said where the points are, as before
    with pytest.raises(FileNotFoundError, match=r"stopped before writing it; its 8 finished point\(s\) are in"):
        read_results(out)


def test_resume_refuses_a_folder_of_another_study_and_fresh_recomputes(serial, tmp_path):
    from apexseal.runtime.studies.sweep.store import StoreError

    out = tmp_path / "out"
    run_sweep(light_study(**{"points = 4": "points = 2"}), out, workers=1, quiet=True)
    other = {"points = 4": "points = 3", 'name = "light"': 'name = "heavy"'}
    with pytest.raises(StoreError, match="holds the results of another study \\('light', this one is 'heavy'\\)"):
        run_sweep(light_study(**other), out, workers=1, quiet=True)
    (out / "a-quantity-of-the-old-study.png").write_bytes(b"")  # as its figures were
    report = run_sweep(light_study(**other), out, workers=1, resume=False, quiet=True)
    assert report.computed == 12 and report.skipped == 0 and len(report.table) == 12
    assert not (out / "a-quantity-of-the-old-study.png").exists()  # --fresh leaves no figure of the study it discards


def test_an_edited_study_keeps_the_points_whose_scene_did_not_change(serial, tmp_path):
    """Adding a value to a grid, or raising the wall-time budget, refused the folder ("holds the results of another
    study"): only --fresh, which discarded every finished point, ran the edited study. The finished points whose
    scene (content hash) the edited study has are kept as its own, renumbered; the others are computed, and the
    table is the one a fresh run gives to the last digit. A quantity the old rows lack computes every point."""
    out = tmp_path / "out"
    run_sweep(light_study(**{"points = 4": "points = 2"}), out, workers=1, quiet=True)  # ks 3e3 and 2e4 only
    grown = run_sweep(light_study(), out, workers=1, quiet=True)
    assert (grown.computed, grown.skipped, grown.carried) == (8, 8, (8, 0))
    assert "8 resumed (8 of them kept from the study before its edit, the same scene and quantities; 0 of its " \
           "rows discarded)" in grown.describe()
    pd.testing.assert_frame_equal(stable(grown.table), stable(serial.table), check_exact=True)
    assert not (out / "points.new").exists() and not (out / "points.old").exists()
    shrunk = run_sweep(light_study(**{'"1 mm", "2 mm", "3 mm", "4 mm"': '"2 mm"'}), out, workers=1, quiet=True)
    assert (shrunk.computed, shrunk.carried, len(shrunk.table)) == (0, (4, 12), 4)
    assert list(shrunk.table["point"]) == [0, 1, 2, 3] and (shrunk.table["spring.delta_s"] == 2e-3).all()
    more = run_sweep(light_study(**{'"1 mm", "2 mm", "3 mm", "4 mm"': '"2 mm"',
                                    '"events.total", ': '"events.total", "gap.max", '}), out, workers=1, quiet=True)
    assert (more.computed, more.carried) == (4, (0, 4)) and more.table["gap.max"].notna().all()


def test_failed_points_are_recorded_with_their_reason_and_the_sweep_goes_on(tmp_path, monkeypatch):
    import apexseal.runtime.api as api

    real = api.simulate

    def flaky(scene, **kw):
        if scene.spring.ks > 1.5e4:
            raise RuntimeError("solver blew up (test)")
        return real(scene, **kw)

    monkeypatch.setattr(api, "simulate", flaky)
    report = run_sweep(light_study(), tmp_path / "flaky", workers=1, quiet=True)
    df = report.table
    bad = df[df["spring.ks"] > 1.5e4]
    assert len(df) == 16 and len(bad) == 4 and report.failed == 4
    assert (bad["status"] == "error").all() and bad["stop"].str.contains("solver blew up").all()
    assert bad["friction_power.total"].isna().all() and not bad["feasible"].any()
    assert (df.drop(bad.index)["status"] == "completed").all()

    monkeypatch.undo()
    budget = run_sweep(light_study(**{'max_wall_time = "60 s"': 'max_wall_time = "1e-6 s"', "points = 4": "points = 2"}),
                       tmp_path / "budget", workers=1, quiet=True)
    assert len(budget.table) == 8 and (budget.table["status"] == "interrupted").all()
    assert budget.table["stop"].str.contains("wall-time budget used up").all()
    # the same budget stops them again (--retry-failed did): a larger one, an edit of the study, computes them
    larger = run_sweep(light_study(**{"points = 4": "points = 2"}), tmp_path / "budget", workers=1, quiet=True)
    assert (larger.computed, larger.carried) == (8, (0, 8)) and (larger.table["status"] == "completed").all()


def test_retry_failed_computes_again_only_the_points_that_did_not_complete(serial, tmp_path, monkeypatch):
    """A resumed sweep skipped every point with a row, failed ones too: a point that failed on a crashed worker or
    an error since fixed could be computed again only by discarding the whole folder (--fresh). retry_failed
    computes those points again, and only those; the others' part-files are not touched."""
    import apexseal.runtime.api as api

    real, bad = api.simulate, set(serial.table["scene_hash"].iloc[[3, 7]])

    def flaky(scene, **kw):
        if scene.content_hash() in bad:
            raise RuntimeError("a worker ran out of memory (test)")
        return real(scene, **kw)

    monkeypatch.setattr(api, "simulate", flaky)
    out = tmp_path / "out"
    first = run_sweep(light_study(), out, workers=1, quiet=True)
    assert first.failed == 2 and sorted(first.table.loc[first.table["status"] == "error", "point"]) == [3, 7]
    monkeypatch.undo()
    resumed = run_sweep(light_study(), out, workers=1, quiet=True)
    assert resumed.computed == 0 and resumed.failed == 2  # resuming alone keeps the failed rows
    parts = out / "points"
    before = {p.name: p.read_bytes() for p in parts.glob("point-*.parquet")}
    again = run_sweep(light_study(), out, workers=1, retry_failed=True, quiet=True)
    assert (again.computed, again.retried, again.skipped, again.failed) == (2, 2, 14, 0)
    assert "2 computed now (2 of them again: their rows had not completed), 14 resumed" in again.describe()
    after = {p.name: p.read_bytes() for p in parts.glob("point-*.parquet")}
    changed = {name for name in before if after[name] != before[name]}
    assert changed == {"point-000003.parquet", "point-000007.parquet"}
    pd.testing.assert_frame_equal(stable(again.table), stable(serial.table), check_exact=True)
    with pytest.raises(ValueError, match="retry_failed = True with resume = False"):
        run_sweep(light_study(), out, workers=1, resume=False, retry_failed=True, quiet=True)


def test_a_study_file_and_an_example_together_are_refused_as_both(tmp_path):
    """Both given, the command answered "give a STUDY file or --example NAME", as to neither."""
    from click.testing import CliRunner

    from apexseal.cli import main

    study = tmp_path / "light.toml"
    study.write_text(LIGHT)
    both = CliRunner().invoke(main, ["sweep", str(study), "--example", "sampling", "-o", str(tmp_path / "o")])
    assert both.exit_code == 2 and "give a STUDY file or --example NAME, not both" in both.output, both.output
    neither = CliRunner().invoke(main, ["sweep", "-o", str(tmp_path / "o")])
    assert neither.exit_code == 2 and "not both" not in neither.output and "--example preload-map" in neither.output
    assert not (tmp_path / "o").exists()


def test_a_sweep_is_not_written_into_a_result_folder(tmp_path):
    """A sweep's --out of a simulation's result folder wrote its points and tables into it."""
    import apexseal
    from apexseal.runtime.studies.sweep.store import StoreError

    out = tmp_path / "result"
    apexseal.simulate(apexseal.load_scene(), revolutions=1, samples_per_revolution=36, out=out)
    before = sorted(p.name for p in out.iterdir())
    with pytest.raises(StoreError, match="holds a simulation's result \\(result.json\\): a sweep's points"):
        run_sweep(light_study(**{"points = 4": "points = 2"}), out, workers=1, quiet=True)
    assert sorted(p.name for p in out.iterdir()) == before


def test_cli_retry_failed_is_named_after_failed_points_and_refused_with_fresh(tmp_path, monkeypatch):
    from click.testing import CliRunner

    from apexseal.cli import main

    study = tmp_path / "light.toml"
    study.write_text(LIGHT.replace("points = 4", "points = 2").replace('"2 mm", "3 mm", "4 mm"', ""))
    refused = CliRunner().invoke(main, ["sweep", str(study), "--retry-failed", "--fresh", "-o", str(tmp_path / "o")])
    assert refused.exit_code == 2 and "--retry-failed with --fresh" in refused.output
    assert not (tmp_path / "o").exists()
    import apexseal.runtime.api as api

    def failing(scene, **kw):
        raise RuntimeError("no memory (test)")

    monkeypatch.setattr(api, "simulate", failing)
    r = CliRunner().invoke(main, ["sweep", str(study), "-w", "1", "-q", "--no-figures", "-o", str(tmp_path / "o")])
    assert r.exit_code == 1, r.output  # none completed: a script or CI job sees it (it exited 0)
    assert "--retry-failed computes them again" in r.output and "error: none of the 2 points completed" in r.output
    monkeypatch.undo()
    r = CliRunner().invoke(main, ["sweep", str(study), "-w", "1", "-q", "--no-figures", "--retry-failed", "-o",
                                  str(tmp_path / "o")])
    assert r.exit_code == 0 and "2 computed now (2 of them again" in r.output and "0 not completed" in r.output


@pytest.mark.slow  # 15 s of a 2-core test process (a cold cache on 2 workers): in the second step, to keep the default
def test_a_sweep_over_parameters_compiles_one_library(tmp_path, monkeypatch):  # suite under 10 min
    """Empty cache, 2 workers, 8 points: one compiled integrator (and at most one model library), each built once."""
    import json

    cache = tmp_path / "cache"
    monkeypatch.setenv("APEXSEAL_CACHE", str(cache))  # the LocalCluster's worker processes inherit it
    report = run_sweep(light_study(**{"points = 4": "points = 2"}), tmp_path / "out", workers=2, quiet=True)
    assert report.complete and (report.table["status"] == "completed").all()
    libs = [p for p in (cache / "lib").iterdir() if p.is_dir() and not p.name.startswith(".")]
    kinds = sorted(json.loads((p / "build.json").read_text())["sources"]["kind"] for p in libs)
    assert kinds in (["function"], ["function", "model"]), kinds  # the integrator; the model library of preflight
    assert all(len(list(p.glob("*.so"))) == 1 for p in libs)


def test_cli_sweep_writes_table_and_figures(serial, tmp_path):
    from click.testing import CliRunner

    from apexseal.cli import main

    study = tmp_path / "light.toml"
    study.write_text(LIGHT)
    out = Path(serial.folder)  # resumed: nothing to compute, the figures and tables are rewritten
    r = CliRunner().invoke(main, ["sweep", str(study), "--workers", "1", "--out", str(out), "-q"])
    assert r.exit_code == 0, r.output
    assert "0 computed now, 16 resumed" in r.output and f"2 parameters, grid design; writing to {out}/" in r.output
    for name in ("results.parquet", "results.csv", "study.json", "feasible.png", "friction_power.total.png",
                 "liftoff_fraction.png"):
        assert (out / name).stat().st_size > 0, name
    # the spreadsheet's table is the Parquet one, each column's unit in its header (it had none)
    csv, table = pd.read_csv(out / "results.csv"), read_results(out)
    assert list(csv.columns[:9]) == ["point", "scene_hash", "status", "stop", "warnings", "spring.ks [N/m]",
                                     "spring.delta_s [m]", "friction_power.total [W]", "friction_power.housing [W]"]
    assert csv["spring.ks [N/m]"].tolist() == table["spring.ks"].tolist() and len(csv.columns) == len(table.columns)
    assert "feasible (liftoff_fraction <= 0; friction_power.total <= 35 W)" in r.output
    bad = tmp_path / "bad.toml"
    bad.write_text(LIGHT.replace('"revolutions"]', '"revolution"]'))
    r = CliRunner().invoke(main, ["sweep", str(bad), "--out", str(tmp_path / "b")])
    assert r.exit_code == 1 and "collect.quantities" in r.output and "did you mean 'revolutions'" in r.output
    r = CliRunner().invoke(main, ["sweep", "--list-quantities"])
    assert r.exit_code == 0 and "friction_power.total" in r.output and "liftoff_fraction" in r.output
    # a folder that holds another study (another name) is refused before anything is written: nothing says it is
    # written to
    edited = tmp_path / "edited.toml"
    edited.write_text(LIGHT.replace('name = "light"', 'name = "other"').replace('"solver.rtol" = 1e-4',
                                                                                 '"solver.rtol" = 1e-5'))
    r = CliRunner().invoke(main, ["sweep", str(edited), "--workers", "1", "--out", str(out), "-q"])
    assert r.exit_code == 1 and "holds the results of another study" in r.output, r.output
    assert "writing to" not in r.output, r.output


@pytest.mark.slow
def test_a_signal_while_the_figures_are_drawn_finishes_them_and_exits_as_interrupted(serial, tmp_path, signalled_in):
    """SIGTERM while a finished sweep drew its figures killed it (exit -15, half-written figure files left)."""
    import signal

    from click.testing import CliRunner

    import apexseal.runtime.studies.sweep.figures as figures
    from apexseal.cli import main

    signalled_in(figures, "sweep_figures")  # noted, not acted on, until the figures are written
    study = tmp_path / "light.toml"
    study.write_text(LIGHT)
    out = Path(serial.folder)
    r = CliRunner().invoke(main, ["sweep", str(study), "--workers", "1", "--out", str(out), "-q"])
    assert r.exit_code == 128 + signal.SIGTERM, r.output
    assert "while the figures were drawn: they were finished first" in r.output
    assert "wrote results.parquet, results.csv and" in r.output and not list(out.glob(".*.tmp"))


@pytest.mark.slow
def test_a_script_without_the_main_guard_is_told_to_add_it(tmp_path):
    """A script that calls run_sweep at its top level: Dask's workers import it and fail to start; the error says
    why and what to write, instead of Dask's bare "Nanny failed to start"."""
    import subprocess
    import sys

    from sweep_helpers import LIGHT

    (tmp_path / "light.toml").write_text(LIGHT)
    (tmp_path / "sweep.py").write_text("from apexseal.runtime.studies.sweep import load_study, run_sweep\n"
                                       "run_sweep(load_study('light.toml'), 'out', workers=2, quiet=True)\n")
    run = subprocess.run([sys.executable, "sweep.py"], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert run.returncode != 0
    assert "Each worker imports the script sweep.py" in run.stderr
    assert 'if __name__ == "__main__":' in run.stderr.splitlines()[-1]


def test_a_script_read_from_standard_input_is_told_to_use_a_file_or_one_worker(tmp_path):
    """``python - < sweep.py``: the main module's __file__ is "<stdin>", which Dask's worker processes try to import
    and cannot, so they fail to start whatever the script holds; the error told to add the `__main__` guard, which
    cannot help. It says the script has no file, and to save it to one or run with workers=1."""
    import subprocess
    import sys

    from sweep_helpers import LIGHT

    (tmp_path / "light.toml").write_text(LIGHT)
    script = ("from apexseal.runtime.studies.sweep import load_study, run_sweep\n"
              "if __name__ == '__main__':\n"
              "    run_sweep(load_study('light.toml'), 'out', workers=2, quiet=True)\n")
    run = subprocess.run([sys.executable, "-"], input=script, cwd=tmp_path, capture_output=True, text=True,
                         timeout=300)
    assert run.returncode != 0
    last = run.stderr.splitlines()[-1]
    assert "this one has no file (<stdin>: it was read from standard input)" in last, run.stderr
    assert "guard cannot help: save the script to a file and run that, or run the points in this process with " \
           "workers=1" in last
    assert not (tmp_path / "out" / "results.parquet").exists()


def test_the_models_are_built_once_before_the_points_and_a_signal_there_stops_the_sweep(serial, tmp_path, monkeypatch):
    """The sweep builds each distinct model once in its own process, its stages reported (inside the points a cold
    model was derived and compiled silently, by every worker at once); a Ctrl-C there computes nothing."""
    import apexseal.runtime.api as api

    real, built = api.model_functions, []

    def counted(scene, **kw):
        built.append(scene.effects)
        return real(scene, **kw)

    monkeypatch.setattr(api, "model_functions", counted)
    report = run_sweep(light_study(), tmp_path / "a", workers=1, quiet=True)
    assert report.computed == len(report.table) > 1 and len(built) == 1 + report.computed  # once, then per point

    def interrupted(scene, **kw):
        raise KeyboardInterrupt

    monkeypatch.setattr(api, "model_functions", interrupted)
    report = run_sweep(light_study(), tmp_path / "b", workers=1, quiet=True)
    assert report.interrupted and report.computed == 0 and report.where.startswith("nothing computed: stopped while")

    def broken(scene, **kw):
        raise RuntimeError("no compiler (test)")

    monkeypatch.setattr(api, "model_functions", broken)  # a model that fails to build: its points say why
    report = run_sweep(light_study(), tmp_path / "c", workers=1, quiet=True)
    assert not report.interrupted and report.computed == report.failed == len(report.table) > 1
    assert (report.table["status"] == "error").all() and report.table["stop"].str.contains("no compiler").all()


@pytest.fixture
def not_a_scheduler():
    """Two addresses with no Dask scheduler: a port nothing listens on, and one where a server answers that is not
    Dask (as a web server at a mistyped port would); Dask's connection timeout cut to 2 s."""
    import socket
    import threading

    import dask

    closed = socket.socket()
    closed.bind(("127.0.0.1", 0))  # bound, never listening: connections are refused
    web = socket.socket()
    web.bind(("127.0.0.1", 0))
    web.listen()

    def answer():
        while True:
            try:
                conn, _ = web.accept()
            except OSError:
                return
            conn.sendall(b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n" * 4)
            time.sleep(0.5)
            conn.close()

    threading.Thread(target=answer, daemon=True).start()
    import distributed  # noqa: F401 - its defaults loaded first: set() on a key of none would drop them on exit
    with dask.config.set({"distributed.comm.timeouts.connect": "2s"}):
        yield [f"tcp://127.0.0.1:{s.getsockname()[1]}" for s in (closed, web)]
    closed.close()
    web.close()


def test_a_scheduler_that_does_not_answer_is_refused_naming_it_before_anything_is_written(not_a_scheduler, tmp_path):
    """An unreachable scheduler was found only after the folder was taken and the command said it wrote to it; a
    server there that is not Dask ended in a MemoryError traceback (its bytes read as a frame's length)."""
    from click.testing import CliRunner

    from apexseal.cli import main
    from apexseal.runtime.studies.sweep.execute import SchedulerError

    study = tmp_path / "light.toml"
    study.write_text(LIGHT)
    for k, address in enumerate(not_a_scheduler):
        started = [None]
        with pytest.raises(SchedulerError) as info:
            run_sweep(light_study(), tmp_path / f"api{k}", scheduler=address, quiet=True,
                      on_start=started.clear)  # a call on a started sweep; none expected
        text = str(info.value)
        assert text.startswith(f"scheduler = {address!r}: no Dask scheduler answered there"), text
        assert "allowed: the address of a running Dask scheduler" in text, text
        assert started == [None] and not (tmp_path / f"api{k}").exists()
        r = CliRunner().invoke(main, ["sweep", str(study), "--scheduler", address, "--out", str(tmp_path / f"c{k}")])
        assert r.exit_code == 1 and f"--scheduler {address}: no Dask scheduler answered there" in r.output, r.output
        assert "writing to" not in r.output and not (tmp_path / f"c{k}").exists(), r.output
    # and no thread of Dask's is left running (the later tests' figure workers fork, which threads make unsafe)
    import threading

    assert not [t.name for t in threading.enumerate() if t.name == "IO loop"]


@pytest.mark.slow
@pytest.mark.parametrize("where", ["serial", "LocalCluster"])
def test_the_bar_shows_how_far_the_long_points_running_have_got(where, tmp_path, monkeypatch, capsys):
    """The bar counted finished points only: a point of minutes left it still for minutes. Now a point running
    longer than watch.LONG_POINT_S is shown with its revolutions and time, serially and from the workers (here
    every point counts as long)."""
    from dask.distributed import Client

    from apexseal.runtime.studies.sweep import watch
    from apexseal.runtime.studies.sweep.execute import local_cluster

    monkeypatch.setattr(watch, "LONG_POINT_S", 0.0)
    monkeypatch.setattr(watch, "EVERY_S", 0.01)
    study = light_study(**{'"operation.revolutions" = 1': '"operation.revolutions" = 30',
                           '"1 mm", "2 mm", "3 mm", "4 mm"': '"2 mm"', "points = 4": "points = 2"})
    if where == "serial":
        report = run_sweep(study, tmp_path / "o", workers=1)
    else:
        with local_cluster(1) as cluster, Client(cluster) as client:
            report = run_sweep(study, tmp_path / "o", client=client)
    assert report.complete
    bar = capsys.readouterr().err
    assert re.search(r"failed=0, point [01]: \d+(\.\d+)?/30 rev, \ds", bar), bar


def test_a_long_point_is_described_with_its_revolutions_and_time():
    from apexseal.runtime.studies.sweep.watch import describe

    running = {3: (0.25, 20, 1.0), 12: (3.5, 20, 65.2), 4: (10.0, 20, 30.0), 7: (1.0, 20, 2.5)}
    assert describe(running) == "point 12: 3.5/20 rev, 1m05s; point 4: 10/20 rev, 30s; 1 more"
    assert describe({3: (0.25, 20, 1.0)}) == ""
    assert describe({0: (0.0, 0, 2.0)}) == "point 0: starting, 2s"  # its run not begun (the model compiling)


@pytest.mark.slow
def test_a_sweep_on_a_scheduler_that_answers_runs_there(tmp_path):
    """The scheduler is reached by Dask's handshake before the Client (execute._probe): a scheduler that answers
    (here a LocalCluster's, over TCP, as `dask scheduler` serves) runs the sweep as its serial run does."""
    from dask.distributed import LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp",
                      dashboard_address=None) as cluster:
        there = run_sweep(light_study(), tmp_path / "there", scheduler=cluster.scheduler_address, quiet=True)
    here = run_sweep(light_study(), tmp_path / "here", workers=1, quiet=True)
    assert len(there.table) == len(here.table) == 16
    pd.testing.assert_frame_equal(stable(there.table), stable(here.table))


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["ctrl-c", "sigterm"])
def test_a_signal_stops_a_script_s_sweep_once_its_points_are_kept(tmp_path, signum):
    """run_sweep from a script returned its report (interrupted) after a Ctrl-C or a SIGTERM without a word, and the
    script went on and exited 0. Now, as apexseal.simulate: after a Ctrl-C RunInterrupted carries the report, after
    a SIGTERM the process ends by it, saying what was kept; the finished points are in the folder either way."""
    study = tmp_path / "light.toml"
    study.write_text(LIGHT)
    out = tmp_path / "out"
    script = tmp_path / "go.py"
    script.write_text(f"""
import apexseal
from apexseal.runtime.studies.sweep import load_study, run_sweep

try:
    report = run_sweep(load_study({str(study)!r}), {str(out)!r}, workers=1, quiet=True)
    print("returned", report.interrupted, flush=True)
except apexseal.RunInterrupted as stop:
    print("stopped:", stop.result.interrupted, len(stop.result.table), flush=True)
    raise
print("the script went on", flush=True)
""")
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _wait_for_points(out, proc, 2)
    proc.send_signal(signum)
    stdout, stderr = proc.communicate(timeout=120)
    assert "returned" not in stdout and "the script went on" not in stdout, stdout + stderr
    finished = len(read_results(out))
    assert 2 <= finished < 16
    if signum == signal.SIGINT:
        assert f"stopped: True {finished}" in stdout and "RunInterrupted: the sweep was interrupted by Ctrl-C" in stderr
    else:
        assert proc.returncode == -signal.SIGTERM, stdout + stderr
        assert f"apexseal: SIGTERM: the sweep was stopped: {finished} of 16 points finished, kept in" in stderr


def _sweep_of_one_preload(tmp_path, parameter: str, base: str = LIGHT, code: int = 0):
    """The light study (or ``base``, a variant of it) with its spring stiffness replaced by ``parameter`` (a
    ``[parameters."..."]`` table) at one preload, 2 mm, run by the command (its exit status ``code``): its text,
    output and table."""
    from click.testing import CliRunner

    from apexseal.cli import main

    ks = '[parameters."spring.ks"]\nfrom = "3e3 N/m"\nto = "2e4 N/m"\npoints = 4\nscale = "log"'
    text = base.replace(ks, parameter).replace('values = ["1 mm", "2 mm", "3 mm", "4 mm"]', 'values = ["2 mm"]')
    (tmp_path / "start.toml").write_text(text)
    r = CliRunner().invoke(main, ["sweep", str(tmp_path / "start.toml"), "-w", "1", "-q", "--no-figures", "-o",
                                  str(tmp_path / "o")])
    assert r.exit_code == code, r.output
    return text, r, read_results(tmp_path / "o")


def test_a_point_refused_for_its_values_is_invalid_and_not_retried(tmp_path):
    """A point whose start is refused for its scene's values alone was a ``failed`` row, and the command offered
    --retry-failed, which computes the same refusal again. Such a point is ``invalid`` with the reason, the command
    says no retry changes it, and --retry-failed leaves it; a value the scene itself refuses (a housing too soft for
    the preload, once refused only at the run's start) refuses the study before any point runs."""
    from apexseal.runtime.studies.sweep import StudyError, study_from_toml

    soft = '[parameters."contacts.kw"]\nvalues = ["1e9 N/m", "1e4 N/m"]'
    text, r, df = _sweep_of_one_preload(tmp_path, '[parameters."operation.initial_state.y"]\nvalues = ["0 mm", "0.4 mm"]')
    assert df["status"].tolist() == ["completed", "invalid"] and "inside a wall" in df.loc[1, "stop"]
    assert "1 point invalid: refused at the start" in r.output and "--retry-failed" not in r.output
    retried = run_sweep(study_from_toml(text, source="start.toml"), tmp_path / "o", workers=1, retry_failed=True,
                        quiet=True)
    assert (retried.computed, retried.retried) == (0, 0)
    with pytest.raises(StudyError, match=r"parameters.contacts.kw = .*allowed: delta_w <= 0.1 Ws .*\(point 1\)"):
        run_sweep(study_from_toml(text.replace('values = ["0 mm", "0.4 mm"]', 'values = ["0 mm"]') + soft,
                                  source="soft.toml"), tmp_path / "soft", workers=1, quiet=True)


def test_a_sweep_until_periodic_has_a_periodic_column_and_says_which_points_did_not_become_periodic(tmp_path):
    """results.csv of a sweep whose scene asks until_periodic did not say which points reached periodicity: it has
    ``periodic`` and ``periodic_change`` columns (summary.json's run.periodic), and the command's closing lines say
    how many points did not become periodic."""
    base = LIGHT.replace('"operation.revolutions" = 1', '"operation.revolutions" = 3\n"operation.until_periodic" = true')
    _, r, df = _sweep_of_one_preload(tmp_path, '[parameters."operation.periodic_tol"]\nvalues = [1e-6, 0.5]', base)
    assert df["periodic"].tolist() == [False, True] and df["revolutions"].tolist() == [3, 2]
    assert (df["periodic_change"] > df["operation.periodic_tol"]).tolist() == [True, False]
    assert df.attrs["units"]["periodic_change"] == "1"
    assert "1 of 2 points did not become periodic (the periodic and periodic_change columns" in r.output
    assert "): point 0; more revolutions" in r.output


def test_a_sweep_stopped_before_its_first_point_says_nothing_of_periodicity(tmp_path):
    """The table of a sweep with no finished point held the periodic columns, and the command then said "all 0
    points became periodic (the periodic column)" of a study that never asked (stopped before its first point)."""
    from apexseal.runtime.studies.sweep.store import PERIODIC, Store

    table = Store(tmp_path / "o").table(light_study())
    assert table.empty and not set(PERIODIC) & set(table.columns)
    assert {"point", "status", "spring.ks", "friction_power.total"} <= set(table.columns)


def test_invalid_points_are_counted_apart_and_said_without_a_crank_angle(tmp_path):
    """Points refused at their start were counted ``failed=`` by the progress bar while the closing line said
    "invalid", their stop began with a meaningless "stopped at crank angle 0.000 deg in mode ...:", and the
    closing sentence said "3 points invalid: ... the values of its scene". Now the bar counts them ``invalid=``,
    the stop is the refusal's reason alone, and the sentence agrees in number."""
    from types import SimpleNamespace

    from apexseal.runtime.studies.sweep.watch import Bar

    _, r, df = _sweep_of_one_preload(tmp_path, '[parameters."operation.initial_state.y"]\nvalues = ["0.4 mm", "0.5 mm"]',
                                     code=1)  # no point completed
    assert df["status"].tolist() == ["invalid", "invalid"] and "none of the 2 points completed" in r.output
    assert not df["stop"].str.startswith("stopped at crank angle").any() and df["stop"].str.contains("wall").all()
    assert "2 points invalid: refused at the start for the values of their scenes" in r.output
    shown = []
    bar = Bar(SimpleNamespace(set_postfix_str=lambda s, refresh: shown.append(s), update=lambda n: None))
    for status in ("invalid", "completed", "failed", "invalid"):
        bar.point_done(status)
    assert shown[-1] == "failed=1, invalid=2", shown


def test_anything_but_a_study_or_its_file_is_a_clear_type_error(tmp_path):
    """The error named apexseal.load_study, which did not exist (AttributeError): the sweep's functions are
    apexseal's own names, each the module's function."""
    import apexseal
    from apexseal.runtime.studies.sweep import load_study

    with pytest.raises(TypeError, match=r"expected a Study \(apexseal.load_study\(path\)\)"):
        run_sweep(42, tmp_path / "bad", workers=1, quiet=True)
    assert (apexseal.load_study, apexseal.run_sweep, apexseal.read_results) == (load_study, run_sweep, read_results)
    assert {"load_study", "run_sweep", "read_results"} <= set(apexseal.__all__)


@pytest.mark.slow  # 7 s of a 2-core test process: in the second step, to keep the default suite under 10 min
def test_a_study_file_s_path_is_a_study(tmp_path):
    """run_sweep("tiny.toml", ...) failed inside with AttributeError: 'str' object has no attribute 'parameters'
    (simulate takes a scene file's path, so a Python user tries this): a path is loaded as the study file it is."""
    path = tmp_path / "light.toml"
    path.write_text(LIGHT)
    report = run_sweep(str(path), tmp_path / "from-path", workers=1, quiet=True)
    assert stable(report.table).equals(stable(run_sweep(light_study(), tmp_path / "from-study", workers=1,
                                                        quiet=True).table))


def test_one_point_of_a_sweep_is_written_as_a_scene_to_simulate_alone(serial, tmp_path):
    """A sweep keeps a row of numbers per point, and its folder is not a result (`apexseal show` refuses it): a
    point could be looked at only by rebuilding its scene by hand. --scene-of N writes it, every value explicit;
    it loads as the point's own scene (the row's scene_hash), and a point outside the study is told the range."""
    from click.testing import CliRunner

    import apexseal
    from apexseal.cli import main
    from apexseal.runtime.studies.sweep import point_scene

    study = tmp_path / "light.toml"
    study.write_text(LIGHT)
    r = CliRunner().invoke(main, ["sweep", str(study), "--scene-of", "5", "-o", str(tmp_path / "o")])
    assert r.exit_code == 0 and f"`apexseal simulate {tmp_path / 'o' / 'point-5.toml'}` runs point 5 alone" in r.output
    scene = apexseal.load_scene(tmp_path / "o" / "point-5.toml")
    assert scene.content_hash() == serial.table.loc[5, "scene_hash"] == point_scene(study, 5).content_hash()
    assert not (tmp_path / "o" / "points").exists()  # nothing of the sweep ran
    r = CliRunner().invoke(main, ["sweep", str(study), "--scene-of", "16", "-o", str(tmp_path / "o")])
    assert r.exit_code == 2 and "16: allowed: an integer 0 <= point <= 15 (the study light has 16 points" in r.output
