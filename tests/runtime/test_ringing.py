"""How fast the seal rings on its contacts, and whether a run's output samples resolve it (runtime/solving/ringing.py;
docs/paper-findings.md, "The main peak and the output sampling")."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import apexseal
from apexseal.runtime.api import initial_state
from apexseal.runtime.solving.ringing import describe_sampling, mode_damping, mode_frequencies, ringing


@pytest.fixture(scope="module")
def rest(default_scene, default_functions):
    """The default scene's model, parameter vector, start angle and initial state."""
    f = default_functions.c
    return f, default_scene.parameter_vector(f.parameter_names), default_scene.operation.start_angle, \
        initial_state(default_scene, f)


def _run(scene, functions, samples: int):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the plausibility checks: not what these tests look at
        return apexseal.simulate(scene, revolutions=1, samples_per_revolution=samples, functions=functions.sx,
                                 flags="quick")


def test_a_contact_rings_at_its_analytic_frequency(default_scene, rest):
    """Where the answer is known in closed form the estimate gives it: the tip alone on the housing pushes through
    the centre of gravity (sqrt(kw/ms)); a back corner alone pushes across the groove at the arm ds2 from it, and
    turns the seal too: sqrt(kg (1/ms + ds2^2/Icg)), 1.9 times sqrt(kg/ms)."""
    p = default_scene.parameters
    w = mode_frequencies(*rest)
    assert w["p2_h_s0"] == pytest.approx(math.sqrt(p["kw"] / p["ms"]), rel=1e-6)
    assert w["n2_h0_s0"] == pytest.approx(math.sqrt(p["kg2"] * (1 / p["ms"] + p["ds2"] ** 2 / p["Icg"])), rel=1e-3)
    assert w["q2_h0_s0"] == pytest.approx(math.sqrt(p["kg4"] * (1 / p["ms"] + p["ds2"] ** 2 / p["Icg"])), rel=1e-3)


def test_a_contacts_damping_ratio_is_its_analytic_one_halved(default_scene, rest):
    """The explicit methods' stability check judged each contact alone, by c / (2 sqrt(k ms)) halved (the damping
    acts on approach only); it now takes each mode's ratio from the model (``mode_damping``). Where the answer is
    known it gives it: the tip alone, cw / (2 sqrt(kw ms)) / 2; a back corner alone, which turns the seal too and
    moves a mass 1 / (1/ms + ds2^2/Icg) at the corner, cr w / (2 kg) / 2, 1.9 times the tip's ratio at 1.9 times
    its frequency. Friction, which damps at rest too, is no part of it; a damper named undamped counts for none."""
    p = default_scene.parameters
    modes = {m.mode: m for m in mode_damping(*rest, ("cw", "cr", "cs"))}
    tip, corner = modes["p2_h_s0"], modes["n2_h0_s0"]
    assert tip.contacts == ("xs5",) and tip.rad_s == pytest.approx(math.sqrt(p["kw"] / p["ms"]), rel=1e-6)
    assert tip.zeta == pytest.approx(p["cw"] / (2 * math.sqrt(p["kw"] * p["ms"])) / 2, rel=1e-4)
    assert corner.zeta == pytest.approx(p["cr"] * corner.rad_s / (2 * p["kg2"]) / 2, rel=2e-3)
    assert corner.zeta > 1.8 * tip.zeta
    assert {m.mode: m.rad_s for m in modes.values()} == mode_frequencies(*rest)
    without = {m.mode: m for m in mode_damping(*rest, ("cw", "cr", "cs"), undamped=("cw",))}
    assert without["p2_h_s0"].zeta == 0 and without["n2_h0_s0"].zeta == corner.zeta


def test_the_fastest_ringing_is_that_of_the_jacobian_along_a_run(default_scene, default_functions, rest):
    """The sampling was judged by sqrt(kw/ms) = 2.4e5 rad/s, one contact through the centre of gravity, but two
    groove corners and the tip closed together (the modes the default run spends most of its time in) ring at
    twice that: along a run, the largest imaginary part of the eigenvalues of the model's Jacobian (the seal's six
    states, each sample's contacts) is the estimate, which friction and the seal's tilt, left out at rest, move by
    a few tenths of a percent; the single-contact estimate is far below it."""
    f, params, *_ = rest
    r = _run(default_scene, default_functions, 360)
    fastest = 0.0
    for i in range(r.n):
        X = r.state[:, i]
        closed = (np.asarray(f.guards(r.theta[i], X, params, np.zeros(2))).ravel() < 0).astype(float)
        J = np.asarray(f.rhs_jac(r.theta[i], X, closed, params, np.zeros(2), np.zeros(X.size))[1])[:6, :6]
        fastest = max(fastest, float(np.abs(np.linalg.eigvals(J).imag).max()))
    estimate = ringing(*rest)
    assert estimate.rad_s == pytest.approx(fastest, rel=0.01)
    p = default_scene.parameters
    assert estimate.rad_s > 2 * math.sqrt(p["kw"] / p["ms"])
    assert r.info["sampling"]["ringing_rad_s"] == estimate.rad_s


@pytest.mark.slow  # 7 s of a 2-core test process: in the second step, to keep the default suite under 10 min
def test_a_run_says_whether_its_samples_resolve_the_ringing(default_scene, default_functions, capsys):
    """At the default 3600 samples per revolution the Nyquist frequency (2.83e5 rad/s) lies below the contacts'
    ringing, and nothing said so (the docs claimed it lay above the "2.4e5 rad/s housing mode"): summary.json's
    ``sampling`` records it, and the console's summary says so with the setting that resolves it; at that setting
    the record says resolved and the console says nothing."""
    from apexseal.cli_common import describe_result
    from apexseal.runtime.results.summary import summarise

    low = _run(default_scene, default_functions, 3600)
    s = summarise(low)["sampling"]
    omega = default_scene.omega
    assert s["samples_per_revolution"] == 3600 and s["nyquist_rad_s"] == pytest.approx(3600 * omega / 2)
    assert not s["resolved"] and s["nyquist_rad_s"] < s["ringing_rad_s"]
    needed = s["samples_per_revolution_resolving"]
    assert needed % 360 == 0 and needed * omega / 2 > 1.2 * s["ringing_rad_s"]
    describe_result(low, summarise(low))
    notes = [line for line in capsys.readouterr().out.splitlines() if "note:" in line and " ring " in line]
    assert len(notes) == 1 and f"--set solver.samples_per_revolution={needed} resolves it" in notes[0]
    assert f"{s['ringing_rad_s']:.3g} rad/s" in notes[0] and f"{s['nyquist_rad_s']:.3g} rad/s" in notes[0]

    high = _run(default_scene, default_functions, needed)
    t = summarise(high)["sampling"]
    assert t["resolved"] and t["ringing_rad_s"] == s["ringing_rad_s"] and t["samples_per_revolution"] == needed
    describe_result(high, summarise(high))
    assert not [line for line in capsys.readouterr().out.splitlines() if "note:" in line and " ring " in line]


@pytest.mark.filterwarnings("ignore::apexseal.runtime.scenes.units.PlausibilityWarning")  # the slow rotor
def test_the_speed_check_follows_the_seals_fastest_ringing(default_scene, rest):
    """The preflight's speed check (at most 1e8 oscillations per rad of crank angle) took the stiffest contact alone,
    sqrt(kw/ms) = 2.4e5 rad/s, and let a rotor twice too slow for the seal's ringing on two groove corners and the
    tip (5.07e5 rad/s) through; it takes that ringing now, and names its mode."""
    from apexseal.runtime.solving.preflight import MAX_OSCILLATIONS_PER_RAD, speed_problem

    f, params, theta, X = rest
    ring = ringing(*rest)
    p = default_scene.parameters
    single = math.sqrt(p["kw"] / p["ms"])
    between = (single + ring.rad_s) / 2 / MAX_OSCILLATIONS_PER_RAD  # rad/s of the rotor: the old check let it run
    assert ring.rad_s > 2 * single
    slow = default_scene.with_overrides(**{"operation.rpm": f"{between * 30 / math.pi} rpm"})
    problem = speed_problem(f, slow.parameter_vector(f.parameter_names), theta, X)
    assert problem is not None and f"contact mode {ring.mode}" in problem
    enough = 1.01 * ring.rad_s / MAX_OSCILLATIONS_PER_RAD
    fast = default_scene.with_overrides(**{"operation.rpm": f"{enough * 30 / math.pi} rpm"})
    assert speed_problem(f, fast.parameter_vector(f.parameter_names), theta, X) is None


def test_the_note_never_advises_a_sampling_beyond_the_allowed_range():
    """At 1 rpm the note advised --set solver.samples_per_revolution=17703360, which the scene then refused
    (allowed: at most 100000): where no allowed sampling resolves the ringing the note says so instead."""
    from apexseal.runtime.solving.settings import LIMITS

    most = LIMITS["samples_per_revolution"][1].le
    record = {"ringing_rad_s": 7.7e5, "ringing_mode": "q3_h_s", "nyquist_rad_s": 377.0, "resolved": False,
              "samples_per_revolution": 3600, "samples_per_revolution_resolving": 17703360}
    line = describe_sampling(record)
    assert "--set" not in line and f"17703360 samples per revolution, above the {most} allowed" in line
    assert "--set solver.samples_per_revolution=7920 resolves it" in describe_sampling(
        record | {"samples_per_revolution_resolving": 7920})


@pytest.mark.parametrize("rad_s", [2.41e5, 5.07e5, 7.7e5])
def test_resolved_and_the_sampling_that_resolves_agree(rad_s):
    """summary.json's ``sampling`` said ``resolved`` by Nyquist's 2 samples per period while its
    ``samples_per_revolution_resolving`` asked for 2.4: at 3000 rpm and 5.07e5 rad/s, 3600 samples were "resolved"
    beside a resolving 3960. One criterion now: the advised sampling is resolved, a degree's sample fewer is not,
    and ``resolved`` holds exactly from SAMPLES_PER_PERIOD samples per period on."""
    from types import SimpleNamespace

    from apexseal.runtime.solving.ringing import SAMPLES_PER_PERIOD, Ringing, sampling

    omega = 3000 * math.pi / 30
    functions = SimpleNamespace(omega=lambda params: omega)
    ring = Ringing(rad_s, "q3_h_s")
    needed = sampling(functions, None, ring, 3600)["samples_per_revolution_resolving"]
    assert sampling(functions, None, ring, needed)["resolved"]
    assert not sampling(functions, None, ring, needed - 360)["resolved"]
    for n in range(36, needed + 1, 36):
        record = sampling(functions, None, ring, n)
        assert record["resolved"] == (n * omega / rad_s >= SAMPLES_PER_PERIOD)
        assert record["samples_per_period"] == pytest.approx(n * omega / rad_s)
        assert describe_sampling(record).count("samples per period") == 1
