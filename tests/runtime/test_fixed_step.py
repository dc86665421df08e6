"""The one fixed-step engine with its two step rules (explicit Euler: apexseal's reading of the paper's "Euler
method"; RK4: the benchmark's rk4-C)."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from apexseal.generated.scaling import to_physical, to_scaled
from apexseal.runtime.solving.fixed_step import EulerIntegrator, FixedStepIntegrator, RK4Integrator

OMEGA, K = 150.0, 4.0e6  # rad/s, 1/s^2: sqrt(K) = 2000 rad/s, about 2 periods over the 0.1 rad span


def oscillator():
    """Three undamped oscillators x'' = -K x in the engine's calling convention, and a guard that never closes."""
    theta, X, p, u = ca.SX.sym("theta"), ca.SX.sym("X", 6), ca.SX.sym("p", 2), ca.SX.sym("u", 2)
    rhs = ca.Function("rhs_switched", [theta, X, p, u], [ca.vertcat(X[3:], -p[1] * X[:3])])
    guards = ca.Function("guards", [theta, X, p, u], [X[0] + 1.0])
    return rhs, guards


def final_error(engine_class, steps: int, span: float = 0.1) -> float:
    rhs, guards = oscillator()
    engine = engine_class(rhs, guards, 2, 0, n_samples=4, steps_per_revolution=steps, span=span, compile_c=False)
    X0 = np.array([1e-6, 2e-6, 0.0, 0.0, 0.0, 1e-3])
    z0 = np.r_[to_scaled(X0, OMEGA), 0.0, 0.0]
    out = engine.run(z0, np.array([OMEGA, K]), 0.0, np.zeros((2, 4)))
    assert out.stats == {"n_steps": engine.sub * 4, "n_rhs": engine.rule.stages * engine.sub * 4}
    t, w = span / OMEGA, np.sqrt(K)
    exact = np.r_[X0[:3] * np.cos(w * t) + X0[3:] / w * np.sin(w * t), -X0[:3] * w * np.sin(w * t) + X0[3:] * np.cos(w * t)]
    got = to_physical(out.z[:6, -1], OMEGA)
    return float(np.max(np.abs(got[:3] - exact[:3])))


@pytest.mark.parametrize(("engine_class", "order", "steps"), [(EulerIntegrator, 1, 64_000), (RK4Integrator, 4, 2_000)])
def test_each_rule_converges_at_its_order(engine_class, order, steps):
    errors = [final_error(engine_class, steps * m) for m in (1, 2, 4)]
    observed = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(observed - order) < 0.15), (errors, observed)


def test_the_rules_share_one_engine():
    assert issubclass(EulerIntegrator, FixedStepIntegrator) and issubclass(RK4Integrator, FixedStepIntegrator)
    assert "run" not in vars(EulerIntegrator) and "run" not in vars(RK4Integrator)
    assert (EulerIntegrator.rule.stages, RK4Integrator.rule.stages) == (1, 4)


def test_bench_rk4_and_the_paper_euler_are_built_by_the_one_engine(default_functions):
    """The benchmark's rk4-C and euler points use the runtime's fixed-step engine, steps counted per revolution."""
    from apexseal.runtime.bench.config import METHODS
    from apexseal.runtime.bench.methods import build_engine

    spans = {}
    for label, cls in (("rk4-C", RK4Integrator), ("euler-C", EulerIntegrator)):
        engine = build_engine(default_functions.sx, METHODS[label], 36_000, samples=18, span=np.pi / 2, flags="quick",
                              compiled=False)
        assert type(engine) is cls
        assert engine.sub * engine.n_samples == 9_000  # a quarter revolution of 36 000 steps per revolution
        spans[label] = engine.h * engine.sub * engine.n_samples
    assert spans["rk4-C"] == pytest.approx(np.pi / 2, rel=1e-12) == spans["euler-C"]


@pytest.mark.parametrize("engine_class", [EulerIntegrator, RK4Integrator])
def test_switches_are_counted_at_every_step_whatever_the_sampling(engine_class):
    """A contact that closes and opens within one output interval counts twice: the engine counts switches at every
    step, so an oscillator whose guard x < 0 is crossed 7 times in the span counts 7 (its exact zeros), with 2 output
    samples as with 16 (counted only where two samples differ, 2 samples showed 1 switch)."""
    k, span = 1.0e9, 0.1  # sqrt(k) = 3.2e4 rad/s: 21.1 rad of phase over the span (0.1 rad at OMEGA), 7 zeros of x
    rhs, guards = oscillator()
    guards = ca.Function("guards", [ca.SX.sym("t"), X := ca.SX.sym("X", 6), ca.SX.sym("p", 2), ca.SX.sym("u", 2)],
                         [X[0]])
    X0 = np.array([1e-6, 0.0, 0.0, 0.0, 0.0, 0.0])
    counts = {}
    for n in (2, 16):
        engine = engine_class(rhs, guards, 2, 0, n_samples=n, steps_per_revolution=2_000_000, span=span,
                              compile_c=False)
        out = engine.run(np.r_[to_scaled(X0, OMEGA), 0.0, 0.0], np.array([OMEGA, k]), 0.0, np.zeros((2, n)))
        counts[n] = out.z[-1]
    t = np.linspace(0.0, span / OMEGA, 200_001)
    exact = int(np.count_nonzero(np.diff(np.cos(np.sqrt(k) * t) < 0)))
    assert exact == 7 and counts[2][-1] == counts[16][-1] == exact, (counts, exact)
    np.testing.assert_array_equal(counts[16][7::8], counts[2])  # the same count at the samples both have


@pytest.mark.filterwarnings("ignore::apexseal.runtime.results.plausibility.PenetrationWarning")  # soft contacts
def test_switches_at_the_start_of_a_call_are_counted(soft_scene):
    """A fixed-step call counts the switch between the state it starts from and its first sample: cut into 36 calls
    a revolution has every switch count of one call, sample by sample (a switch at a call's start was dropped,
    unnoticed)."""
    import apexseal

    kw = dict(method="euler", samples_per_revolution=360, flags="quick")
    one, many = (apexseal.simulate(soft_scene, calls_per_revolution=c, **kw) for c in (1, 36))
    assert one.status == many.status == "completed" and one.events[:, -1].sum() > 20
    np.testing.assert_array_equal(many.events, one.events)
