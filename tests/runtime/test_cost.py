"""The cost of a run said before it starts: a slow rotor against the seal's fastest ringing (runtime/solving/cost.py)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from apexseal.runtime.solving import run as sim
from apexseal.runtime.solving.cost import (
    DEFAULT_RINGING_PER_REVOLUTION,
    SLOW_FACTOR,
    STEPS_PER_RINGING_RAD,
    SlowRunWarning,
    estimate,
    ringing_per_revolution,
    slow_rotor_note,
)
from apexseal.runtime.solving.ringing import ringing


@pytest.fixture(scope="module")
def fns(default_functions):
    return default_functions.sx


def _cost(scene, fns, **settings):
    p = scene.parameter_vector(fns.parameter_names)
    ring = ringing(fns, p, 0.0, np.zeros(6))
    omega = fns.omega(p)
    return estimate(ring, omega, sim.RunSettings(**settings)), ring, omega


def test_the_default_constant_is_the_default_scenes_ringing(default_scene, fns):
    p = default_scene.parameter_vector(fns.parameter_names)
    per_rev = ringing_per_revolution(ringing(fns, p, 0.0, np.zeros(6)).rad_s, fns.omega(p))
    assert per_rev == pytest.approx(DEFAULT_RINGING_PER_REVOLUTION, rel=1e-3)


def test_a_1_rpm_run_is_estimated_1500_times_the_default_and_noted(default_scene, fns):
    """Nothing estimated a run's cost before it started: 1 rpm (the bottom of the speed's plausible range) took
    erk 52 s a revolution on the default scene, 650 times the 0.08 s at 1500 rpm, and on a scene with more switches
    the compiled call failed after 90 s and its re-run crawled at 0.5 deg/s, with no word of what to expect."""
    cost, ring, omega = _cost(default_scene, fns, revolutions=3)
    assert cost.factor == pytest.approx(1.0, rel=1e-3) and slow_rotor_note(cost, ring, omega) is None
    slow = default_scene.with_overrides(**{"operation.rpm": 1})
    cost, ring, omega = _cost(slow, fns, revolutions=3)
    assert cost.factor == pytest.approx(1500, rel=1e-3)
    # the law: erk's steps follow the radians of ringing per revolution (checked against erk's own steps below)
    assert cost.steps_per_revolution == pytest.approx(1500 * DEFAULT_RINGING_PER_REVOLUTION * STEPS_PER_RINGING_RAD,
                                                      rel=1e-3)
    assert 100 < cost.seconds < 300  # three revolutions of about a minute each
    note = slow_rotor_note(cost, ring, omega)
    assert "operation.rpm = 1 rpm" in note and "1.5e+03 times the default" in note and "3 revolution(s)" in note
    assert "--method rosenbrock" in note and "higher operation.rpm" in note


@pytest.mark.slow
def test_the_estimate_is_the_steps_erk_takes_on_a_slow_rotor(default_scene, fns):
    """The estimate's constant was measured at 60 rpm; at 30 rpm the law (steps grow like the ringing per revolution)
    must give the steps erk takes (interpreted, which counts them): 588,610 estimated, 581,728 taken (one run,
    20 s of CPU)."""
    import apexseal

    scene = default_scene.with_overrides(**{"operation.rpm": 30})
    cost, _, _ = _cost(scene, fns)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the slow rotor's note, the plausibility checks
        result = apexseal.simulate(scene, revolutions=1, interpreted=True, progress=False)
    assert result.status == "completed"
    assert result.info["cost_estimate"]["steps_per_revolution"] == pytest.approx(cost.steps_per_revolution)
    assert result.info["solver_stats"]["n_steps"] == pytest.approx(cost.steps_per_revolution, rel=0.1)


def test_the_note_starts_at_the_threshold_and_not_for_implicit_methods(default_scene, fns):
    rpm = 1500 / SLOW_FACTOR
    for factor, noted in ((0.99, False), (1.01, True)):
        cost, ring, omega = _cost(default_scene.with_overrides(**{"operation.rpm": rpm / factor}), fns)
        assert (slow_rotor_note(cost, ring, omega) is not None) == noted, factor
    assert _cost(default_scene.with_overrides(**{"operation.rpm": 1}), fns, method="rosenbrock")[0] is None


class _Refused(RuntimeError):
    pass


@pytest.mark.parametrize("rpm, noted, per_call", [(1, True, 20), (1500, False, 720)])
def test_the_note_is_given_before_the_first_step_and_cuts_the_revolution(default_scene, fns, monkeypatch, rpm, noted,
                                                                         per_call):
    """The warning comes before any integrator call (a run whose engine refuses to be built has warned already), and
    a slow run's revolution is cut into 36 calls, 10 degrees each, so that its bar moves within a revolution: at 1
    rpm erk's one call per revolution took 52 s with the bar at 0/1 all along."""
    asked = {}

    def refuse(*a, n_samples, **k):
        asked["n_samples"] = n_samples
        raise _Refused

    monkeypatch.setattr(sim.engine_pool, "lease", refuse)
    scene = default_scene.with_overrides(**{"operation.rpm": rpm})
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(_Refused):
            sim.run(fns, scene.parameter_vector(), sim.RunSettings(compile_c=False), theta_start=0.0,
                    state0=np.zeros(6), revolutions=1, pressure=scene.pressure)
    assert bool([w for w in caught if issubclass(w.category, SlowRunWarning)]) == noted, [str(w.message) for w in caught]
    assert asked["n_samples"] == per_call  # 360 samples, 2 intervals each (720 table rows)


def test_a_resumed_run_is_estimated_for_the_revolutions_it_has_left(default_scene, fns):
    """`--resume` with 1 of 4 revolutions left at 10 rpm said "4 revolution(s): about 18 s" (it took 3.5 s): the
    estimate counted the revolutions asked for, not those left."""
    slow = default_scene.with_overrides(**{"operation.rpm": 1})
    whole, ring, omega = _cost(slow, fns, revolutions=4)
    p = slow.parameter_vector(fns.parameter_names)
    left = estimate(ring, fns.omega(p), sim.RunSettings(revolutions=4), done=3)
    assert left.revolutions == 1 and left.seconds == pytest.approx(whole.seconds / 4, rel=1e-12)
    assert "1 revolution(s) left (of 4): about" in slow_rotor_note(left, ring, omega)
