"""``apexseal simulate --timings``: the split of the wall time is printed, and its stages add up to the wall time."""

from __future__ import annotations

import json
import subprocess
import time

import pytest

from apexseal.cli import command
from apexseal.runtime.bench.e2e import VARIANTS, e2e_md, end_to_end


def _simulate(tmp_path, *extra):
    w0 = time.perf_counter()
    proc = subprocess.run(command("simulate", "--revolutions", "1", "--quiet", "--out", str(tmp_path), *extra),
                          capture_output=True, text=True, check=False)
    return proc, time.perf_counter() - w0


def test_timings_are_printed_and_sum_to_the_wall_time(tmp_path):
    proc, wall = _simulate(tmp_path, "--timings", "--no-figures")
    assert proc.returncode == 0, proc.stderr
    assert "timings (wall, s; total" in proc.stdout
    line = next(x for x in proc.stdout.splitlines() if x.startswith("timings-json "))
    t = json.loads(line.split(" ", 1)[1])
    stages = t["stages"]
    for k in ("import", "scene", "load", "compile", "integrate", "assemble", "save"):
        assert k in stages and stages[k] >= 0, k
        assert f"  {k} " in proc.stdout
    assert "figures" not in stages
    assert all(v < wall for v in stages.values())
    # the stages cover the command from its first line to the report: only echoes fall between them
    assert sum(stages.values()) == pytest.approx(t["total_s"], abs=0.05 + 0.02 * t["total_s"])
    # from process start (Linux) to the report: the subprocess's wall less the interpreter's shutdown
    if "startup" in stages:
        assert t["total_s"] <= wall + 0.05 and t["total_s"] > 0.6 * wall, (t["total_s"], wall)


def test_no_timings_without_the_flag(tmp_path):
    proc, _ = _simulate(tmp_path, "--no-figures")
    assert proc.returncode == 0, proc.stderr
    assert "timings (wall" not in proc.stdout and "timings-json" not in proc.stdout


@pytest.mark.slow
def test_bench_end_to_end_split_with_figures():
    e2e = end_to_end(revolutions=1, repeats=1, log=lambda _: None)
    assert list(e2e["variants"]) == [name for name, _, _ in VARIANTS]
    for name in e2e["variants"]:
        v = e2e["variants"][name]
        assert v["stages_s"]["integrate"] > 0 and sum(v["stages_s"].values()) == pytest.approx(v["wall_s"], rel=0.05)
    assert "figures" in e2e["variants"]["with figures"]["stages_s"]
    assert "| integrate |" in "\n".join(e2e_md(e2e))
