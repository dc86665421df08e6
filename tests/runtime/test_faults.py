"""Faults during a run and while saving: nothing lost, nothing mixed, nothing unchecked (docs/bad-input.md, "Faults").

Signals are sent to a real ``apexseal simulate`` subprocess (interpreted integrator, 360 samples: about a second
per revolution, so a signal lands inside a CasADi call); a full disk is a patched write; mixed folders are built
from two real results.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from apexseal.cli import command
from apexseal.files import sha256_bytes
from apexseal.runtime.results import folder as folder_mod
from apexseal.runtime.results.folder import ResultFolder, ResultFolderError, ResultStorageError
from apexseal.runtime.results.result import SimulationResult
from apexseal.runtime.scenes.scene import default_scene_text
from apexseal.runtime.solving import run as sim

SCENES_DIR = Path(__file__).resolve().parents[2] / "runtime" / "scenes"
SAMPLES = 72


def _run(scene, functions, revolutions=2, **kw):
    st = sim.RunSettings(samples_per_revolution=SAMPLES, compile_c=False, revolutions=revolutions)
    return sim.run(functions.sx, scene.parameter_vector(), st, theta_start=0.0, state0=np.zeros(6),
                   pressure=scene.pressure, **kw)


@pytest.fixture(scope="module")
def two_results(default_scene, default_functions):
    return _run(default_scene, default_functions, 2), _run(default_scene, default_functions, 1)


def _disk_full_at(monkeypatch, name: str, started: list | None = None) -> None:
    """Writing the file ``name`` of a result folder fails with ENOSPC (every write's name noted in ``started``)."""
    real = folder_mod._write_bytes

    def write(path, data):
        if started is not None:
            started.append(path.name)
        if path.name == name:
            raise OSError(28, "No space left on device")
        real(path, data)

    monkeypatch.setattr(folder_mod, "_write_bytes", write)


# ---------------------------------------------------------------- the result folder is one unit
def test_streamed_folder_round_trip_and_counts(default_scene, default_functions, tmp_path):
    sink = ResultFolder(tmp_path / "o")
    r = _run(default_scene, default_functions, 3, sink=sink)
    sink.commit()
    meta = json.loads((tmp_path / "o" / "result.json").read_text())
    assert meta["status"] == "completed" and meta["samples"] == r.n == 1 + 3 * SAMPLES
    assert [p["samples"] for p in meta["parts"]] == [1 + SAMPLES, SAMPLES, SAMPLES]  # one part per revolution
    with np.load(tmp_path / "o" / meta["parts"][1]["file"]) as d:
        assert str(d["run_id"]) == meta["run_id"] and int(d["samples"]) == SAMPLES
    back = SimulationResult.load(tmp_path / "o")
    assert np.array_equal(back.state, r.state) and back.modes == r.modes and back.info["run_id"] == meta["run_id"]
    assert not list(tmp_path.glob("o.partial-*"))


def test_in_memory_and_streamed_runs_agree(default_scene, default_functions, two_results, tmp_path):
    sink = ResultFolder(tmp_path / "o")
    streamed = _run(default_scene, default_functions, 2, sink=sink)
    mem = two_results[0]
    assert np.array_equal(streamed.state, mem.state) and np.array_equal(streamed.theta, mem.theta)
    assert all(np.array_equal(streamed.outputs[k], v) for k, v in mem.outputs.items())


@pytest.mark.parametrize("keep", [folder_mod.KEEP_BYTES, 0])
def test_finish_returns_what_reading_the_folder_gives(default_scene, default_functions, tmp_path, monkeypatch, keep):
    """finish() joins the parts it wrote (within KEEP_BYTES) instead of reading the folder back: the same result
    (the run adds its stage timings to the returned info afterwards)."""
    monkeypatch.setattr(folder_mod, "KEEP_BYTES", keep)
    sink = ResultFolder(tmp_path / "o")
    r = _run(default_scene, default_functions, 2, sink=sink, info={"note": ("a", 1)})
    assert (sink.kept is None) and sink.final
    back = folder_mod.read(sink.staging)
    for name in ("theta", "time", "state", "closed", "events"):
        assert np.array_equal(getattr(r, name), getattr(back, name)), name
    assert r.outputs.keys() == back.outputs.keys() and all(np.array_equal(r.outputs[k], back.outputs[k]) for k in r.outputs)
    assert r.modes == back.modes and r.guard_names == back.guard_names
    assert (r.status, r.stop) == (back.status, back.stop)
    assert set(r.info) - {"timings_s"} <= set(back.info)
    assert r.info["note"] == ["a", 1] and r.info["run_id"] == back.info["run_id"]


def _mixed(tmp_path, two_results, edit) -> Path:
    a, b = tmp_path / "a", tmp_path / "b"
    two_results[0].save(a, csv=True)
    two_results[1].save(b, csv=True)
    edit(a, b)
    return a


def _copy_part(a, b):
    shutil.copy(b / "parts" / "part-00000.npz", a / "parts" / "part-00000.npz")


def _relabel_part(a, b):  # a part of another run with result.json's hash updated: the run id still differs
    _copy_part(a, b)
    meta = json.loads((a / "result.json").read_text())
    meta["parts"][0]["sha256"] = json.loads((b / "result.json").read_text())["parts"][0]["sha256"]
    (a / "result.json").write_text(json.dumps(meta))


def _short_state(a, b):  # a state array shorter than theta, with a matching hash
    p = a / "parts" / "part-00000.npz"
    with np.load(p) as d:
        arrays = {k: d[k] for k in d.files}
    arrays["state"] = arrays["state"][:, :-1]
    np.savez(p, **arrays)
    meta = json.loads((a / "result.json").read_text())
    meta["parts"][0]["sha256"] = sha256_bytes(p.read_bytes())
    (a / "result.json").write_text(json.dumps(meta))


def _truncated_guards(a, b):
    meta = json.loads((a / "result.json").read_text())
    meta["guard_names"] = meta["guard_names"][:-1]
    (a / "result.json").write_text(json.dumps(meta))


def _old_result_json(a, b):  # the new parts beside an older run's record (the disk-full case of the issue)
    shutil.copy(b / "result.json", a / "result.json")


MIXED = [
    ("part-of-another-run", _copy_part, "sha256 differs"),
    ("part-relabelled", _relabel_part, "mixed folder"),
    ("state-shorter-than-theta", _short_state, "state has shape"),
    ("truncated-guard-list", _truncated_guards, "closed has shape"),
    ("result-json-of-another-run", _old_result_json, "sha256 differs"),
    ("csv-of-another-run", lambda a, b: shutil.copy(b / "trajectory.csv", a / "trajectory.csv"), "mixed folder"),
    ("scene-of-another-run", lambda a, b: (a / "scene.toml").write_text(  # stamped as a run writes it, b's id
        (b / "trajectory.csv").read_text().splitlines()[0] + "\n"), "scene.toml belongs to run"),
    ("legacy-record", lambda a, b: (a / "result.json").write_text('{"status": "completed"}'), "older apexseal"),
    ("missing-part", lambda a, b: (a / "parts" / "part-00000.npz").unlink(), "missing"),
    ("not-a-result", lambda a, b: (a / "result.json").unlink(), "no result.json"),
    # said to "belong to run None" of a "mixed folder" before
    ("unreadable-summary", lambda a, b: (a / "summary.json").write_text("{"), r"summary.json is unreadable \("),
    ("unstamped-csv", lambda a, b: (a / "trajectory.csv").write_text("theta,x\n0,1\n"),
     r"trajectory.csv names no run: not a file of this result"),
]


@pytest.mark.parametrize("edit,message", [m[1:] for m in MIXED], ids=[m[0] for m in MIXED])
def test_mixed_folder_is_refused(tmp_path, two_results, edit, message):
    a = _mixed(tmp_path, two_results, edit)
    with pytest.raises(ResultFolderError, match=message):
        SimulationResult.load(a)


@pytest.mark.parametrize("edit", ["changed", "missing"])
def test_a_pressure_table_changed_or_missing_is_refused(tmp_path, two_results, default_scene, edit):
    """pressure.csv, the table the result's scene.toml names, carries no run id: a changed one (another run's, or an
    edited row) loaded silently, and `result.scene` (and `apexseal simulate <folder>/scene.toml`) was then not the
    scene that ran. result.json records its sha256."""
    result = two_results[1]
    result.scene = default_scene
    folder = result.save(tmp_path / "a")
    assert SimulationResult.load(folder).scene == default_scene
    table = folder / "pressure.csv"
    if edit == "changed":
        lines = table.read_text().splitlines(keepends=True)
        theta, pa, pb = lines[1].split(",")
        table.write_text(lines[0] + f"{theta},{float(pa) + 1e5},{pb}" + "".join(lines[2:]))
    else:
        table.unlink()
    with pytest.raises(ResultFolderError, match="pressure.csv is (not the file result.json recorded|missing)"):
        SimulationResult.load(folder)


def test_summary_of_another_run_is_refused(tmp_path, two_results):
    a, b = tmp_path / "a", tmp_path / "b"
    for r, f in zip(two_results, (a, b), strict=True):
        w = ResultFolder(f)
        w.append(r)
        w.finish(r.status, r.stop, r.info)
        w.write_json("summary.json", {"status": r.status})
        w.commit()
    shutil.copy(b / "summary.json", a / "summary.json")
    with pytest.raises(ResultFolderError, match="summary.json belongs to run"):
        SimulationResult.load(a)


def test_a_full_disk_during_save_keeps_the_previous_result(tmp_path, two_results, monkeypatch):
    """ENOSPC while saving over an earlier result: the earlier result stays whole, the error names the folder."""
    new, old = two_results
    out = tmp_path / "o"
    old.save(out)
    _disk_full_at(monkeypatch, "result.json")
    with pytest.raises(ResultStorageError, match="No space left on device") as err:
        new.save(out)
    assert str(out) in str(err.value) and "previous result" in str(err.value) and "[Errno" not in str(err.value)
    monkeypatch.undo()
    back = SimulationResult.load(out)
    assert back.n == old.n and back.status == "completed"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o"]  # no half folder left behind


def test_a_full_disk_during_a_streamed_run_keeps_the_completed_revolutions(default_scene, default_functions, tmp_path,
                                                                           monkeypatch):
    _disk_full_at(monkeypatch, "part-00002.npz")
    sink = ResultFolder(tmp_path / "o")
    r = _run(default_scene, default_functions, 4, sink=sink)
    assert r.status == "failed" and r.n == 1 + 2 * SAMPLES
    assert r.stop.reason == ("could not write a part (part-00002.npz): No space left on device; the run ends with "
                             "the 2 part(s) written before it")
    # where its samples end, and their mode (the run noticed the failure a revolution or more later, parts being
    # written behind it, and recorded that angle and the folder it then had, renamed by the commit)
    assert r.stop.theta == pytest.approx(r.theta[-1] - r.theta[0]) and r.stop.mode == r.modes[-1]
    sink.commit()
    back = SimulationResult.load(tmp_path / "o")
    assert back.status == "failed" and back.stop == r.stop


def test_a_run_that_keeps_nothing_leaves_no_folder(default_scene, tmp_path, monkeypatch):
    """A full disk at the first revolution (or a crash before it) said "nothing of this run was kept" and left
    o.partial-<id>/ behind, which `show` then took for a run killed before its first revolution. Now the folder
    goes with it, and the message names no folder that is gone."""
    import apexseal

    _disk_full_at(monkeypatch, "part-00000.npz")
    with pytest.raises(ResultStorageError) as err:
        apexseal.simulate(default_scene, revolutions=1, samples_per_revolution=360, out=tmp_path / "o")
    assert "nothing of this run was kept (no complete part was written)" in str(err.value)
    assert list(tmp_path.iterdir()) == []


def test_a_run_that_did_not_complete_never_replaces_a_completed_result(default_scene, default_functions, tmp_path,
                                                                        two_results):
    """A rerun at the same --out that is interrupted or fails (here: a full disk at its third part) leaves the
    completed result of the earlier run in place; its own result stays whole in its .partial- folder. Before, the
    failed rerun replaced a finished result with a fraction of a revolution."""
    out = tmp_path / "o"
    two_results[0].save(out)
    before = SimulationResult.load(out)
    monkeypatch = pytest.MonkeyPatch()
    _disk_full_at(monkeypatch, "part-00002.npz")
    sink = ResultFolder(out)
    failed = _run(default_scene, default_functions, 4, sink=sink)
    monkeypatch.undo()
    where = sink.commit()
    assert failed.status == "failed" and where == sink.staging != out
    assert sink.kept_aside == f"this run ended failed, so the completed result at {out} was kept"
    after = SimulationResult.load(out)
    assert after.info["run_id"] == before.info["run_id"] and after.status == "completed" and after.n == before.n
    assert SimulationResult.load(where).status == "failed"
    done = ResultFolder(out)  # a completed rerun replaces it, as before
    _run(default_scene, default_functions, 1, sink=done)
    assert done.commit() == out and SimulationResult.load(out).info["run_id"] == done.run_id


def test_a_run_never_replaces_a_result_written_at_its_target_while_it_ran(tmp_path, two_results):
    """Two runs into one --out at once: the one that ends second keeps its result in its .partial- folder and says
    why, instead of replacing the other's without a word."""
    out = tmp_path / "o"
    first = ResultFolder(out)
    first.append(two_results[0])
    two_results[1].save(out)  # another run, started later, ends first
    other = SimulationResult.load(out).info["run_id"]
    first.finish("completed", None, two_results[0].info)
    where = first.commit()
    assert where == first.staging and first.kept_aside == f"another run ({other[:12]}) wrote {out} while this one ran"
    assert SimulationResult.load(out).info["run_id"] == other and SimulationResult.load(where).n == two_results[0].n


def test_a_killed_writer_s_temporary_file_is_not_committed(tmp_path, two_results):
    """A figure worker stopped by a signal mid-file leaves .<name>.<random>.tmp in the folder being written: the
    commit removes it, and a folder holding one is still a result that a new run may replace."""
    out = tmp_path / "o"
    writer = ResultFolder(out)
    writer.append(two_results[1])
    writer.finish("completed", None, two_results[1].info)
    (writer.staging / ".fig12_displacements.png.x1y2z3.tmp").write_bytes(b"half a png")
    writer.commit()
    assert not list(out.glob(".*.tmp"))
    (out / ".fig13_forces.png.a1b2c3.tmp").write_bytes(b"left by an older version")
    two_results[0].save(out)  # replaces it: the temporary is apexseal's own
    assert SimulationResult.load(out).n == two_results[0].n


def test_a_part_is_written_beside_the_run_and_a_failed_write_stops_all_later_ones(two_results, tmp_path,
                                                                                    monkeypatch):
    """append() hands a part to a writer thread; the next append() (or sync()) raises that write's error, and no
    part is written after a failed one, so the folder has no gap; finish() still records what was written."""
    started: list[str] = []
    _disk_full_at(monkeypatch, "part-00001.npz", started)
    first = two_results[1]
    sink = ResultFolder(tmp_path / "o", background=True)
    sink.append(first)
    sink.append(first)  # part 0 was written: no error yet
    with pytest.raises(ResultStorageError, match="part-00001.npz.*No space left") as err:
        sink.append(first)  # part 1's error, reported here
    assert "1 completed part(s)" in str(err.value)
    with pytest.raises(ResultStorageError):
        sink.append(first)  # and again: nothing is written after a failed part
    sink.sync()  # reported already: nothing more to raise
    assert started == ["part-00000.npz", "result.json", "part-00001.npz"]
    back = sink.finish("failed", None, {})
    assert back.n == first.n and len(sink.parts) == 1 and back.status == "failed"
    assert first.status == "completed" and "run_id" not in first.info  # the part handed over is not changed
    assert sorted(p.name for p in (sink.staging / "parts").iterdir()) == ["part-00000.npz"]


def test_without_the_writer_thread_a_failed_write_is_reported_by_its_own_append(two_results, tmp_path, monkeypatch):
    """APEXSEAL_WRITE_BEHIND=0, or a process on one core: each part is written in the caller's thread."""
    _disk_full_at(monkeypatch, "part-00001.npz")
    sink = ResultFolder(tmp_path / "o", background=False)
    sink.append(two_results[1])
    assert sorted(p.name for p in (sink.staging / "parts").iterdir()) == ["part-00000.npz"]  # written already
    with pytest.raises(ResultStorageError, match="part-00001.npz"):
        sink.append(two_results[1])  # its own error, at once
    with pytest.raises(ResultStorageError):
        sink.append(two_results[1])


@pytest.mark.parametrize("value,cores,expected", [(None, 2, True), ("1", 2, True), ("0", 2, False), (None, 1, False),
                                                  (" 0 ", 4, False)])
def test_the_writer_thread_is_used_with_a_second_core_unless_switched_off(monkeypatch, value, cores, expected):
    monkeypatch.setattr(folder_mod, "available_cores", lambda: cores)
    if value is None:
        monkeypatch.delenv(folder_mod.WRITE_BEHIND, raising=False)
    else:
        monkeypatch.setenv(folder_mod.WRITE_BEHIND, value)
    assert folder_mod.write_behind() is expected


def test_a_killed_run_leaves_a_loadable_folder(default_scene, default_functions, tmp_path):
    """The progress record after each part: a run that never finishes loads as interrupted, all parts kept."""
    full = _run(default_scene, default_functions, 2)
    sink = ResultFolder(tmp_path / "o")
    first = _run(default_scene, default_functions, 1)
    sink.append(first)  # as the run loop does after the first revolution
    sink.sync()  # written while the second revolution integrates (sync: at the latest)
    live = SimulationResult.load(sink.staging)  # read while the run goes on: it says so, not that it was killed
    assert live.status == "interrupted" and "still going on" in live.stop.reason, live.stop.reason
    # its --out folder, not there yet, was "killed and left what it computed in <partial>: load or resume that"
    # (and resuming it is refused while the run goes on)
    with pytest.raises(ResultFolderError, match=r"does not exist yet: a running process is writing its result in "
                       r".*\.partial-.* \(moved to .* when the run ends\)") as info:
        SimulationResult.load(tmp_path / "o")
    assert "was killed" not in str(info.value)
    os.close(sink._lock)  # then the process dies, and its lock with it
    sink._lock = None  # closed: the folder's release must not close the number again (another file may hold it)
    back = SimulationResult.load(sink.staging)
    assert back.status == "interrupted" and "without its final record" in back.stop.reason
    with pytest.raises(ResultFolderError, match="a run into it was killed and left what it computed in"):
        SimulationResult.load(tmp_path / "o")
    assert back.n == live.n == 1 + SAMPLES and np.array_equal(back.state, full.state[:, :1 + SAMPLES])
    assert not (tmp_path / "o").exists()


def test_a_result_never_replaces_a_folder_of_other_files(tmp_path, two_results):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("keep me")
    with pytest.raises(ResultFolderError, match="notes.txt"):
        two_results[1].save(out)
    assert (out / "notes.txt").read_text() == "keep me" and len(list(tmp_path.iterdir())) == 1


def test_cli_refuses_an_output_folder_of_other_files(tmp_path):
    from click.testing import CliRunner

    from apexseal.cli import main

    (tmp_path / "data.csv").write_text("1,2\n")
    r = CliRunner().invoke(main, ["simulate", "--out", str(tmp_path), "-q", "-n", "1"])
    assert r.exit_code != 0 and "--out" in r.output and "data.csv" in r.output
    assert [p.name for p in tmp_path.iterdir()] == ["data.csv"]


# ---------------------------------------------------------------- chattering covers only the angle reached
def test_chattering_result_covers_only_the_angle_reached(default_functions):
    """tip-chatter stops near 43 deg: its samples and summary end there (0.12 revolutions), not at 360 deg."""
    from hard_helpers import load, simulate

    from apexseal.runtime.results.summary import summarise

    r = simulate(load("tip-chatter"), default_functions.sx, calls_per_revolution=72)
    assert r.status == "chattering", r.stop
    assert r.theta[-1] <= r.stop.theta + 1e-12 and r.theta[-1] > r.stop.theta - np.radians(1.0)
    s = summarise(r)
    assert s["revolutions"] == pytest.approx(r.stop.theta / (2 * np.pi)) and s["revolutions"] < 0.5


# ---------------------------------------------------------------- signals, sent to a real process
@pytest.fixture(scope="module")
def slow_scene(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("signals")
    text = default_scene_text().replace("samples_per_revolution = 3600", "samples_per_revolution = 360")
    (d / "s.toml").write_text(text.replace("interpreted = false", "interpreted = true"))
    shutil.copy(SCENES_DIR / "expander-pressure.csv", d)
    return d / "s.toml"


def _start(scene: Path, out: Path, revolutions: int = 200, ignoring: int | None = None) -> subprocess.Popen:
    """``apexseal simulate`` of ``scene``; started with the signal ``ignoring`` ignored, as a shell starts a
    background job with SIGINT ignored."""
    cmd = command("simulate", str(scene), "-n", str(revolutions), "--out", str(out), "-q", "--no-figures")
    ignore = None if ignoring is None else lambda: signal.signal(ignoring, signal.SIG_IGN)
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=os.environ.copy(),
                            preexec_fn=ignore)


def _signalled(proc: subprocess.Popen, signum: int, code: int, what: str) -> tuple[str, str]:
    """Send ``signum`` to ``proc``; it must end within a few seconds with exit code ``code``: its output."""
    sent = time.monotonic()
    proc.send_signal(signum)
    stdout, stderr = proc.communicate(timeout=60)
    assert time.monotonic() - sent < 10.0, f"{what} must end within a few seconds"
    assert proc.returncode == code, (stdout, stderr)
    return stdout, stderr


def _wait_for_parts(out: Path, proc: subprocess.Popen, count: int, timeout: float = 120.0) -> Path:
    t_end = time.monotonic() + timeout
    while time.monotonic() < t_end:
        for staging in out.parent.glob(f"{out.name}.partial-*"):
            if (staging / "parts" / f"part-{count - 1:05d}.npz").exists():
                return staging
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.05)
    proc.kill()
    raise AssertionError(f"no {count} parts after {timeout} s")


@pytest.mark.parametrize("signum,code,words", [(signal.SIGTERM, 143, "SIGTERM"),
                                               pytest.param(signal.SIGINT, 130, "Ctrl-C", marks=pytest.mark.slow),
                                               pytest.param(signal.SIGHUP, 129, "SIGHUP (its terminal or session closed)",
                                                            marks=pytest.mark.slow)])
def test_a_signal_keeps_every_completed_revolution(slow_scene, tmp_path, signum, code, words):
    """SIGHUP (a terminal or ssh session that closed) ended the run as SIGKILL does (its .partial- folder left
    interrupted): it is caught as SIGTERM is."""
    out = tmp_path / "o"
    proc = _start(slow_scene, out)
    _wait_for_parts(out, proc, 2)
    time.sleep(0.3)  # into the next revolution's integrator call
    stdout, stderr = _signalled(proc, signum, code, "the run")
    assert "Traceback" not in stderr and "NotImplementedError" not in stderr, stderr
    assert f"continue it: apexseal simulate --resume {out}" in stderr
    r = SimulationResult.load(out)
    assert r.status == "interrupted" and words in r.stop.reason
    assert r.n >= 1 + 2 * 360 and (r.n - 1) % 360 == 0  # whole revolutions: every completed call kept
    assert r.theta[-1] == pytest.approx(r.stop.theta)
    assert json.loads((out / "summary.json").read_text())["status"] == "interrupted"
    assert not list(tmp_path.glob("o.partial-*"))


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_the_run_was_started_ignoring_stays_ignored(slow_scene, tmp_path, signum):
    """A run caught SIGINT and SIGTERM even when its process was started with them ignored: a job that a script
    starts in the background (the shell ignores SIGINT there, so that Ctrl-C in the terminal stops the script, not
    the job) was stopped by the Ctrl-C too, and a SIGTERM ignored on purpose stopped the run but not the process.
    Now a signal ignored at the start stays ignored, as Python leaves it: the run goes on to its end."""
    out = tmp_path / "o"
    proc = _start(slow_scene, out, revolutions=6, ignoring=signum)
    _wait_for_parts(out, proc, 1)
    assert proc.poll() is None, "the signal must reach the run while it goes on"
    proc.send_signal(signum)
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 0, (stdout, stderr)
    r = SimulationResult.load(out)
    assert r.status == "completed" and r.revolutions == 6


@pytest.mark.slow
def test_a_signal_says_the_figures_were_not_drawn_and_how_to_draw_them(slow_scene, tmp_path):
    """The figures of a run a signal stopped are skipped (the user asked it to stop); it was not said."""
    out = tmp_path / "o"
    proc = subprocess.Popen(command("simulate", str(slow_scene), "-n", "200", "--out", str(out), "-q"),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=os.environ.copy())
    _wait_for_parts(out, proc, 2)
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 130, (stdout, stderr)
    assert f"figures not drawn (a signal came): apexseal show {out} --figures draws them" in stderr
    assert not list(out.glob("*.png"))


def test_a_second_signal_while_saving_corrupts_nothing(slow_scene, tmp_path):
    out = tmp_path / "o"
    proc = _start(slow_scene, out)
    _wait_for_parts(out, proc, 2)
    proc.send_signal(signal.SIGINT)
    for _ in range(20):  # keep pressing Ctrl-C while the run stops and saves
        time.sleep(0.02)
        if proc.poll() is not None:
            break
        proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 130, (stdout, stderr)
    assert "Traceback" not in stderr, stderr
    r = SimulationResult.load(out)
    assert r.status == "interrupted" and r.n >= 1 + 2 * 360


@pytest.mark.parametrize("signum,code,words", [
    pytest.param(signal.SIGINT, 130, "the user (Ctrl-C, SIGINT)", marks=pytest.mark.slow),
    (signal.SIGTERM, 143, "SIGTERM")])
def test_a_signal_during_the_benchmark_s_settling_ends_it_as_simulate_ends(tmp_path, signum, code, words):
    """Ctrl-C while `apexseal bench` settled its scene printed a RuntimeError traceback ("settling default failed:
    ... interrupted"): the settling run noted the signal and ended interrupted, which the benchmark took for a
    failure. Now the command ends as a run's Ctrl-C does: one line, exit code 130 (143 for SIGTERM)."""
    out = tmp_path / "bench"
    # one method, interpreted: the settling run is the benchmark's own whatever it times (its --quick methods took
    # some 20 s of compiling before the settling began, on a cold cache)
    proc = subprocess.Popen(command("bench", "--quick", "--methods", "erk-VM", "--scenes", "default", "--no-effects",
                                    "--no-check", "--no-e2e", "--no-gas", "--settle", "100", "--out", str(out)),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=os.environ.copy())
    seen = []
    for line in proc.stderr:  # the model compiled (cached after the first time), then the settling begins
        seen.append(line)
        if "settling 100 revolutions" in line:
            break
    assert proc.poll() is None, "".join(seen)
    time.sleep(0.5)  # into the settling run's integrator calls
    stdout, stderr = _signalled(proc, signum, code, "the benchmark")
    assert "Traceback" not in stderr and "RuntimeError" not in stderr, stderr
    assert f"interrupted by {words}" in stderr and "nothing written" in stderr, stderr
    assert not out.exists() or not any(out.iterdir())


def test_a_killed_run_leaves_the_previous_result_intact(slow_scene, tmp_path, two_results):
    out = tmp_path / "o"
    two_results[1].save(out)  # an earlier result at --out
    before = SimulationResult.load(out)
    proc = _start(slow_scene, out)
    staging = _wait_for_parts(out, proc, 3)
    proc.kill()  # SIGKILL: no handler runs
    proc.communicate(timeout=30)  # reaps it and closes its pipes
    after = SimulationResult.load(out)
    assert after.info["run_id"] == before.info["run_id"] and after.n == before.n and after.ok
    partial = SimulationResult.load(staging)  # what the killed run had completed and recorded
    assert partial.status == "interrupted" and partial.n >= 1 + 2 * 360 and (partial.n - 1) % 360 == 0
    # how it was run, recorded before its first step
    assert partial.info["method"] == "erk" and partial.info["revolutions_asked"] == 200 and partial.info["rtol"] > 0


def test_a_signal_abandons_a_model_load_at_once_but_only_under_stop_signals():
    """StopSignals.abandoning (around the derivation, generation and compilation of a model): a signal raises at
    once inside it, one noted before it raises on entry, the previous raising is restored after it, and without
    an active StopSignals the block is left to Python's own handler."""
    import os
    import signal

    from apexseal.signals import StopSignals

    with StopSignals() as signals:
        with StopSignals.abandoning():
            assert signals.raising
        assert not signals.raising
        reached = []
        with pytest.raises(KeyboardInterrupt), StopSignals.abandoning():
            os.kill(os.getpid(), signal.SIGTERM)
            reached.append(True)  # not reached: the handler raised at the next bytecode
        assert reached == [] and signals.received == [signal.SIGTERM] and not signals.raising
        with pytest.raises(KeyboardInterrupt), StopSignals.abandoning():  # a signal noted before: no work begins
            reached.append(True)
        assert reached == []
    with StopSignals.abandoning():  # nothing active: nothing changes
        reached.append(True)
    assert reached == [True]


def test_an_abandoned_build_stops_its_compilers_and_is_no_missing_compiler():
    """SIGTERM reaches only this process: the compilers a build started are killed with their own programs, not
    waited for; and a compiler that failed because a signal stopped the work raises the interruption instead of
    warning that no compiler is there."""
    import os
    import signal
    import threading
    import time

    from apexseal.generated.compile import fallback
    from apexseal.generated.compiler import run_compiler, stop
    from apexseal.signals import StopSignals

    running: set = set()
    done = []
    worker = threading.Thread(target=lambda: done.append(run_compiler(["sleep", "30"], running=running)))
    worker.start()
    while not running:
        time.sleep(0.01)
    t0 = time.perf_counter()
    stop(running)
    worker.join(5)
    assert done and done[0].returncode == -signal.SIGKILL and time.perf_counter() - t0 < 5 and not running
    with StopSignals():
        os.kill(os.getpid(), signal.SIGTERM)
        with pytest.raises(KeyboardInterrupt):
            fallback("gcc failed on casadi_model.c")


def test_a_signal_abandons_builds_running_in_worker_threads(monkeypatch):
    """The preload study builds two libraries at once, in worker threads, which a signal does not reach: Ctrl-C
    waited for both compilations to end (tens of seconds). Now their compilers are killed and nothing waits."""
    import os
    import signal
    import threading
    import time

    import apexseal.generated.compile as compile_module
    from apexseal.generated.compiler import run_compiler
    from apexseal.signals import StopSignals

    ended = []

    def slow_build(source, *, flags):  # a compiler that would run for 30 s
        ended.append(run_compiler(["sleep", "30"]).returncode)

    monkeypatch.setattr(compile_module, "build_function", slow_build)
    t0 = time.perf_counter()
    threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT)).start()
    with StopSignals(raising=True), pytest.raises(KeyboardInterrupt):
        compile_module.build_function_libraries(["interval", "forward"], flags="optimised")
    assert time.perf_counter() - t0 < 5
    deadline = time.perf_counter() + 5
    while len(ended) < 2 and time.perf_counter() < deadline:
        time.sleep(0.05)
    assert ended == [-signal.SIGKILL, -signal.SIGKILL]


@pytest.mark.slow
def test_sigterm_in_a_script_that_loops_over_runs_ends_it_once_the_run_is_kept(slow_scene, tmp_path):
    """apexseal.simulate caught a SIGTERM, returned the interrupted run and the script went on to its next design
    (a batch scheduler could not stop it): the run is kept, then the signal ends the process."""
    script = tmp_path / "loop.py"
    script.write_text(f"""
import sys
import apexseal

scene = apexseal.load_scene({str(slow_scene)!r})
for k in ("5e3 N/m", "1e4 N/m", "2e4 N/m"):
    r = apexseal.simulate(scene.with_overrides(**{{"spring.ks": k}}), revolutions=200, out={str(tmp_path)!r} + "/" + k[:3])
    print("returned", k, r.status, flush=True)
print("the loop went on to its end", flush=True)
""")
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _wait_for_parts(tmp_path / "5e3", proc, 2)
    proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == -signal.SIGTERM, out + err
    assert "returned" not in out and "the loop went on" not in out
    # it ended without a word on what it kept
    assert re.search(r"apexseal: SIGTERM: the run was stopped: \d+\.\d\d revolutions kept in .*5e3; ending the "
                     r"process", err), err
    from apexseal.runtime.results.result import SimulationResult

    kept = SimulationResult.load(tmp_path / "5e3")  # the interrupted run, moved into place
    assert kept.status == "interrupted" and kept.revolutions >= 2 and "SIGTERM" in kept.stop.describe()
    assert not list(tmp_path.glob("1e4*"))


def test_ctrl_c_in_a_script_that_loops_over_runs_stops_it_once_the_run_is_kept(slow_scene, tmp_path):
    """apexseal.simulate caught a Ctrl-C, returned the interrupted run without a word and the script went on to its
    next design (an optimiser would take the partial run's numbers): the run is kept, then RunInterrupted (a
    KeyboardInterrupt) carries it out of the call, and the script stops as Ctrl-C asks."""
    script = tmp_path / "loop.py"
    script.write_text(f"""
import apexseal

scene = apexseal.load_scene({str(slow_scene)!r})
try:
    for k in ("5e3 N/m", "1e4 N/m"):
        r = apexseal.simulate(scene.with_overrides(**{{"spring.ks": k}}), revolutions=200,
                              out={str(tmp_path)!r} + "/" + k[:3])
        print("returned", k, r.status, flush=True)
except apexseal.RunInterrupted as stop:
    print("stopped:", stop.result.status, stop.result.revolutions >= 2, flush=True)
    raise
""")
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _wait_for_parts(tmp_path / "5e3", proc, 2)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode not in (0, None) and "returned" not in out, out + err
    assert "stopped: interrupted True" in out and "RunInterrupted: the run was interrupted by Ctrl-C" in err
    from apexseal.runtime.results.result import SimulationResult

    kept = SimulationResult.load(tmp_path / "5e3")  # written and moved into place before the exception
    assert kept.status == "interrupted" and "Ctrl-C" in kept.stop.describe()
    assert not list(tmp_path.glob("1e4*"))


def test_ctrl_c_returns_the_run_in_a_session_and_leaves_an_enclosing_owner_s_signal_alone(monkeypatch):
    """In an interactive session (a notebook) the interrupted run is returned, with a warning, for the next cell to
    look at; a Ctrl-C that an enclosing command or study caught is theirs to act on (nothing raised here)."""
    from types import SimpleNamespace

    import apexseal.signals
    from apexseal.runtime.api import RunInterruptedWarning, _after_a_ctrl_c
    from apexseal.signals import RunInterrupted, StopSignals

    result = SimpleNamespace(revolutions=2.0, status="interrupted")
    stop = StopSignals()
    stop.received.append(signal.SIGINT)
    monkeypatch.setattr(apexseal.signals, "interactive", lambda: True)
    with pytest.warns(RunInterruptedWarning, match="the run was interrupted by Ctrl-C: 2.00 revolutions kept in o"):
        assert _after_a_ctrl_c(result, stop, stop, "o") is result
    monkeypatch.setattr(apexseal.signals, "interactive", lambda: False)
    with pytest.raises(RunInterrupted, match="2.00 revolutions kept; the exception's .result holds it") as info:
        _after_a_ctrl_c(result, stop, stop, None)
    assert info.value.result is result and isinstance(info.value, KeyboardInterrupt)
    assert _after_a_ctrl_c(result, stop, StopSignals(), None) is result  # nested: the enclosing one's signal
    assert _after_a_ctrl_c(result, StopSignals(), StopSignals(), None) is result  # no signal
    done = SimpleNamespace(revolutions=2.0, status="completed")  # a Ctrl-C while a completed run was written
    assert _after_a_ctrl_c(done, stop, stop, None) is done


@pytest.mark.slow
def test_a_run_in_another_thread_started_first_does_not_take_the_main_thread_s_signals(slow_scene, tmp_path):
    """A simulate in a worker thread, started before the main thread's, became the active StopSignals (which installs
    no handler outside the main thread): a SIGTERM then killed the process at once and neither result was written.
    Now the main thread's run is stopped, written and moved into place before the signal ends the process."""
    script = tmp_path / "threads.py"
    script.write_text(f"""
import threading
import time
import apexseal

scene = apexseal.load_scene({str(slow_scene)!r})
threading.Thread(target=apexseal.simulate, args=(scene,), kwargs=dict(revolutions=400, out={str(tmp_path / "T")!r}),
                 daemon=True).start()
time.sleep(1)
apexseal.simulate(scene, revolutions=400, out={str(tmp_path / "M")!r})
""")
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _wait_for_parts(tmp_path / "M", proc, 2)
    proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == -signal.SIGTERM, out + err
    from apexseal.runtime.results.result import SimulationResult

    kept = SimulationResult.load(tmp_path / "M")
    assert kept.status == "interrupted" and "SIGTERM" in kept.stop.describe()


def test_a_signal_ends_the_watched_engines_deadline_at_once():
    """A signal sets the deadline of every engine being watched to the past, so an engine that checks its deadline
    inside a call stops there, not at the call's end (a handler that only noted the signal went unnoticed)."""
    import math
    import signal
    from types import SimpleNamespace

    from apexseal.signals import StopSignals

    engine, other = SimpleNamespace(deadline=1e9), SimpleNamespace(deadline=1e9)
    with StopSignals() as signals:
        signals.watch(engine)
        signal.raise_signal(signal.SIGINT)
        assert signals.requested and engine.deadline == -math.inf and other.deadline == 1e9


def test_a_command_stopped_by_a_signal_leaves_the_next_run_of_its_process_catching_signals():
    """The CLI ignores further signals once its interrupted run is written (a Ctrl-C while it exits cannot turn 130
    into a death by signal). It set them to SIG_IGN, which a command run in a process that goes on (the CLI from
    Python, click's test runner) left behind: that process's later runs, and the processes it started, left the
    signals ignored (a run does not take a signal ignored at its start), so a Ctrl-C no longer stopped them. Now
    the command gives the handlers back in such a process, and ignores the signals outright in the console
    script's, which exits."""
    from apexseal.signals import StopSignals, command_scope

    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        with command_scope(exiting=False):
            with StopSignals() as first:
                signal.raise_signal(signal.SIGINT)
                first.ignore_after()
            signal.raise_signal(signal.SIGINT)  # while the command reports: not heeded, raises nothing
        assert {s: signal.getsignal(s) for s in before} == before
        with StopSignals() as later:
            signal.raise_signal(signal.SIGTERM)
            assert later.received == [signal.SIGTERM]
        child = subprocess.run([sys.executable, "-c", "import signal; print(signal.getsignal(signal.SIGINT) is "
                                "signal.SIG_IGN, signal.getsignal(signal.SIGTERM) is signal.SIG_IGN)"],
                               capture_output=True, text=True, timeout=60)
        assert child.stdout.split() == ["False", "False"], child
        with command_scope(exiting=True):  # the console script: the process exits with the command's code
            with StopSignals() as first:
                signal.raise_signal(signal.SIGTERM)
                first.ignore_after()
        assert all(signal.getsignal(s) is signal.SIG_IGN for s in before)
    finally:
        for s, handler in before.items():
            signal.signal(s, handler)


def test_a_run_that_raises_after_a_revolution_was_handed_over_keeps_it(two_results, tmp_path, monkeypatch):
    """The folder of a run that raised was removed when it held no part yet, checked before the writer thread had
    written the revolution handed to it: that revolution went with the folder. The writer is waited for first."""
    import threading

    gate = threading.Event()
    real = folder_mod._write_bytes

    def slow(path, data):
        gate.wait(5)
        real(path, data)

    monkeypatch.setattr(folder_mod, "_write_bytes", slow)
    sink = ResultFolder(tmp_path / "o", background=True)
    sink.append(two_results[1])
    threading.Timer(0.2, gate.set).start()
    with pytest.raises(RuntimeError, match="a crash"), sink.discarded_if_empty():
        raise RuntimeError("a crash")
    assert sink.staging.is_dir() and len(sink.parts) == 1
    empty = ResultFolder(tmp_path / "e")
    with pytest.raises(RuntimeError), empty.discarded_if_empty():
        raise RuntimeError("a crash before the first revolution")
    assert not empty.staging.exists()


def test_a_partial_folder_that_is_gone_is_said_to_be_no_result(tmp_path):
    """Loading a .partial- folder that no longer exists (its resume committed it) raised FileNotFoundError."""
    with pytest.raises(ResultFolderError, match="no result.json"):
        SimulationResult.load(tmp_path / "o.partial-0123456789ab")
