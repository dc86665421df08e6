"""The work-precision benchmark (issue: apexseal bench): `--quick` on a tiny problem, and its building blocks.

No timing is asserted: the machine is shared. What is checked: the outputs exist
and hold what they promise, errors fall with the tolerance, failures are kept.
"""

from __future__ import annotations

import json
import math

import pytest
from click.testing import CliRunner

from apexseal.cli import main
from apexseal.runtime.bench.metrics import pareto, time_at_error
from apexseal.runtime.bench.output import FILES
from apexseal.runtime.bench.timing import BudgetExceeded, measure

TINY = ["bench", "--quick", "--samples", "24", "--span", "20", "--settle", "0", "--methods", "erk-C,scipy-LSODA",
        "--flags", "quick", "--repeats", "1"]


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench")
    res = CliRunner().invoke(main, [*TINY, "--out", str(out)], catch_exceptions=False)
    assert res.exit_code == 0, res.output
    return out, json.loads((out / "results.json").read_text()), res.output


def test_outputs_exist(tiny):
    out, _, stdout = tiny
    for name in FILES:
        assert (out / name).is_file() and (out / name).stat().st_size > 0, name
    assert (out / "work-precision.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "wrote" in stdout


def test_json_fields(tiny):
    _, r, _ = tiny
    for key in ("config", "machine", "model", "compile", "scenes", "summary", "targets", "command"):
        assert key in r, key
    assert r["scenes"][0]["rhs_cost"] and all(c["s"] > 0 for c in r["scenes"][0]["rhs_cost"])
    assert r["machine"]["packages"]["casadi"] and r["machine"]["cpu"]
    scene = r["scenes"][0]
    assert set(scene["problem"]["initial_state"]) == {"x", "y", "phi", "xd", "yd", "phid"}
    ref = scene["reference"]
    assert ref["rtol"] == 1e-12 and ref["check"]["status"] == "ok"
    assert ref["check"]["difference"]["state"] < 1e-6  # two methods agree
    methods = {p["method"] for p in scene["points"]}
    assert methods == {"erk-C", "scipy-LSODA"}
    for p in scene["points"]:
        assert p["status"] == "ok", p.get("reason")
        assert {"x", "y", "phi", "state", "friction_power"} <= set(p["error"])
        assert p["timing"]["median_cpu_s"] > 0 and p["stats"]["rhs_evaluations"] > 0
    erk = [p for p in scene["points"] if p["method"] == "erk-C"]
    assert all(p["compiled"] for p in erk)
    assert all(p["stats"]["source"].startswith("one interpreted run") for p in erk)


@pytest.mark.parametrize("method", ["erk-C", "scipy-LSODA"])
def test_error_decreases_with_tolerance(tiny, method):
    _, r, _ = tiny
    pts = sorted((p for p in r["scenes"][0]["points"] if p["method"] == method), key=lambda p: -p["value"])
    errs = [p["error"]["state"] for p in pts]
    assert len(errs) >= 2 and errs[-1] < errs[0] / 3, errs
    assert errs == sorted(errs, reverse=True), errs


def test_tables_name_the_command_and_targets(tiny):
    out, r, _ = tiny
    table = (out / "table.md").read_text()
    assert r["command"].startswith("apexseal bench --quick") and r["command"] in table
    assert "## Targets" in table and "scaled error" in table
    assert all(t["status"] in ("met", "missed", "not measured") for t in r["targets"])
    # a span of 20 deg is not a revolution: its times are per span, and the one-revolution target was judged on them
    assert "**Span 20 deg, not a revolution** (`--span`)" in table
    assert not [t for t in r["targets"] if "one revolution" in t["target"]]


def test_reports_are_written_again_from_results_json_alone(tiny, tmp_path):
    """``python -m apexseal.runtime.bench.output DIR`` gives the tables the run wrote, from results.json alone."""
    import shutil

    from apexseal.runtime.bench.output import rewrite_reports

    out, _, _ = tiny
    shutil.copy(out / "results.json", tmp_path / "results.json")
    shutil.copy(out / "effects.md", tmp_path / "effects.md")  # a folder without it gets none
    written = rewrite_reports(tmp_path)
    assert sorted(p.name for p in written) == ["effects.md", "table.md", "work-precision.png"]
    for path in written:
        assert path.read_bytes() == (out / path.name).read_bytes(), path.name


def test_budget_and_failure_are_recorded():
    def busy():
        x = 0
        while True:
            x += 1

    with pytest.raises(BudgetExceeded):
        measure(busy, repeats=1, slow_run_s=1.0, budget_s=0.2)


def test_time_at_error_interpolates_and_extrapolates():
    curve = [(1.0, 1e-4), (2.0, 1e-6 / 4), (1.5, 1e-3)]  # (time, error); (1.5, 1e-3) is beaten by (1.0, 1e-4)
    assert pareto(curve) == [(1.0, 1e-4), (2.0, 2.5e-7)]
    at = time_at_error(curve, 1e-6)
    assert at["how"] == "interpolated" and 1.0 < at["time_s"] < 2.0
    ext = time_at_error([(1.0, 1e-2), (10.0, 1e-3)], 1e-6)  # first order: 10x time per digit
    assert ext["how"].startswith("extrapolated") and math.isclose(ext["time_s"], 1e4, rel_tol=1e-9)
    assert time_at_error([], 1e-6) is None


def test_full_preset_times_every_point_five_times():
    """The full benchmark takes the median of at least 5 timed runs after a warm-up, however slow the run."""
    import time

    from apexseal.runtime.bench.config import full

    cfg = full()
    assert cfg.repeats >= 5
    calls = []

    def slow():
        calls.append(1)
        t = time.process_time()
        while time.process_time() - t < 0.03:
            pass

    _, timing = measure(slow, repeats=cfg.repeats, slow_run_s=cfg.slow_run_s, budget_s=None, min_sample_s=0.0)
    assert len(timing.cpu_s) == cfg.repeats and len(calls) == cfg.repeats + 1
    _, adaptive = measure(slow, repeats=5, slow_run_s=0.01, budget_s=None, min_sample_s=0.0)
    assert len(adaptive.cpu_s) < 5  # the quick preset's adaptive rule, for contrast


def test_a_call_whose_cpu_time_reads_zero_gets_a_bounded_batch(monkeypatch):
    """CPU time is accounted in ticks on a busy VM: a short call can read 0 s. The batch is then sized on the
    wall time (and capped), not on the 1e-6 s floor that asked for 200000 runs per sample."""
    import time

    from apexseal.runtime.bench import timing

    monkeypatch.setattr(timing.time, "process_time", lambda: 0.0)
    calls = []

    def short():
        calls.append(1)
        time.sleep(0.002)

    _, t = measure(short, repeats=2, slow_run_s=0.5, budget_s=None, min_sample_s=0.2)
    assert 1 <= t.batch <= 200 and len(calls) == 1 + 2 * t.batch


def _point(method, family, cpu_s, evaluations, error, generated_c):
    return {"method": method, "family": family, "generated_c": generated_c, "status": "ok",
            "timing": {"median_cpu_s": cpu_s}, "stats": {"rhs_evaluations": evaluations}, "error": {"state": error}}


def test_evaluation_budget_bounds_an_own_integrator():
    """Two methods whose evaluations and CPU time each fall 10x per digit of error, 100 and 50 ns per
    evaluation, the cheapest measured evaluation 20 ns: at 1e-6 apexseal's needs 1e6 evaluations (0.1 s), the
    peer 4e5 (0.02 s); an overhead-free integrator with apexseal's evaluations at 20 ns takes 0.02 s (1.0x the
    peer), and 2x ahead (0.01 s) allows 5e5 evaluations: 0.5 of apexseal's, 1.25 of the peer's."""
    from apexseal.runtime.bench.budget import budget_md, evaluation_budget

    pts = []
    for e in (1e-5, 1e-7):
        n_a, n_p = 1e6 * (1e-6 / e) ** 0.5, 4e5 * (1e-6 / e) ** 0.5
        pts += [_point("erk-C", "C integrator", 100e-9 * n_a, n_a, e, True),
                _point("numbalsoda-LSODA", "sympy.cse + numba (peer)", 50e-9 * n_p, n_p, e, False)]
    r = {"config": {"target_error": 1e-6},
         "scenes": [{"name": "default", "points": pts,
                     "rhs_cost": [{"form": "bare loop", "s": 20e-9, "n": 1000}, {"form": "inside erk", "s": 100e-9,
                                                                                   "n": "erk-C"}]}]}
    b = evaluation_budget(r)
    assert (b["apexseal"], b["peer"]) == ("erk-C", "numbalsoda-LSODA")
    assert math.isclose(b["apexseal_evaluations"], 1e6, rel_tol=1e-9)
    assert math.isclose(b["peer_evaluations"], 4e5, rel_tol=1e-9)
    assert math.isclose(b["apexseal_s_per_evaluation"], 100e-9, rel_tol=1e-9)
    assert b["cheapest_form"] == "bare loop"
    assert math.isclose(b["bound_s"], 0.02, rel_tol=1e-9) and math.isclose(b["bound_ratio"], 1.0, rel_tol=1e-9)
    assert math.isclose(b["allowed_evaluations"], 5e5, rel_tol=1e-9)
    assert math.isclose(b["allowed_vs_apexseal"], 0.5, rel_tol=1e-9)
    assert math.isclose(b["allowed_vs_peer"], 1.25, rel_tol=1e-9)
    text = "\n".join(budget_md(r))
    assert "**1.00x**" in text and "500,000 evaluations" in text and "Only a method that needs" in text
    ahead = [_point("erk-C", "C integrator", q["timing"]["median_cpu_s"] / 20, q["stats"]["rhs_evaluations"],
                    q["error"]["state"], True) if q["method"] == "erk-C" else q for q in pts]  # 20x cheaper: 4x ahead
    assert "erk-C is 4.00x ahead" in "\n".join(budget_md(r | {"scenes": [r["scenes"][0] | {"points": ahead}]}))
    r["scenes"][0]["points"] = [p for p in pts if p["method"] == "erk-C"]  # no peer: no section
    assert evaluation_budget(r) is None and budget_md(r) == []


def test_the_peer_comparison_at_1e8_rests_on_measured_points_on_both_sides():
    """The full preset sweeps apexseal's fastest methods and numbalsoda's LSODA one decade past rtol 1e-10, where
    LSODA stayed above a scaled error of 1e-8: the ratio there is interpolated, not extrapolated."""
    from apexseal.runtime.bench.config import full

    sweeps = full().scenes[0].sweeps
    tightest = {m: min(sweeps[m]) for m in ("erk-C", "composite-C", "numbalsoda-LSODA")}
    assert set(tightest.values()) == {1e-11}, tightest


def test_what_a_peer_printed_is_reported_beside_its_points(monkeypatch):
    from apexseal.runtime.bench import report, runner

    monkeypatch.setattr(runner, "peer_ratios", lambda r, name: [])
    point = {"method": "numbalsoda-LSODA", "family": "sympy.cse + numba (peer)", "sweep": "rtol", "value": 1e-11,
             "solver_messages": {"lines": 12, "first": "lsoda-- warning..internal t (=r1) and h (=r2) are"}}
    r = {"scenes": [{"name": "default", "points": [point]}]}
    text = "\n".join(report.peer_md(r))
    assert "numbalsoda-LSODA at rtol 1e-11: 12 lines" in text and "lsoda-- warning" in text
    point.pop("solver_messages")
    assert "printed" not in "\n".join(report.peer_md(r))


def test_what_c_code_prints_on_stdout_and_stderr_is_captured():
    """numbalsoda's LSODA warns on file descriptor 2 from C++: the benchmark keeps it with the point."""
    import os

    from apexseal.runtime.bench.points import captured_output

    with captured_output((1, 2)) as box:
        os.write(1, b"out ")
        os.write(2, b"lsoda -- warning")
    assert box["text"] == "out lsoda -- warning"
    with captured_output() as box:
        os.write(1, b"casadi")
    assert box["text"] == "casadi"


@pytest.mark.parametrize("args, fragments", [
    (["--quick", "--scenes", "stiff"], ["--scenes", "unknown scene(s) stiff in the quick run (its scenes: default); "
                                        "stiff only in the full run"]),
    (["--quick", "--methods", "rk4-C"], ["--methods", "none of the method(s) rk4-C is measured in the quick run",
                                         "its methods: composite-C, erk-C"]),
    (["--quick", "--methods", ",,"], ["--methods", "',,' names none"]),  # it ran every method
], ids=["scene-of-the-full-run", "method-of-the-full-run", "no-method"])
def test_a_selection_the_run_does_not_hold_is_told_where_it_is(args, fragments, tmp_path):
    """`--quick --scenes stiff` said "unknown scene" of a scene the full run measures, and `--quick --methods rk4-C`
    went on to settle the reference with nothing to measure."""
    res = CliRunner().invoke(main, ["bench", *args, "--out", str(tmp_path / "b")])
    assert res.exit_code == 2 and not (tmp_path / "b").exists(), res.output
    for fragment in fragments:
        assert fragment in res.output


def test_a_run_whose_methods_are_all_unavailable_stops_before_settling(monkeypatch, tmp_path):
    """Only numbalsoda's methods asked for where it is not installed: the run settled the reference for minutes
    and then measured nothing."""
    from apexseal.runtime.bench import peer_numba

    monkeypatch.setattr(peer_numba, "numbalsoda_available", lambda: "numbalsoda is not installed (here: on purpose)")
    res = CliRunner().invoke(main, ["bench", "--quick", "--methods", "numbalsoda-LSODA", "--out", str(tmp_path / "b")])
    assert res.exit_code == 2, res.output
    assert ("no method left to measure: numbalsoda-LSODA: numbalsoda is not installed (here: on purpose)"
            in res.output)
    assert "settling" not in res.output


def test_every_method_of_the_bench_has_run_settings_its_engine_accepts():
    """The composite's bench points asked for compile_c = False (the spec compiles no integrator of CasADi's), which
    the settings refuse since the composite runs only in the model library: `apexseal bench` with composite-C
    stopped with a traceback after minutes, every point measured lost. Every method's settings are accepted, at
    every setting of its sweep, for its timed engine and its interpreted twin alike."""
    from apexseal.runtime.bench.config import METHODS, PRESETS
    from apexseal.runtime.bench.methods import settings_for

    values = {m: v for preset in PRESETS.values() for s in preset().scenes for m, v in s.sweeps.items()}
    for spec in METHODS.values():
        if spec.kind not in ("casadi", "rk4"):
            continue
        for value in values.get(spec.id, [1e-6]):
            for compiled in {spec.compiled, False}:
                st = settings_for(spec, value, samples=360, span=2 * math.pi, flags="quick", compiled=compiled)
                assert st.compile_c if spec.model_c else st.compile_c == compiled, (spec.id, compiled)


def test_a_point_whose_engine_cannot_be_built_is_a_failed_point_not_the_end_of_the_run(monkeypatch):
    """An engine refused at its construction raised out of the whole bench, which wrote nothing: it is that
    point's failure, with its reason, and the run goes on."""
    from types import SimpleNamespace

    from apexseal.runtime.bench.config import METHODS
    from apexseal.runtime.bench.runner import _Context

    def refused(*args, **kw):
        raise ValueError("method 'composite' runs only in the compiled model library (test)")

    ctx = _Context.__new__(_Context)
    ctx.cfg = SimpleNamespace(repeats=1, slow_run_s=1.0, budget_s=None)
    ctx.engines, ctx.c_model, ctx.sx = SimpleNamespace(get=refused), None, None
    point = ctx.point(SimpleNamespace(name="default"), None, METHODS["composite-C"], 1e-6)
    assert point["status"] == "failed" and point["method"] == "composite-C" and point["value"] == 1e-6
    assert point["reason"] == "ValueError: method 'composite' runs only in the compiled model library (test)"


def test_a_run_stopped_halfway_writes_what_it_measured_as_a_partial_result(tiny, tmp_path):
    """A Ctrl-C while measuring wrote nothing ("nothing written"), every point measured lost: the points measured
    are written, with the summary, targets and tables over them, and the table says it is a partial run."""
    from apexseal.runtime.bench.config import PRESETS
    from apexseal.runtime.bench.output import write_outputs
    from apexseal.runtime.bench.runner import partial_results

    _, r, _ = tiny
    cfg = PRESETS["quick"]().restricted(methods=("erk-C", "scipy-LSODA"), samples=24, span_deg=20, settle=0, repeats=1,
                                        flags="quick")
    measured = dict(r, scenes=[dict(r["scenes"][0], points=r["scenes"][0]["points"][:2])])
    for part in ("summary", "targets", "elapsed_wall_s"):
        measured.pop(part)
    measured["started_wall"] = 0.0  # what run_benchmark puts there: time.perf_counter() at its start
    kept = partial_results(measured, cfg, "interrupted by the user (Ctrl-C, SIGINT)")
    total = sum(len(v) for s in cfg.scenes for v in s.sweeps.values())
    assert kept["interrupted"].startswith(f"interrupted by the user (Ctrl-C, SIGINT): 2 of {total} points measured")
    assert list(kept["summary"]["default"]) == ["erk-C"] and kept["summary"]["default"]["erk-C"]["points"] == 2
    paths = write_outputs(kept, tmp_path, r["command"])
    assert "**A partial run**, interrupted by the user" in paths["table.md"].read_text()
    assert json.loads(paths["results.json"].read_text())["interrupted"] == kept["interrupted"]
    assert partial_results(dict(r, scenes=[dict(r["scenes"][0], points=[])]), cfg, "interrupted") is None


@pytest.mark.slow  # a bench run of its own (20-40 s): in the second step
def test_a_ctrl_c_between_points_keeps_the_points_measured(tmp_path, monkeypatch):
    """The command's side of the partial result: a Ctrl-C as the second point starts ends the run with exit code
    130, and the folder holds the first point's result, its table marked partial."""
    import os
    import signal

    import apexseal.runtime.bench.runner as runner

    real, calls = runner.casadi_point, []

    def second_interrupted(*args, **kw):
        calls.append(1)
        if len(calls) == 2:
            os.kill(os.getpid(), signal.SIGINT)  # the command's handler raises here: the point is not measured
        return real(*args, **kw)

    monkeypatch.setattr(runner, "casadi_point", second_interrupted)
    out = tmp_path / "bench"
    res = CliRunner().invoke(main, [*TINY[:TINY.index("--methods") + 1], "erk-C", *TINY[TINY.index("--methods") + 2:],
                                    "--out", str(out)])
    assert res.exit_code == 130, res.output
    data = json.loads((out / "results.json").read_text())
    assert [p["value"] for p in data["scenes"][0]["points"]] == [data["config"]["scenes"][0]["sweeps"]["erk-C"][0]]
    assert data["interrupted"].startswith("interrupted by the user (Ctrl-C, SIGINT): 1 of ")
    assert "**A partial run**" in (out / "table.md").read_text() and "a partial run: its table says so" in res.output
