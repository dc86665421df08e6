"""Where the benchmark's error and work are (runtime/bench/anatomy.py): its windows, errors and split runs.

The building blocks on made-up data; the whole measurement on 20 degrees of the default scene from its initial
state (24 output intervals, interpreted integrators: nothing is compiled).
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from apexseal.runtime.api import model_functions
from apexseal.runtime.bench.anatomy import (
    Anatomy,
    evaluations_at,
    markdown,
    sample_errors,
    switch_intervals,
    switch_windows,
    windowed_errors,
)
from apexseal.runtime.bench.metrics import Trajectory
from apexseal.runtime.bench.problem import make_problem
from apexseal.runtime.scenes.scene import load_scene
from apexseal.runtime.solving.methods import make_engine
from apexseal.runtime.solving.settings import RunSettings


def test_switch_windows_hold_each_switch_and_the_intervals_after_it_periodically():
    switched = np.zeros(10, bool)
    switched[[2, 9]] = True
    w = switch_windows(switched, 2)
    # 2 -> 2, 3, 4; 9 -> 9, then 0 and 1 of the next revolution
    assert np.flatnonzero(w).tolist() == [0, 1, 2, 3, 4, 9]
    assert switch_windows(switched, 0).tolist() == switched.tolist()


def test_switch_intervals_are_where_the_event_counters_go_up():
    functions = SimpleNamespace(state_names=("a",), guard_names=("g1", "g2"))
    problem = SimpleNamespace(functions=functions, z0=np.array([0.0, 1.0, 0.0, 3.0, 5.0]))
    counts = np.array([[3, 3, 4, 4, 6],  # g1: up over intervals 2 and 4
                       [5, 5, 5, 5, 5]])  # g2: never
    z = np.vstack([np.zeros((1, 5)), np.zeros((2, 5)), counts])
    assert switch_intervals(problem, z).tolist() == [False, False, True, False, True]
    counts[1, 0] = 6  # g2 switched in the first interval: counted from z0
    z = np.vstack([np.zeros((1, 5)), np.zeros((2, 5)), counts])
    assert switch_intervals(problem, z).tolist() == [True, False, True, False, True]


def _traj(x, y, phi):
    X = np.vstack([x, y, phi, np.zeros((3, len(x)))])
    return Trajectory(X, np.zeros((1, len(x))), np.zeros(1), np.ones(len(x)))


def test_errors_inside_and_outside_the_windows():
    ref = _traj(np.linspace(0, 2, 5), np.linspace(0, 10, 5), np.linspace(0, 1, 5))
    moved = _traj(ref.X[0] + [0, 0, 0.2, 0, 0], ref.X[1] + [0, 0.5, 0, 0, 0], ref.X[2])
    # x: 0.2 of its range 2 at sample 2; y: 0.5 of 10 at sample 1
    np.testing.assert_allclose(sample_errors(moved, ref), [0, 0.05, 0.1, 0, 0])
    w = np.array([False, False, True, True, False])
    e = windowed_errors(moved, ref, w)
    assert e == pytest.approx({"state": 0.1, "inside": 0.1, "outside": 0.05})
    assert windowed_errors(moved, ref, ~w) == pytest.approx({"state": 0.1, "inside": 0.05, "outside": 0.1})


def test_evaluations_at_an_error_interpolate_on_the_pareto_front():
    rows = [{"method": "A", "rhs": 1000, "state": 1e-4}, {"method": "A", "rhs": 10000, "state": 1e-8},
            {"method": "A", "rhs": 5000, "state": 1e-3},  # off the front: more work for more error
            {"method": "B", "rhs": 10, "state": 1e-2}, {"method": "A", "rhs": 1, "failed": "x"}]
    assert evaluations_at(rows, "A", 1e-6) == pytest.approx(math.sqrt(1000 * 10000))
    assert evaluations_at(rows, "A", 1e-9) is None  # not bracketed
    assert evaluations_at(rows, "B", 1e-6) is None


@pytest.fixture(scope="module")
def tiny():
    """20 degrees of the default scene from its initial state (it starts with its switches), 24 intervals."""
    scene = load_scene()
    f = model_functions(scene, compiled=False)
    span, samples = math.radians(20), 24
    problem = make_problem("default", scene, scene.effects, f, samples=samples, span=span, settle_revolutions=0,
                           pressure_profile="linear")
    st = RunSettings(method="erk", rtol=1e-11, samples_per_revolution=round(samples * 2 * math.pi / span),
                     event_tol=1e-13, compile_c=False, pressure="linear")
    ref = make_engine(f, st, n_samples=samples, span=span).run(problem.z0, problem.params, problem.theta0,
                                                                problem.pressures)
    return Anatomy(problem=problem, reference_z=ref.z, ring_deg=2.5)


@pytest.mark.slow
def test_the_whole_measurement_on_a_short_span(tiny):
    an = tiny
    assert an.switched.any() and an.windows.sum() > an.switched.sum()  # the start rings: windows are longer
    assert (an.windows[an.switched]).all()
    segs = an.segments()
    assert segs[0][0] == 0 and segs[-1][1] == an.problem.samples
    assert all(a[1] == b[0] and a[2] != b[2] for a, b in zip(segs, segs[1:], strict=False))  # contiguous, alternating
    assert {s[2] for s in segs} <= {"erk", "rosenbrock"} and {s[3] for s in segs} == {1.0}
    loose = an.segments(between="erk", loose=100.0)
    assert [s[:2] for s in loose] == [s[:2] for s in segs]
    assert all(s[2] == "erk" and s[3] == (1.0 if an.windows[s[0]] else 100.0) for s in loose)
    rows = an.casadi_rows(methods=("erk",), rtols=(1e-5, 1e-8), log=lambda _: None)
    loose, tight = rows
    for r in rows:
        assert r["state"] == pytest.approx(max(r["inside"], r["outside"]))
    assert tight["state"] < loose["state"] and tight["steps"] > loose["steps"] > 0
    split = an.split_rows(rtols=(1e-8, 1e-10), repeats=1, compiled=False, log=lambda _: None)
    plans = ["erk", "rosenbrock", "erk, cut at the windows", "erk in the windows, rosenbrock between",
             "erk, 100x rtol outside the windows", "erk, 1000x rtol outside the windows"]
    assert [r["plan"] for r in split] == plans * 2
    assert split[0]["steps"] == tight["steps"]  # one segment: the same integrator as the whole-span run
    assert split[2]["segments"] == split[3]["segments"] == split[4]["segments"] == len(segs)
    assert 0 < split[2]["steps_inside"] < split[2]["steps"]
    cut, loosened = split[8], split[10]  # rtol 1e-10: erk cut at the windows, and 100x looser outside them
    # the same erk at the same rtol in the windows (which start from slightly other states)
    assert loosened["steps_inside"] == pytest.approx(cut["steps_inside"], rel=0.05)
    assert loosened["steps"] - loosened["steps_inside"] < cut["steps"] - cut["steps_inside"]  # fewer outside
    for coarse, fine in zip(split[:6], split[6:], strict=True):  # each way of integrating converges to the reference
        assert fine["state"] < min(coarse["state"], 1e-3)
        assert fine["outside"] < fine["inside"]  # the start's switches and their ringing hold the error
    located = an.casadi_rows(methods=("erk",), rtols=(1e-8,), event_tol=1e-12, log=lambda _: None)
    assert located[0]["method"] == "erk, events to 1e-12 rad" and located[0]["state"] < loose["state"]
    text = markdown(an, rows, [], split, 2.5)
    assert "| erk | 1e-08 |" in text and "rosenbrock between" in text


@pytest.mark.slow
def test_scipy_methods_count_their_evaluations_and_converge(tiny):
    pytest.importorskip("numba")
    from apexseal.runtime.bench.anatomy import scipy_rows

    rows = scipy_rows(tiny, methods=("RK45", "LSODA"), rtols=(1e-5, 1e-8), log=lambda _: None)
    assert [(r["method"], r["rtol"]) for r in rows] == [("RK45", 1e-5), ("RK45", 1e-8), ("LSODA", 1e-5), ("LSODA", 1e-8)]
    for loose, tight in (rows[:2], rows[2:]):
        assert "failed" not in loose and "failed" not in tight
        assert tight["state"] < loose["state"] and tight["rhs"] > loose["rhs"] > 0
    assert rows[0]["jacobians"] == 0 and rows[2]["jacobians"] > 0  # LSODA's finite-difference Jacobians
    text = markdown(tiny, [], rows, [], 2.5)
    assert "LSODA" in text and "RHS evaluations for a scaled error of 1e-6" in text and "Radau" not in text


@pytest.mark.slow  # a benchmark study's command (the run method's own tests are in the default suite)
def test_the_exponential_prototype_finds_the_switches_and_converges(tiny):
    """runtime/bench/exponential.py on the short span: the reference's switches, an error that falls with rtol,
    and a looser velocity tolerance that takes fewer steps."""
    pytest.importorskip("numba")
    from apexseal.runtime.bench.exponential import markdown as exp_markdown
    from apexseal.runtime.bench.exponential import rows as exp_rows

    rs = exp_rows(tiny, rtols=(1e-5, 1e-8), velocity_weights=(1.0, 1000.0), log=lambda _: None)
    loose, tight, weighted = rs[0], rs[1], rs[2]
    assert tight["events"] == int(tiny.ref.events.sum())
    assert tight["state"] < min(loose["state"] / 10, 1e-3)  # the bound of the erk, rosenbrock plans above
    assert tight["steps"] > loose["steps"] > 0 and tight["jacobians"] == tight["steps"]
    assert weighted["steps"] < loose["steps"]  # the velocities' tolerance sets the steps
    assert "| 1000 | 1e-05 |" in exp_markdown(tiny, rs)


def test_scaled_velocities_loosen_the_error_norm_and_nothing_else(tiny):
    """``--velocity-scale``: the same physics (errors stay small), another step sequence, the scaling restored."""
    from apexseal.generated.scaling import state_scale
    from apexseal.runtime.bench.anatomy import velocities_scaled

    before = state_scale(100.0)
    with velocities_scaled(10.0):
        np.testing.assert_allclose(state_scale(100.0), before * [1, 1, 1, 10, 10, 10])
    np.testing.assert_array_equal(state_scale(100.0), before)
    plain, scaled = (tiny.casadi_rows(methods=("erk",), rtols=(1e-10,), velocity_scale=k, log=lambda _: None)[0]
                     for k in (1.0, 10.0))
    assert scaled["method"] == "erk, velocities scaled 10x" and scaled["steps"] != plain["steps"]
    assert scaled["state"] < 1e-3  # the trajectory of the same model (a wrong scaling would be far off)
    np.testing.assert_array_equal(state_scale(100.0), before)


@pytest.mark.slow  # 57 s: a benchmark study's numba prototype (the run method's own tests are in the default suite)
def test_the_composite_prototype_switches_phases_and_converges(tiny):
    """runtime/bench/composite.py on the short span: RK45 through the start's switches (the reference's count),
    exprb32 once the contacts have rung down, an error that falls with rtol."""
    pytest.importorskip("numba")
    from apexseal.runtime.bench.composite import markdown as comp_markdown
    from apexseal.runtime.bench.composite import rows as comp_rows

    rs = comp_rows(tiny, rtols=(1e-6, 1e-9), settings=((100.0, 100.0, 2.0),), repeats=1, erk=False,
                   log=lambda _: None)
    loose, tight = rs
    assert tight["events"] == int(tiny.ref.events.sum())
    assert tight["state"] < min(loose["state"] / 10, 1e-3)
    for r in rs:
        assert r["tight_steps"] > 0 and r["quiet_steps"] > 0 and r["jacobians"] == r["quiet_steps"] + r["given_back"]
    # the same method in generated C (templates/apexseal_composite.in.c): the same switches, as accurate, and no
    # more evaluations (its Jacobian is the library's exact one where the prototype differences; 10 % fewer here)
    assert tight["c_events"] == tight["events"] and tight["c_state"] < min(loose["c_state"] / 10, 1e-3)
    assert 0.7 * tight["rhs"] < tight["c_rhs"] <= 1.05 * tight["rhs"]
    assert "| 100, 100, 2 deg | 1e-09 |" in comp_markdown(tiny, rs)


@pytest.mark.slow  # a benchmark study's command (the run method's own tests are in the default suite)
def test_the_composite_on_a_stress_scene_finds_its_switches():
    """``composite --hard``: the first degrees of one stress scene, against erk at rtol 1e-10; a failing integrator
    is reported by its innermost message."""
    pytest.importorskip("numba")
    from apexseal.runtime.bench.composite import _failure, hard_markdown, hard_rows

    (row,) = hard_rows(["grazing-housing"], degrees=20.0, log=lambda _: None)
    assert row["done_deg"] == 20.0 and row["events"] == row["reference_events"] == row["erk_events"]
    assert row["state"] < 1e-4 and row["tight_steps"] > 0
    assert "| grazing-housing |" in hard_markdown([row], 20.0, 1e-8)
    exc = RuntimeError("Error in Function::call at .../casadi/core/function.cpp:1655:\n"
                       ".../casadi/core/function_internal.hpp:1766: Evaluation failed")
    assert _failure(exc) == "failed: Evaluation failed"


def test_the_composite_rules_command_sets_the_run_method_beside_its_variants(tiny):
    """``composite --rules``: below rtol 1e-8 the run method is RK45 alone with events located to 1e-3 rtol (the
    same evaluations and states as that variant); at 1e-8 it locates them to the run's 1e-10 rad."""
    from apexseal.runtime.bench.composite import RULE_VARIANTS, rule_markdown, rule_rows

    rules, alone_label = RULE_VARIANTS[0], "RK45 alone, events to min(1e-10, 1e-3 rtol) rad"
    rs = rule_rows(tiny, rtols=(1e-8, 1e-9), variants=[rules, *(v for v in RULE_VARIANTS if v[0] == alone_label)],
                   repeats=1, log=lambda _: None)
    run = {r["rtol"]: r for r in rs if r["variant"] == rules[0]}
    alone = {r["rtol"]: r for r in rs if r["variant"] == alone_label}
    assert set(alone) == {1e-8, 1e-9}
    assert run[1e-9]["quiet_steps"] == 0 and run[1e-9]["rhs"] == alone[1e-9]["rhs"]
    assert run[1e-9]["state"] == alone[1e-9]["state"]
    assert run[1e-8]["state"] != alone[1e-8]["state"]
    assert all(r["events"] == int(tiny.ref.events.sum()) for r in rs)
    assert "| the run method (its rules) | 1e-09 |" in rule_markdown(tiny, rs)


def test_the_composite_default_run_command_times_both_methods():
    """``composite --default-run``: erk and the composite on the default scene, the run's own integration time."""
    from apexseal.runtime.bench.composite import default_run_markdown, default_run_rows

    rs = default_run_rows(rtols=(1e-6,), samples=(720,), revolutions=1, repeats=1, log=lambda _: None)
    erk, comp = rs
    assert (erk["method"], comp["method"]) == ("erk", "composite") and erk["quiet_steps"] is None
    assert comp["quiet_steps"] > 0 and comp["tight_steps"] > 0
    assert all(r["ms_per_rev"] > 0 for r in rs)
    assert "| 720 | 1e-06 | composite |" in default_run_markdown(rs)
