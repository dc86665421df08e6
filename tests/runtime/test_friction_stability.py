"""Explicit Euler on the friction regularisation mu N tanh(v / v_eps) (runtime/solving/friction_stability.py).

Where the seal sticks the law is a damper mu N / v_eps; one Euler step multiplies the sliding velocity by
1 - h mu N / (v_eps m), so beyond 2 the velocity flips sign at every step. Before, such a run completed with that
wrong friction and no word; now it is refused before the first step (a normal force held from the start: the
spring's preload) or stopped (the normal forces reached), with the steps, the v_eps or the method that would do.
"""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest
from hard_helpers import load, short_run

import apexseal
from apexseal.runtime.results.plausibility import PenetrationWarning
from apexseal.runtime.solving.friction_stability import MAX_FRICTION_SHARE, beyond_shares

#: the default scene with a sticky groove: a high seal-groove friction and a narrow regularisation
STICKY_GROOVE = {"friction.mu2": 0.5, "friction.v_eps": "0.1 mm/s"}
#: the default scene whose spring preload (10 N) holds a sticky seal-spring friction from the start
STICKY_SPRING = {"friction.mus": 0.9, "friction.v_eps": "10 um/s", "friction.mu2": 0.001}


def simulate(scene, functions, **kw):
    """One revolution of explicit Euler, interpreted, 360 samples."""
    kw = {"method": "euler", "samples_per_revolution": 360, "compile_c": False} | kw
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PenetrationWarning)
        return apexseal.simulate(scene, revolutions=1, functions=functions, **kw)


def _remedies(reason: str) -> tuple[float, int, float]:
    """h mu N / (v_eps m), and the steps per revolution and the v_eps (m/s) that bring it to 2, as a stop says."""
    found = re.search(r"h mu N / \(v_eps m\) = ([0-9.e+-]+) at (\d+) steps per revolution, above 2, .* use at least "
                      r"(\d+) solver\.euler_steps_per_revolution, a wider friction\.v_eps \(at least ([0-9.e+-]+) m/s\)",
                      reason)
    assert found, reason
    step, steps, needed, v_eps = float(found[1]), int(found[2]), int(found[3]), float(found[4])
    assert needed == pytest.approx(steps * step / 2, rel=5e-3)  # h mu N / (v_eps m) is written to 3 digits
    return step, needed, v_eps


@pytest.fixture(scope="module")
def fns(default_functions):
    return default_functions.sx


@pytest.mark.slow  # 7 s of a 2-core test process: in the second step, to keep the default suite under 10 min
def test_euler_stops_where_its_groove_friction_flips_sign_at_every_step(default_scene, fns):
    """mu2 = 0.5 with v_eps = 0.1 mm/s: h mu N / (v_eps m) = 16 on the groove's normal force (about 200 N) at the
    default 200000 steps. Euler's radial velocity then changes sign at most samples where rosenbrock's keeps it
    (5 steps per sample, so a sign flipping at every step shows at every sample), and the run, which completed before
    with that friction, stops with the numbers and the remedies: twice the v_eps it names runs, and so does
    rosenbrock."""
    scene = default_scene.with_overrides(**STICKY_GROOVE)
    flips = {}
    for method, kw in (("euler", {"steps_per_revolution": 200000}), ("rosenbrock", {})):
        _, X, _, _ = short_run(scene, fns, method, 90, samples=40000, **kw)
        flips[method] = int(np.count_nonzero(np.sign(X[3, 1:]) != np.sign(X[3, :-1])))
    assert flips["euler"] > 10 * flips["rosenbrock"], flips

    r = simulate(scene, fns)
    assert r.status == "failed", r.stop
    assert 0 < r.stop.theta < np.pi and r.n > 1 and np.isfinite(r.state).all()  # the samples before are kept
    reason = r.stop.reason
    assert "explicit Euler cannot follow the friction of the seal along the groove walls" in reason
    assert "friction.mu2 = 0.5" in reason and "friction.v_eps = 0.0001 m/s" in reason
    assert f"over {MAX_FRICTION_SHARE:.0%} of a revolution" in reason and "'rosenbrock'" in reason
    step, _, v_eps = _remedies(reason)
    assert step > 2 and v_eps == pytest.approx(1e-4 * step / 2, rel=5e-3)
    # the remedies are estimated from the forces of the failed run: twice the width leaves a margin
    assert simulate(scene.with_overrides(**{"friction.v_eps": 2 * v_eps}), fns).ok
    assert simulate(scene, fns, method="rosenbrock").ok


def test_euler_refuses_a_sticky_spring_before_the_first_step(default_scene, fns):
    """The spring's preload presses the seal's back face on it from the start: with mus = 0.9 and v_eps = 10 um/s
    the run is refused before its first step, naming the spring's coefficient and the preload it judged."""
    scene = default_scene.with_overrides(**STICKY_SPRING)
    r = simulate(scene, fns)
    assert r.status == "failed" and r.n == 1 and r.stop.theta == 0.0
    reason = r.stop.reason
    assert "the friction of the seal's back face across the spring" in reason and "friction.mus = 0.9" in reason
    assert "at the start, held all the run" in reason
    preload = scene.parameters["ks"] * scene.parameters["delta_s"]
    judged = float(re.search(r"a normal force N = ([0-9.e+-]+) N", reason)[1])
    assert judged == pytest.approx(preload, rel=5e-3)  # the preload, written to 3 digits
    step, _, v_eps = _remedies(reason)
    assert step > 2 and simulate(scene.with_overrides(**{"friction.v_eps": 2 * v_eps}), fns).ok


def test_the_share_is_counted_over_the_revolution_whatever_the_calls_it_is_cut_into(default_scene, fns, monkeypatch):
    """The run check adds up a revolution's samples over its integrator calls (36 with a wall-time budget) and starts
    again with the next revolution."""
    from apexseal.runtime.solving import friction_stability

    scene = default_scene.with_overrides(**STICKY_GROOVE)
    monkeypatch.setattr(friction_stability, "MAX_FRICTION_SHARE", 1.01)  # the run unchecked: its outputs
    r = simulate(scene, fns)
    monkeypatch.undo()
    Y = np.vstack([r.outputs[n][1:] for n in fns.output_names])  # the samples after the start
    dth = 2 * np.pi / 360
    p = scene.parameter_vector()
    k, _ = friction_stability.FrictionWatch(fns, p, 200000).check(0, Y, dth)
    watch = friction_stability.FrictionWatch(fns, p, 200000)
    chunks = [watch.check(0, Y[:, i:i + 10], dth) for i in range(0, k + 1, 10)]  # the last holds sample k
    assert all(c is None for c in chunks[:-1]) and 10 * (len(chunks) - 1) + chunks[-1][0] == k
    again = friction_stability.FrictionWatch(fns, p, 200000)
    assert again.check(0, Y[:, :k], dth) is None and again.check(1, Y[:, :k], dth) is None  # a new revolution


@pytest.mark.parametrize("name", ["default", "pressure-square-wave"])
def test_impacts_beyond_the_bound_do_not_stop_a_stable_scene(name, default_scene, fns):
    """Where the seal sticks in its groove, its impacts on the groove walls take the friction beyond Euler's bound
    for a few samples each (pressure-square-wave's pressure steps slam it across the groove): below the share of a
    revolution the run allows, so Euler runs these scenes as before."""
    scene = default_scene if name == "default" else load(name)
    r = simulate(scene, fns, samples_per_revolution=3600)
    assert r.status == "completed", r.stop
    share = beyond_shares(r)["friction.mu2"]
    assert share < MAX_FRICTION_SHARE
    if name == "pressure-square-wave":
        assert share > 0  # the check sees its impacts


def test_a_friction_law_that_is_off_is_not_checked(default_scene):
    """The sticky groove of the first test with its friction switched off: no law of the model reads mu2, so Euler
    runs it; the spring's friction, on, is still weighed."""
    from apexseal.generated.load import load_functions

    scene = default_scene.with_overrides(**STICKY_GROOVE, **{"effects.groove_friction": False})
    fns = load_functions(scene.effects, scene.assumptions, flags="quick").sx
    r = simulate(scene, fns)
    assert r.status == "completed", r.stop
    assert set(beyond_shares(r)) == {"friction.mus"}


def test_the_normal_force_and_the_sliding_speed_are_read_back_from_the_force_and_the_friction_power():
    """|F| = N sqrt(1 + mu^2 tanh(v / v_eps)^2) and Pf = mu N tanh(v / v_eps) v give N back, sticking or sliding,
    and |v| where tanh(v / v_eps) still tells it (a fast slide reads as infinitely fast)."""
    from apexseal.runtime.solving.friction_stability import normal_and_speed

    rng = np.random.default_rng(1)
    mu, v_eps = 0.7, 1e-4
    N = rng.uniform(1.0, 500.0, 300)
    v = rng.normal(0.0, 1.0, 300) * np.repeat([1e-6, 1e-4, 1.0], 100)  # stuck, in the band, sliding fast
    t = np.tanh(v / v_eps)
    normal, speed = normal_and_speed(N * np.sqrt(1 + (mu * t) ** 2), mu * N * t * v, mu, v_eps)
    np.testing.assert_allclose(normal, N, rtol=1e-12)
    told = np.abs(v) < 10 * v_eps
    np.testing.assert_allclose(speed[told], np.abs(v[told]), rtol=1e-6, atol=1e-12)
    assert np.isinf(speed[np.abs(v) > 30 * v_eps]).all()
