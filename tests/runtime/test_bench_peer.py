"""The hand-written numba peer of the benchmark (runtime/bench/peer_source.py, peer_numba.py).

Its right-hand side must be the model's to round-off (same sympy equations, printed
differently), and its integrations must reach the reference's trajectory at tight
tolerances; without numba (or numbalsoda) those tests skip, and the benchmark
skips the methods with a note.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from apexseal.generated.layout import HybridLayout
from apexseal.runtime.api import model_functions
from apexseal.runtime.bench.config import quick
from apexseal.runtime.bench.metrics import errors, trajectory
from apexseal.runtime.bench.problem import make_problem
from apexseal.runtime.scenes.scene import load_scene
from apexseal.runtime.solving.methods import make_engine
from apexseal.runtime.solving.settings import RunSettings


@pytest.fixture(scope="module")
def numba_model():
    pytest.importorskip("numba")
    from apexseal.runtime.bench.peer_source import numba_model as build

    scene = load_scene()
    return scene, build(scene.effects, scene.assumptions)


def test_numba_rhs_equals_casadi_rhs_at_random_states_and_modes(numba_model):
    scene, nm = numba_model
    f = model_functions(scene)
    p = scene.parameter_vector()
    rng = np.random.default_rng(12)
    # around the settled motion: µm and mrad displacements, their speeds at omega ~ 157 rad/s
    spread = np.array([5e-6, 300e-6, 15e-3, 5e-3, 0.3, 20.0])
    n_g = nm.n_guards
    for _ in range(40):
        theta = rng.uniform(0, 2 * math.pi)
        X = rng.normal(size=6) * spread
        A = rng.integers(0, 2, n_g).astype(float)
        u = rng.uniform(0, 2e6, 2)
        acc, gap, sw = np.empty(3), np.empty(n_g), np.empty(3)
        nm.accelerations(theta, X, A, p, u[0], u[1], acc)
        nm.guards(theta, X, p, u[0], u[1], gap)
        nm.switched(theta, X, p, u[0], u[1], sw)
        ref = np.array(f.rhs(theta, X, A, p, u)).ravel()[3:]
        ref_g = np.array(f.guards(theta, X, p, u)).ravel()
        ref_sw = np.array(f.rhs_switched(theta, X, p, u)).ravel()[3:]
        # round-off of sums of large terms: relative to the largest force the model forms (~ the spring and contacts)
        np.testing.assert_allclose(acc, ref, rtol=1e-9, atol=1e-9 * np.abs(ref).max())
        np.testing.assert_allclose(gap, ref_g, rtol=1e-9, atol=1e-15)
        np.testing.assert_allclose(sw, ref_sw, rtol=1e-9, atol=1e-9 * np.abs(ref_sw).max())
        assert ((gap < 0) == (ref_g < 0)).all()


def _tiny(pressure: str):
    """20 degrees of the default scene from its initial state, 24 output intervals, reference erk at 1e-12."""
    scene = load_scene()
    f = model_functions(scene)
    span, samples = math.radians(20), 24
    problem = make_problem("default", scene, scene.effects, f, samples=samples, span=span, settle_revolutions=0,
                           pressure_profile=pressure)
    per_rev = round(samples * 2 * math.pi / span)  # settings count samples per revolution
    st = RunSettings(method="erk", rtol=1e-12, samples_per_revolution=per_rev, event_tol=1e-13, compile_c=False,
                     pressure=pressure)
    out = make_engine(f, st, n_samples=samples, span=span).run(problem.z0, problem.params, problem.theta0,
                                                                problem.pressures)
    return problem, trajectory(problem, out.z)


@pytest.fixture(scope="module")
def tiny_problem():
    return _tiny("steps")


@pytest.mark.parametrize("method", ["numba-scipy-LSODA", "numbalsoda-LSODA", "numbalsoda-DOP853"])
def test_peer_trajectory_agrees_with_erk_at_tight_tolerance(numba_model, tiny_problem, method):
    if method.startswith("numbalsoda"):
        pytest.importorskip("numbalsoda")
    pytest.importorskip("scipy")
    from apexseal.runtime.bench.peer_numba import NumbaPeer

    problem, ref = tiny_problem
    peer = NumbaPeer(problem, numba_model[1])
    peer.build(numbalsoda=method.startswith("numbalsoda"))
    out = peer.run(method, 1e-10)
    traj = trajectory(problem, out.z)
    err = errors(traj, ref)
    # DOP853: numbalsoda locates events to a fixed 1e-8 rad of crank angle, which left a floor of 6e-6 to 1.5e-5 on
    # the metal contacts whatever the tolerance until the driver took a Newton step at each root (polished_root)
    assert err["state"] < 1e-6, err
    assert out.stats["n_rhs"] > 0
    if method == "numbalsoda-DOP853":  # events located: the same contact switches as the reference
        assert ref.events.sum() > 0
        np.testing.assert_array_equal(traj.events, ref.events)
        np.testing.assert_array_equal(traj.closed, ref.closed)
    looser = trajectory(problem, peer.run(method, 1e-5).z)
    assert errors(looser, ref)["state"] > err["state"]  # the tolerance is what sets the error


def test_peer_interpolates_linear_pressures_inside_an_interval(numba_model):
    """With ``bench --pressure linear`` the peer's right-hand sides see the line through the pressures at the
    interval's ends (as the hybrid DAE does, tests/runtime/test_pressure_profile.py), not the interval's mean."""
    from apexseal.generated.scaling import scaled_rhs
    from apexseal.runtime.bench.peer_numba import NumbaPeer

    scene, nm = numba_model
    f = model_functions(scene)
    span, samples = math.radians(20), 24
    problem = make_problem("default", scene, scene.effects, f, samples=samples, span=span, settle_revolutions=0,
                           pressure_profile="linear")
    peer = NumbaPeer(problem, nm)
    peer.build(numbalsoda=False)
    P = problem.pressures
    assert P.shape == (2, samples + 1)
    k = int(np.argmax(np.abs(np.diff(P, axis=1)).max(axis=0)))  # the interval where a pressure changes most
    w = 0.25  # a quarter into it
    t = (k + w) * span / samples
    Pt = P[:, k] + w * (P[:, k + 1] - P[:, k])
    assert np.abs(Pt - P[:, k]).max() > 1e3  # the pressure changes over the interval: the test can see the difference
    X = np.array([0.2e-6, -30e-6, 1e-3, 1e-3, 0.01, 0.5])
    z = X / peer.data[peer.layout.SC:peer.layout.SC + 6]
    dz = np.empty(6)
    peer.kernels["switched_rhs"](t, z.copy(), peer.data.copy(), dz)
    omega = problem.omega
    want = np.array(scaled_rhs(f.rhs_switched(problem.theta0 + t, X, problem.params, Pt), omega)).ravel()
    np.testing.assert_allclose(dz, want, rtol=1e-9, atol=1e-9 * np.abs(want).max())


def test_missing_numbalsoda_skips_its_methods_with_a_note(monkeypatch):
    from apexseal.runtime.bench import peer_numba, runner

    monkeypatch.setattr(peer_numba, "numbalsoda_available", lambda: "numbalsoda is not installed (test)")
    monkeypatch.setattr(peer_numba, "numba_available", lambda: None)
    notes = []
    cfg, skipped = runner._available(quick(), notes.append)
    assert {s["method"] for s in skipped} == {"numbalsoda-LSODA", "numbalsoda-DOP853"}
    assert all("not installed" in n and n.startswith("note: skipping") for n in notes) and len(notes) == 2
    kept = {m for s in cfg.scenes for m in s.sweeps}
    assert "numba-scipy-LSODA" in kept and "erk-C" in kept and not kept & {"numbalsoda-LSODA", "numbalsoda-DOP853"}


def test_dop853_locates_the_earliest_of_the_crossings_in_a_step(numba_model):
    """A settled revolution of the benchmark's problem, whose second cluster of switches has several contacts
    changing sign within one DOP853 step. numbalsoda locates only the lowest-indexed event function that changed
    sign, so the peer hands it one function, the smallest of the zero functions (runtime/bench/peer_numba.py):
    with one function per contact it integrated contacts that had crossed first in the wrong mode and switched 120
    times instead of 104. Against the composite at rtol 1e-10 (RK45 with events to 1e-13 rad): the same switches
    of every contact in every output interval, and the trajectory within DOP853's event floor."""
    pytest.importorskip("numbalsoda")
    from apexseal.runtime.bench.composite import composite_c
    from apexseal.runtime.bench.peer_numba import NumbaPeer

    scene, nm = numba_model
    f = model_functions(scene)
    settle = RunSettings(method="composite", rtol=1e-8, samples_per_revolution=360, pressure="linear")
    problem = make_problem("default", scene, scene.effects, f, samples=360, span=2 * math.pi, settle_revolutions=3,
                           settle_settings=settle, pressure_profile="linear")
    ref_z = composite_c(problem, 1e-10, None, None, None, 1e-13).run(problem.z0, problem.params, problem.theta0,
                                                                      problem.pressures).z
    ref = trajectory(problem, ref_z)
    assert ref.events.sum() > 50  # the clusters are there
    peer = NumbaPeer(problem, nm)
    peer.build(numbalsoda=True)
    z = peer.run("numbalsoda-DOP853", 1e-7).z
    counts = HybridLayout.of(f).counts  # each contact's switches so far, at the end of every output interval
    np.testing.assert_array_equal(np.asarray(z)[counts], np.asarray(ref_z)[counts])
    assert errors(trajectory(problem, z), ref)["state"] < 1e-4


def test_the_peer_refuses_a_problem_of_other_effects():
    """The peer is printed from the default effects' model: a problem with an effect off has a shorter parameter
    vector now (it had the default's, and the peer computed the default effects' physics for it)."""
    import types

    pytest.importorskip("numba")
    from apexseal.derive.symbols import PARAMETER_NAMES
    from apexseal.runtime.bench.peer_numba import NumbaPeer

    names = tuple(n for n in PARAMETER_NAMES if n != "cw")  # housing damping off
    problem = types.SimpleNamespace(name="no-housing-damping", functions=types.SimpleNamespace(parameter_names=names))
    with pytest.raises(ValueError, match="problem no-housing-damping has others"):
        NumbaPeer(problem, None)
