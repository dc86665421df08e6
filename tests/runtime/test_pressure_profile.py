"""Chamber pressures linear over each output interval (``RunSettings.pressure = "linear"``, runtime/solving/hybrid.py).

The controls are an intercept and a slope per interval; the hybrid DAE must see exactly the line through the
pressures at the interval's ends, a constant pressure must give the "steps" result, and the setting must be
refused where it cannot be honoured.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from apexseal.runtime.api import model_functions, simulate
from apexseal.runtime.scenes.scene import load_scene
from apexseal.runtime.solving.event_integrator import EventIntegrator
from apexseal.runtime.solving.hybrid import build_hybrid_dae, linear_controls
from apexseal.runtime.solving.layout import HybridLayout
from apexseal.runtime.solving.scaling import scaled_rhs, state_scale
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


@pytest.mark.parametrize("method", ["cvodes", "euler", "collocation"])
def test_linear_pressure_is_refused_by_methods_that_hold_them_per_interval(method):
    with pytest.raises(SettingsError, match=r"pressure = \"linear\": needs an event method") as err:
        RunSettings(method=method, pressure="linear")
    assert err.value.keys() == ["pressure"]


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
    assert settings_of(scene).pressure == "steps"
    linear = scene.with_overrides(**{"solver.pressure": "linear"})
    assert settings_of(linear).pressure == "linear"
    ran = scene_that_ran(scene, settings_of(scene, pressure="linear"))
    assert ran.solver.pressure == "linear" and ran.content_hash() == linear.content_hash()
    with pytest.raises(Exception, match="solver.pressure"):
        scene.with_overrides(**{"solver.pressure": "ramp"})
