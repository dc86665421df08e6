"""Sliding speeds and Archard's sliding work at the seal's contacts (runtime/results/wear.py): a run's summary had
forces, lift-off and friction power, but no speed of the seal on its walls, no wear measure and no seal mass."""

from __future__ import annotations

import math
import warnings
from types import SimpleNamespace

import numpy as np
import pytest

import apexseal
from apexseal.runtime.results.quantities import collect, quantity_help
from apexseal.runtime.results.result import SimulationResult
from apexseal.runtime.results.summary import summarise
from apexseal.runtime.results.wear import wear

SAMPLES = 360  # the integrator of tests/runtime/test_simulate.py: compiled once per session
OMEGA = 100.0  # rad/s, the hand-made result's
#: the hand-made tip contact: normal force N (N) and sliding velocity v (m/s) at five samples over one revolution,
#: the tip off the housing at the fourth
NORMAL = np.array([100.0, 200.0, 300.0, 0.0, 400.0])
SLIDE = np.array([4.0, 5.0, -6.0, 7.0, 8.0])
CLOSED = np.array([True, True, True, False, True])


def _tip_result(*, mu: float | None, scene=None) -> SimulationResult:
    """One revolution of five samples with the tip's force N n + f t on the housing (n, t at lambda = 0.2 rad, as
    derive/submodels/housing.py builds them) and, with ``mu``, its Coulomb friction f = -mu N tanh(v / v_eps) and
    power Pf = mu N tanh(v / v_eps) v."""
    lam, v_eps = 0.2, 1e-3
    n, t = np.array([-np.cos(lam), np.sin(lam)]), np.array([np.sin(lam), np.cos(lam)])
    f = np.zeros_like(NORMAL) if mu is None else -mu * NORMAL * np.tanh(SLIDE / v_eps)
    force = np.outer(n, NORMAL) + np.outer(t, f)
    outputs = {"F_housing_X": force[0], "F_housing_Y": force[1], "v_housing": SLIDE}
    if mu is not None:
        outputs["Pf_housing"] = -f * SLIDE
    theta = np.linspace(0.0, 2 * np.pi, NORMAL.size)
    return SimulationResult(theta=theta, time=theta / OMEGA, state=np.zeros((6, theta.size)),
                            closed=CLOSED[None, :], events=np.zeros((1, theta.size)), outputs=outputs,
                            guard_names=("xs5",), modes=["q1_h_s"] * theta.size, scene=scene)


@pytest.mark.parametrize("mu", [None, 0.1], ids=["no friction", "friction"])
def test_sliding_work_is_normal_force_times_speed_over_a_revolution(mu):
    """N |v| from the force, the sliding velocity and the friction power (|F|^2 = N^2 + f^2, Pf = |f| |v|): its mean
    over the samples after the first in W, its integral over the revolution in J, the speed |v| (a slide against
    the rotation counts by its size) and N |v| / Bs only while the tip is on the housing."""
    scene = SimpleNamespace(parameters={"ms": 0.02, "Bs": 0.1})
    block = wear(_tip_result(mu=mu, scene=scene))
    rate = NORMAL * np.abs(SLIDE)  # 400, 1000, 1800, 0, 3200 W
    power = rate[1:].mean()  # 1500 W
    on = CLOSED[1:]
    assert block["seal_mass_kg"] == 0.02 and block["seal_length_m"] == 0.1
    assert block["contacts"] == {"housing": {
        "contact_fraction": pytest.approx(0.75),
        "speed_mean_m_s": pytest.approx(np.abs(SLIDE[1:][on]).mean()),  # 5, 6, 8 m/s
        "speed_max_m_s": pytest.approx(8.0),
        "sliding_power_W": pytest.approx(power, rel=1e-12),
        "sliding_work_J_per_rev": pytest.approx(power * 2 * np.pi / OMEGA, rel=1e-12),
        "pv_mean_W_per_m": pytest.approx((rate[1:][on] / 0.1).mean(), rel=1e-12),
        "pv_max_W_per_m": pytest.approx(32000.0, rel=1e-12)}}


def test_without_the_scene_the_mass_and_the_load_per_length_are_null():
    """A result without its scene has no seal length: no N / Bs |v| is made up, and no mass."""
    block = wear(_tip_result(mu=0.1))
    assert block["seal_mass_kg"] is None and block["seal_length_m"] is None
    assert block["contacts"]["housing"]["pv_max_W_per_m"] is None
    assert block["contacts"]["housing"]["sliding_work_J_per_rev"] == pytest.approx(1500 * 2 * np.pi / OMEGA)


@pytest.fixture(scope="module")
def default_run(default_scene, default_functions):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return apexseal.simulate(default_scene, samples_per_revolution=SAMPLES, functions=default_functions.sx)


def test_a_run_reports_the_wear_of_each_contact_and_its_quantities(default_run, default_scene):
    """On the default scene the tip slides at 4.7 m/s or more, far beyond v_eps, where the friction law's tanh is 1:
    its friction power is mu1 times the sliding power, as the model's own Pf_housing says; the quantities of sweeps
    and ``apexseal compare`` are the summary's."""
    summary = summarise(default_run)
    p = default_scene.parameters
    block = summary["wear"]
    assert set(block["contacts"]) == {"housing", "i1", "c2", "i2", "c4", "spring"}
    tip = block["contacts"]["housing"]
    assert p["mu1"] * tip["sliding_power_W"] == pytest.approx(summary["mean_friction_power_W"]["housing"], rel=1e-9)
    assert tip["sliding_work_J_per_rev"] == pytest.approx(tip["sliding_power_W"] * 2 * np.pi / p["omega"], rel=1e-9)
    assert block["seal_mass_kg"] == p["ms"] and block["seal_length_m"] == p["Bs"]
    names = ("wear.housing.speed_mean", "wear.housing.work", "wear.i2.power", "wear.housing.pv_max", "wear.seal_mass")
    assert all(n in quantity_help() for n in names)
    got = collect(default_run, names)
    assert list(got.values()) == pytest.approx([tip["speed_mean_m_s"], tip["sliding_work_J_per_rev"],
                                 block["contacts"]["i2"]["sliding_power_W"], tip["pv_max_W_per_m"], p["ms"] * 1e3])
    assert not math.isnan(got["wear.i2.power"])


def test_the_console_line_of_a_tip_that_never_touches_says_so():
    """A seal held off the housing for the whole run printed "next most at c2 …" after nothing: the line now says
    that the tip never touches, and where the seal slides most."""
    from apexseal.runtime.results.wear import describe_wear

    empty = {"contact_fraction": 0.0, "speed_mean_m_s": None, "speed_max_m_s": None, "sliding_power_W": 0.0,
             "sliding_work_J_per_rev": 0.0, "pv_mean_W_per_m": None, "pv_max_W_per_m": None}
    c2 = dict(empty, contact_fraction=0.5, speed_mean_m_s=1e-3, speed_max_m_s=0.1, sliding_work_J_per_rev=0.0117)
    line = describe_wear({"seal_mass_kg": 0.0173, "seal_length_m": 0.1, "contacts": {"housing": empty, "c2": c2}})
    assert "the tip never touches the housing; most at c2 0.0117 J/rev" in line and "next most" not in line
