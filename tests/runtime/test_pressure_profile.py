"""Chamber pressures linear over each output interval (``RunSettings.pressure = "linear"``, generated/hybrid.py).

The controls are an intercept and a slope per interval; the hybrid DAE must see exactly the line through the
pressures at the interval's ends, a constant pressure must give the "steps" result, and the setting must be
refused where it cannot be honoured.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from apexseal.generated.hybrid import build_hybrid_dae, linear_controls
from apexseal.generated.layout import HybridLayout
from apexseal.generated.scaling import scaled_rhs, state_scale
from apexseal.runtime.api import model_functions, simulate
from apexseal.runtime.scenes.scene import load_scene
from apexseal.runtime.solving.event_integrator import EventIntegrator
from apexseal.runtime.solving.settings import RunSettings, SettingsError


def test_linear_controls_pass_through_the_values_at_the_edges():
    grid = np.array([0.1, 0.25, 0.4])
    P = np.array([[1e5, 3e5, 2e5, 2e5], [7e5, 6e5, 9e5, 1e5]])
    U = linear_controls(P, grid)
    assert U.shape == (4, 3)
    starts, ends = np.r_[0.0, grid[:-1]], grid
    np.testing.assert_allclose(U[:2] + U[2:] * starts, P[:, :-1], rtol=1e-14)
    np.testing.assert_allclose(U[:2] + U[2:] * ends, P[:, 1:], rtol=1e-14)
    assert U[2, 2] == 0.0  # a flat interval has zero slope


def test_linear_controls_refuse_the_interval_means_shape():
    with pytest.raises(ValueError, match=r"pressures: expected the values at the 4 interval edges, shape \(2, 4\)"):
        linear_controls(np.ones((2, 3)), np.array([0.1, 0.2, 0.3]))


def test_the_hybrid_dae_sees_the_interpolated_pressure_inside_an_interval():
    scene = load_scene()
    f = model_functions(scene, compiled=False)
    names = tuple(f.parameter_names)
    h = build_hybrid_dae(f.rhs, f.guards, len(names), names.index("omega"), pressure="linear")
    dae = h.dae
    assert dae["u"].size1() == 4
    ode = ca.Function("ode", [dae["t"], dae["x"], dae["p"], dae["u"]], [dae["ode"]])
    lay = HybridLayout.of(f)
    params = scene.parameter_vector()
    omega = float(params[names.index("omega")])
    theta0 = 0.3
    X = np.array([0.2e-6, -30e-6, 1e-3, 1e-3, 0.01, 0.5])
    active = np.array([1.0, 0, 0, 1, 1, 1])[:lay.n_g]
    z = lay.pack(X / state_scale(omega, lay.state_names), active)
    edges = np.array([1.0e6, 1.6e6])  # Pa at tau = 0 and tau = 0.02; Pb = 2e5 Pa throughout
    U = linear_controls(np.array([edges, [2e5, 2e5]]), np.array([0.02]))[:, 0]
    tau = 0.015  # three quarters into the interval: Pa = 1.45e6 Pa
    got = np.array(ode(tau, z, np.r_[params, theta0], U)).ravel()[:lay.n_x]
    P = np.array([1.45e6, 2e5])
    want = np.array(scaled_rhs(f.rhs(theta0 + tau, X, active, params, P), omega, lay.state_names)).ravel()
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * np.abs(want).max())
    with pytest.raises(ValueError, match="pressure = 'ramp'"):
        build_hybrid_dae(f.rhs, f.guards, len(names), names.index("omega"), pressure="ramp")


def test_a_constant_pressure_gives_the_same_run_either_way():
    scene = load_scene()
    f = model_functions(scene, compiled=False)
    names = tuple(f.parameter_names)
    params = scene.parameter_vector()
    lay = HybridLayout.of(f)
    omega = float(params[names.index("omega")])
    n, span = 12, math.radians(6)
    z0 = lay.pack(np.zeros(6) / state_scale(omega, lay.state_names), np.zeros(lay.n_g))
    out = {}
    for profile, P in (("steps", np.full((2, n), 4e5)), ("linear", np.full((2, n + 1), 4e5))):
        e = EventIntegrator(f.rhs, f.guards, len(names), names.index("omega"), method="erk", rtol=1e-8, atol=None,
                            n_samples=n, span=span, compile_c=False, pressure=profile)
        out[profile] = e.run(z0, params, 0.0, P).z
    np.testing.assert_allclose(out["linear"], out["steps"], rtol=1e-12, atol=1e-12)
    assert np.abs(out["steps"][:lay.n_x]).max() > 1e-3  # the seal moved: the comparison is not of two rests


def test_an_engine_without_the_linear_profile_is_refused_by_name():
    from apexseal.runtime.solving.methods import METHODS, Engine, register_method

    class HoldsPerInterval(Engine):
        """A user's engine that takes interval means only (the Engine default)."""

    register_method("holds-per-interval", HoldsPerInterval, "test engine")
    try:
        with pytest.raises(SettingsError, match=r"pressure = \"linear\": method 'holds-per-interval' integrates the "
                                                r"pressure profiles steps") as err:
            RunSettings(method="holds-per-interval", pressure="linear")
        assert err.value.keys() == ["pressure"]
    finally:
        METHODS.pop("holds-per-interval")


def _ramp_run(method, profile, P, n, span, **kw):
    """``n`` samples over ``span`` from rest at crank angle 0 with the pressures ``P`` (interval means or edge
    values), engine of ``method`` on the interpreted model."""
    from apexseal.runtime.solving.methods import make_engine

    scene = load_scene()
    f = model_functions(scene, compiled=False)
    st = RunSettings(method=method, rtol=1e-9, pressure=profile, compile_c=False, **kw)
    engine = make_engine(f, st, n_samples=n, span=span, compile_c=False)
    from apexseal.generated.scaling import to_scaled
    from apexseal.runtime.api import initial_state
    from apexseal.runtime.solving.preflight import initial_activations

    lay = HybridLayout.of(f)
    params = scene.parameter_vector()
    omega = float(params[list(f.parameter_names).index("omega")])
    X0 = initial_state(scene, f)  # the scene's start, contacts closed by their gaps (as a run starts)
    z0 = lay.pack(to_scaled(X0, omega, lay.state_names), initial_activations(f, 0.0, X0, params, P[:, 0]))
    return engine.run(z0, params, 0.0, P).z[:lay.n_x]


N_RAMP, SPAN_RAMP = 12, math.radians(6)
#: a chamber pressure rising from 2 to 14 bar over the span, Pb at 1 bar: the edge values and the interval means
EDGES_RAMP = np.vstack([np.linspace(2e5, 14e5, N_RAMP + 1), np.full(N_RAMP + 1, 1e5)])
MEANS_RAMP = 0.5 * (EDGES_RAMP[:, :-1] + EDGES_RAMP[:, 1:])


@pytest.mark.parametrize(("method", "kw"), [("cvodes", {}), pytest.param("idas", {}, marks=pytest.mark.slow),
                                         pytest.param("rk", {"steps_per_revolution": 400_000}, marks=pytest.mark.slow)])
def test_the_stepper_engines_integrate_linear_pressures_as_erk_does(method, kw):
    """The engines of the apexseal event loop take the line through the edge values too: on a pressure ramp they
    agree with erk's linear run, and differ from their own interval-means run by far more than they disagree."""
    ref = _ramp_run("erk", "linear", EDGES_RAMP, N_RAMP, SPAN_RAMP)
    got = _ramp_run(method, "linear", EDGES_RAMP, N_RAMP, SPAN_RAMP, **kw)
    held = _ramp_run(method, "steps", MEANS_RAMP, N_RAMP, SPAN_RAMP, **kw)
    scale = np.abs(ref).max(axis=1, keepdims=True)
    err, shift = np.abs(got - ref) / scale, np.abs(held - ref) / scale
    assert err.max() < 1e-3, (method, err.max())
    assert shift.max() > 10 * err.max(), (method, shift.max(), err.max())


def test_explicit_euler_steps_along_the_pressure_line():
    """Two Euler steps in one output interval, against the rule written out: the second step sees the pressure
    of the line at its own crank angle (explicit Euler on the switched rhs is too sensitive at the contacts'
    stiffness for a comparison with erk over a span)."""
    from apexseal.runtime.api import initial_state
    from apexseal.runtime.solving.fixed_step import EulerIntegrator

    scene = load_scene()
    fns = model_functions(scene, compiled=False)
    f, states = fns.sx(), fns.state_names
    names = tuple(f.parameter_names)
    params = scene.parameter_vector()
    omega = float(params[names.index("omega")])
    h, theta0 = 1e-6, 0.3
    engine = EulerIntegrator(f.rhs_switched, f.guards, len(names), names.index("omega"), n_samples=1,
                             steps_per_revolution=round(2 * 2 * math.pi / (2 * h)), span=2 * h, compile_c=False,
                             state_names=states, pressure="linear")
    assert engine.sub == 2
    h = engine.h  # the step as the engine computes it (span / steps)
    lay = engine.layout
    sc = np.asarray(state_scale(omega, states), float).ravel()
    X0 = initial_state(scene, fns)
    z0 = lay.pack(X0 / sc, np.zeros(lay.n_g))
    P = np.array([[3e5, 9e5], [1e5, 1e5]])  # Pa rises by 6 bar over the interval
    got = engine.run(z0, params, theta0, P).z[:lay.n_x, 0]

    def rate(theta, z, u):
        return np.array(scaled_rhs(f.rhs_switched(theta, z * sc, params, u), omega, states)).ravel()

    z1 = z0[:lay.n_x] + h * rate(theta0, z0[:lay.n_x], P[:, 0])
    slope = (P[:, 1] - P[:, 0]) / (2 * h)
    want = z1 + h * rate(theta0 + h, z1, P[:, 0] + slope * ((theta0 + h) - theta0))  # the engine's rounding of h
    held = z1 + h * rate(theta0 + h, z1, P[:, 0])
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-15)
    assert np.abs(held - want).max() > 1e6 * np.abs(got - want).max()


@pytest.mark.parametrize(("method", "kw"), [("cvodes", {}), ("euler", {"steps_per_revolution": 200_000})])
def test_a_constant_pressure_gives_the_same_run_either_way_with_every_engine(method, kw):
    """Zero slopes change nothing: the "linear" form of a constant pressure is the "steps" run, bit for bit."""
    const = 4e5
    lin = _ramp_run(method, "linear", np.full((2, N_RAMP + 1), const), N_RAMP, SPAN_RAMP, **kw)
    steps = _ramp_run(method, "steps", np.full((2, N_RAMP), const), N_RAMP, SPAN_RAMP, **kw)
    np.testing.assert_array_equal(lin, steps)
    assert np.abs(steps).max() > 1e-3


def test_an_unknown_profile_names_the_allowed_ones():
    with pytest.raises(SettingsError, match="pressure = \"ramp\": not allowed; allowed: steps, linear"):
        RunSettings(pressure="ramp")


def test_simulate_with_linear_pressures_records_it_and_differs_from_steps_by_little():
    """One revolution of the default scene at 360 samples: the linear run completes, says so in its info, and its
    mean friction power is within 3 % of the interval-means run (measured 2.5 % at this grid, 0.1 % at 3600)."""
    scene = load_scene()
    runs = {p: simulate(scene, revolutions=1, samples_per_revolution=360, pressure=p) for p in ("steps", "linear")}
    for p, r in runs.items():
        assert r.status == "completed", r.stop
        assert r.info["pressure"] == p
    pf = {p: float(r.friction_power) for p, r in runs.items()}
    assert pf["linear"] != pf["steps"]
    assert abs(pf["linear"] - pf["steps"]) < 0.03 * abs(pf["steps"])


def test_linear_run_without_chamber_pressure_integrates_zero_pressures():
    """No pressure source (the chamber-pressure effect off): the linear engine still gets its (2, n + 1) zeros."""
    from apexseal.runtime.api import initial_state
    from apexseal.runtime.solving.run import run

    scene = load_scene()
    f = model_functions(scene)
    st = RunSettings(method="erk", rtol=1e-6, samples_per_revolution=36, pressure="linear")
    res = run(f, scene.parameter_vector(), st, theta_start=0.0, state0=initial_state(scene, f), revolutions=1)
    assert res.status == "completed", res.stop
    assert res.info["pressure"] == "linear"


def test_the_scene_key_reaches_the_run_settings_and_a_run_writes_it_back():
    from apexseal.runtime.api import scene_that_ran, settings_of

    scene = load_scene()
    assert settings_of(scene).pressure == "linear"  # the default
    steps = scene.with_overrides(**{"solver.pressure": "steps"})
    assert settings_of(steps).pressure == "steps"
    ran = scene_that_ran(scene, settings_of(scene, pressure="steps"))
    assert ran.solver.pressure == "steps" and ran.content_hash() == steps.content_hash()
    with pytest.raises(Exception, match="solver.pressure"):
        scene.with_overrides(**{"solver.pressure": "ramp"})


def test_angle_settings_are_written_back_with_their_unit():
    """event_tol and chatter_window are crank angles: a run's scene writes them with "rad" (a bare angle is refused
    by the scene as ambiguous, which made simulate(scene, event_tol=...) fail before it ran)."""
    from apexseal.runtime.api import scene_that_ran, settings_of

    scene = load_scene()
    ran = scene_that_ran(scene, settings_of(scene, event_tol=1e-12, chatter_window=2e-3))
    assert ran.solver.event_tol == 1e-12 and ran.solver.chatter_window == 2e-3
    assert settings_of(ran).event_tol == 1e-12 and settings_of(ran).chatter_window == 2e-3


def test_substeps_make_the_integrator_see_every_row_of_the_table():
    from apexseal.runtime.scenes.pressure import ConstantPressure
    from apexseal.runtime.solving.run import pressure_substeps

    table = load_scene().pressure  # 720 rows, every 0.5 deg
    assert table.rows_per_revolution() == 720
    assert [pressure_substeps(table, n) for n in (36, 100, 360, 720, 721, 3600)] == [20, 8, 2, 1, 1, 1]
    assert pressure_substeps(ConstantPressure(2e5, 1e5), 36) == 1
    assert pressure_substeps(None, 36) == 1


@pytest.mark.parametrize("profile", ["linear", "steps"])
def test_the_physics_does_not_depend_on_how_often_the_run_is_sampled(profile):
    """Sampled every 1 deg, the run integrates every 0.5 deg row of the default scene's table, as a run sampled every
    0.5 deg does: the same integrator, the same numbers at the common samples (before, with the pressures linear
    between the 1 deg samples, or held at their 1 deg means, the corners of the table's rows were cut and the motion
    differed)."""
    scene = load_scene()
    coarse = simulate(scene, revolutions=1, samples_per_revolution=360, pressure=profile)
    fine = simulate(scene, revolutions=1, samples_per_revolution=720, pressure=profile)
    assert coarse.info["pressure_substeps"] == 2 and fine.info["pressure_substeps"] == 1
    assert coarse.n == 361 and fine.n == 721
    np.testing.assert_array_equal(coarse.theta, fine.theta[::2])
    np.testing.assert_array_equal(coarse.state, fine.state[:, ::2])
    np.testing.assert_array_equal(coarse.events, fine.events[:, ::2])
    for name in ("Pf_total", "F_housing_X", "Pa", "Pb"):
        np.testing.assert_array_equal(coarse.outputs[name], fine.outputs[name][::2])
    assert coarse.n_events == fine.n_events
