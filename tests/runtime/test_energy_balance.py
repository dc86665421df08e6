"""The seal's energy balance over a run's output samples (runtime/results/energy.py; docs/results.md, "Energy
balance and sampling"): the summary's friction powers and Archard's sliding works are sums over the output samples,
and nothing said when those samples missed the groove contacts' impacts (at the default 3600 samples per revolution
a groove corner's friction work is off by tens of per cent, while the total friction power hardly moves)."""

from __future__ import annotations

import warnings
from types import SimpleNamespace

import numpy as np
import pytest

import apexseal
from apexseal.runtime.results.energy import energy_balance, inertial_acceleration
from apexseal.runtime.results.result import SimulationResult
from apexseal.runtime.results.summary import summarise


def test_inertial_acceleration_is_the_models():
    """The balance's inertia forces are those of Eq. 80 as derived (derive/kinematics.py, Eqs. 14-15 with the
    relative accelerations at zero), at arbitrary crank angles, positions and speeds."""
    import sympy as sp

    from apexseal.derive import kinematics
    from apexseal.derive.symbols import P, qs, theta, udots, us

    values = {"omega": 157.1, "r": 0.021, "Li": 0.034}
    exprs = [e.subs({u: 0 for u in udots}).subs({P[k]: v for k, v in values.items()})
             for e in kinematics.acceleration_rotor(kinematics.build())]
    derived = sp.lambdify((theta, *qs, *us), exprs)
    rng = np.random.default_rng(1)
    th, x, y, phi = rng.uniform(-7, 7, 20), rng.uniform(-1e-3, 1e-3, 20), rng.uniform(-1e-3, 1e-3, 20), np.zeros(20)
    xd, yd = rng.uniform(-1, 1, 20), rng.uniform(-1, 1, 20)
    want = derived(th, x, y, phi, xd, yd, phi)
    got = inertial_acceleration(th, x, y, xd, yd, values["omega"], values["r"], values["Li"])
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-9)


def test_a_resolved_balance_closes_and_names_each_loads_work():
    """A hand-made seal pushed along X by a constant 2 N from rest for one revolution (inertia off): the force's work
    equals the kinetic energy gained (the trapezoidal rule is exact for its linear power), so the residual is 0."""
    ms, omega, force = 0.02, 100.0, 2.0
    theta = np.linspace(0.0, 2 * np.pi, 11)
    t = theta / omega
    state = np.zeros((6, t.size))
    state[3] = force / ms * t  # x'
    state[0] = 0.5 * force / ms * t * t
    n = t.size
    outputs = {"F_push_X": np.full(n, force), "F_push_Y": np.zeros(n), "M_push": np.zeros(n)}
    scene = SimpleNamespace(parameters={"ms": ms, "Icg": 1e-6, "omega": omega, "r": 0.02, "Li": 0.03},
                            effects=SimpleNamespace(inertia=False), operation=SimpleNamespace(start_angle=0.0))
    result = SimulationResult(theta=theta, time=t, state=state, closed=np.zeros((0, n), bool),
                              events=np.zeros((0, n)), outputs=outputs, guard_names=(), modes=["q1"] * n,
                              scene=scene)
    block = energy_balance(result)
    gained = 0.5 * ms * (force / ms * t[-1]) ** 2
    assert block["kinetic_change_J_per_rev"] == pytest.approx(gained, rel=1e-12)
    assert block["work_J_per_rev"] == {"push": pytest.approx(gained, rel=1e-12)}
    assert block["inertial_J_per_rev"] == 0.0
    assert abs(block["residual_J_per_rev"]) < 1e-12 * gained and block["closes"]
    assert energy_balance(SimulationResult(theta=theta, time=t, state=state, closed=result.closed,
                                           events=result.events, outputs=outputs, guard_names=(),
                                           modes=result.modes)) is None  # no scene: no mass


def _run(scene, functions, samples: int):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the plausibility checks: not what these tests look at
        return apexseal.simulate(scene, revolutions=1, samples_per_revolution=samples, functions=functions.sx,
                                 flags="quick")


@pytest.mark.slow  # 6 s of a 2-core test process: in the second step, to keep the default suite under 10 min
def test_the_summary_says_when_its_samples_miss_the_contacts_work(default_scene, default_functions, capsys):
    """At the default 3600 samples per revolution the samples miss a large part of the groove contacts' work, and
    neither summary.json nor the console said so: ``energy_balance`` records the residual (not closing) and the
    console prints a note; at 36000 samples it closes (residual under 1 % of its terms) and the note is gone. The
    change of kinetic energy is exact, so the residual is the sampled work's. A sweep and ``apexseal compare`` read
    the same residual as the quantities ``energy.residual`` and ``energy.residual_fraction``."""
    from apexseal.cli_common import describe_result
    from apexseal.runtime.results.quantities import collect

    names = ("energy.residual", "energy.residual_fraction")

    low = _run(default_scene, default_functions, 3600)
    s = summarise(low)
    b = s["energy_balance"]
    assert not b["closes"] and b["residual_fraction"] > 0.2
    assert set(b["work_J_per_rev"]) >= {"housing", "i1", "c2", "i2", "c4", "spring", "pressure"}
    describe_result(low, s)
    notes = [line for line in capsys.readouterr().out.splitlines() if "energy balance" in line]
    assert len(notes) == 1 and f"{abs(b['residual_J_per_rev']):.3g} J per revolution" in notes[0]
    assert collect(low, names) == dict(zip(names, (b["residual_J_per_rev"], b["residual_fraction"]), strict=True))

    high = _run(default_scene, default_functions, 36000)
    t = summarise(high)
    assert t["energy_balance"]["closes"] and t["energy_balance"]["residual_fraction"] < 0.01
    assert abs(t["energy_balance"]["residual_J_per_rev"]) < 0.05 * abs(b["residual_J_per_rev"])
    describe_result(high, t)
    assert "energy balance" not in capsys.readouterr().out
    assert collect(high, names)["energy.residual_fraction"] == t["energy_balance"]["residual_fraction"] < 0.01


@pytest.mark.slow
def test_the_default_sampling_resolves_the_tips_work_and_not_the_groove_corners():
    """What docs/results.md states ("Energy balance and sampling"): over a settled revolution the tip's friction work
    and sliding work at 3600 samples per revolution are within 1 % of 36000's, each groove corner's is not (at least
    one off by more than 20 %), and the balance closes at 36000 only."""
    from apexseal.runtime.studies.calibration.energy import friction_work, settled

    runs = settled((3600, 36000))
    fric = {n: friction_work(r) for n, r in runs.items()}
    assert fric[3600]["housing"] == pytest.approx(fric[36000]["housing"], rel=0.01)
    assert fric[3600]["total"] == pytest.approx(fric[36000]["total"], rel=0.01)
    corners = [abs(fric[3600][c] / fric[36000][c] - 1) for c in ("i1", "c2", "i2", "c4")]
    assert max(corners) > 0.2
    assert not energy_balance(runs[3600])["closes"] and energy_balance(runs[36000])["closes"]
