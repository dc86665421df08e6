"""The preload study's Functions from Python (``apexseal.preload_functions``, docs/preload.md).

Before, the compiled Functions were reachable only through three internal modules, with CasADi's generic slot names
(x0, p, u, qf) whose entries only module docstrings explained. The docs' example is run here: one call of the
interval integrator over the small study's revolution gives simulate()'s samples, and its friction quadrature
differs from simulate()'s mean at the samples by the rectangle rule's error only.
"""

from __future__ import annotations

import numpy as np
import pytest

import apexseal
from apexseal.runtime.studies.preload.problem import PreloadStudyError

SAMPLES = 72


@pytest.fixture(scope="module")
def small(soft_scene):
    """The small study's scene (soft contacts without chamber pressure), its Functions at 72 and 720 samples per
    call (one revolution each, CasADi's own evaluation: nothing to compile), and simulate()'s first revolution."""
    scene = soft_scene.with_overrides(**{"effects.chamber_pressure": False})
    pf = apexseal.preload_functions(scene, samples=SAMPLES, min_force=10.0, compile_c=False)
    fine = apexseal.preload_functions(scene, samples=10 * SAMPLES, min_force=10.0, compile_c=False,
                                      functions=pf.setup.functions)
    with pytest.warns(UserWarning):  # the soft contacts' implausible penetration
        run = apexseal.simulate(scene, revolutions=1, method="erk", samples_per_revolution=SAMPLES)
    return scene, pf, fine, run


def one_revolution(pf, delta_s):
    """The docs' example: one call of the interval integrator from the scene's start."""
    theta0 = pf.setup.theta_start
    r = pf.interval(x0=pf.setup.start_state(delta_s), p=pf.p(delta_s, theta0), u=pf.u(theta0))
    return np.array(r["xf"]), np.array(r["qf"]), theta0


def pf_total_at_samples(pf, xf, theta0, delta_s):
    s = pf.setup
    edges = theta0 + s.dth * np.arange(pf.m + 1)
    P = np.repeat(s.pmap(delta_s)[:, None], pf.m, 1)
    Y = s.at_samples(s.functions.outputs, xf, edges[1:], P, s.pressures(edges))
    return Y[tuple(s.functions.output_names).index("Pf_total")]


def test_every_slot_is_named(small):
    _, pf, _, _ = small
    f, s = pf.interval, pf.setup
    assert f.size_in("x0") == (len(pf.x0_names), 1) and f.size_in("p") == (len(pf.p_names), 1)
    assert f.size_in("u") == (len(pf.u_names), SAMPLES) and f.size_out("qf") == (len(pf.qf_names), SAMPLES)
    assert pf.x0_names[:6] == ("x", "y", "phi", "xd", "yd", "phid")
    assert pf.x0_names[6] == f"closed_{s.layout.guard_names[0]}" and pf.x0_names[-1].startswith("events_")
    assert pf.p_names[:len(s.pmap.names)] == s.pmap.names
    assert pf.p_names[len(s.pmap.names):len(s.pmap.names) + 4] == ("theta0", "slope", "f_min", "f_max")
    assert pf.p_names[-1] == "window4_end" and pf.qf_names == ("friction_energy", "force_deficit")
    assert all(pf.p_names) and "qf 2x72: friction_energy, force_deficit" in pf.describe()
    p = pf.p(2e-3, 1.0, slope=0.5)
    assert p[pf.p_names.index("delta_s")] == 2e-3 and p[pf.p_names.index("theta0")] == 1.0
    assert p[pf.p_names.index("slope")] == 0.5 and p[pf.p_names.index("f_min")] == 10.0


def test_one_interval_gives_simulates_samples_and_its_friction_power_between_them(small):
    """The interval's samples are simulate()'s (the same model, integrator and rtol): the mean of Pf_total at them is
    simulate()'s friction_power to 1e-6. The quadrature integrates Pf_total between the samples too, so it differs
    from that mean (27.911 against 27.962 W here) by the right-endpoint rectangle rule's error, at most
    (2 pi / n) TV / (2 pi) = TV / n for Pf_total's total variation TV over the revolution; it does not depend on the
    samples (no chamber pressure here), while the mean at 10 x the samples moves towards it."""
    scene, pf, fine, run = small
    d = scene.parameters["delta_s"]
    xf, qf, theta0 = one_revolution(pf, d)
    # the same erk at the same rtol (1e-6), but the quadratures enter its error control: other steps, rtol-level
    scale = np.abs(run.state).max(axis=1, keepdims=True)
    assert np.all(np.abs(pf.physical(xf) - run.state[:, 1:]) <= 1e-4 * scale)
    at_samples = pf_total_at_samples(pf, xf, theta0, d)
    assert at_samples.mean() == pytest.approx(run.friction_power, rel=1e-6)
    quadrature = qf[0, -1] / (2 * np.pi)
    xf10, qf10, _ = one_revolution(fine, d)
    assert qf10[0, -1] / (2 * np.pi) == pytest.approx(quadrature, rel=1e-6)  # grid-independent
    fine_samples = pf_total_at_samples(fine, xf10, theta0, d)
    tv = np.abs(np.diff(np.r_[fine_samples[-1], fine_samples])).sum()  # the variation the finer samples see
    assert 0 < abs(run.friction_power - quadrature) <= tv / SAMPLES
    assert abs(fine_samples.mean() - quadrature) < abs(run.friction_power - quadrature) / 2


def test_hybrid_state_is_the_inverse_of_physical(small):
    _, pf, _, run = small
    z = pf.hybrid_state(run.state[:, 5], run.closed[:, 5])
    assert np.allclose(pf.physical(z[:, None])[:, 0], run.state[:, 5], rtol=1e-12)
    assert np.array_equal(z[pf.setup.layout.active], run.closed[:, 5].astype(float))


def test_a_bad_per_interval_names_the_option_and_range(small):
    scene, pf, _, _ = small
    with pytest.raises(PreloadStudyError, match=r"per_interval = 7: must be an integer in 1\.\.72 dividing"):
        apexseal.preload_functions(scene, samples=SAMPLES, min_force=10.0, per_interval=7, compile_c=False,
                                   functions=pf.setup.functions)


def test_a_preload_results_contact_powers_are_means_at_the_samples_and_its_total_a_quadrature(small):
    """PreloadResult.contact_friction_power (each contact's mean at the samples) and friction_power (the quadrature)
    are measured differently: on the small study's 2-knot schedule the housing's 23.876 W exceeded the total's
    23.857 W. The contacts sum to the mean of Pf_total at the samples, which is within TV / n of the quadrature (the
    docstring and docs/preload.md say so)."""
    from apexseal.runtime.studies.preload.result import PreloadResult, contact_powers
    from apexseal.runtime.studies.preload.schedule import SegmentGrid, simulate_schedule

    scene, pf, _, _ = small
    halves = apexseal.preload_functions(scene, samples=SAMPLES, min_force=10.0, per_interval=SAMPLES // 2,
                                        compile_c=False, functions=pf.setup.functions)  # a call per knot stretch
    s = halves.setup
    grid = SegmentGrid(s.samples, 1, 2, s.theta_start, s.dth)
    sim = simulate_schedule(s, halves.study, grid, np.array([0.0, 2.4e-3]), s.min_force, ())
    contacts = contact_powers(s, sim)
    xf = sim.z[:, 1:]
    P = s.pmap.p0[:, None] + s.pmap.dp[:, None] * sim.delta_s[None, :]
    Y = s.at_samples(s.functions.outputs, xf, sim.thetas, P, sim.pressures)
    at_samples = Y[tuple(s.functions.output_names).index("Pf_total")]
    assert sum(contacts.values()) == pytest.approx(at_samples.mean(), rel=1e-9)
    tv = np.abs(np.diff(np.r_[at_samples[-1], at_samples])).sum()
    assert abs(at_samples.mean() - sim.friction_power) <= tv / s.samples
    doc = PreloadResult.__doc__
    assert "mean of each contact's ``Pf_<contact>`` at the ``samples``" in doc and "quadrature of ``Pf_total``" in doc


def test_a_preload_result_without_an_optimum_has_no_simulation_and_a_short_repr():
    """A failed or interrupted study's result had no ``simulation`` attribute at all (AttributeError where a solved
    one had it), and its repr was every field (kilobytes, the start search's history included)."""
    from apexseal.runtime.studies.preload.result import PreloadResult

    failed = PreloadResult(False, "infeasible: no constant preload up to max_preload = 100 mm keeps the contact force "
                                  ">= 5 N between samples", 5.0, [], history=[(1e-3, -3.0, 1.0)] * 200)
    assert failed.simulation is None and failed.scene_simulation is None
    assert repr(failed) == ("PreloadResult(failed (infeasible: no constant preload up to max_preload = 100 mm …), "
                            "IPOPT not run, 0 iterations)")
    solved = PreloadResult(True, "solved", 5.0, [], knot_angles_deg=[0.0], knots=[1.7565e-3], delta_s=1.7565e-3,
                           friction_power=26.849, ipopt_status="Solved_To_Acceptable_Level", ipopt_iterations=11)
    solved.__dict__["simulation"] = "the re-simulation"  # as fill_result keeps it
    assert solved.simulation == "the re-simulation" and "simulation" not in solved.to_dict()
    assert repr(solved) == ("PreloadResult(solved, constant 1.7565 mm, friction power 26.849 W, IPOPT "
                            "Solved_To_Acceptable_Level, 11 iterations)")
    assert solved == PreloadResult(**solved.to_dict())  # the fields compared, not the simulations
    for method in (PreloadResult.describe, PreloadResult.to_dict, PreloadResult.schedule.fget):
        assert method.__doc__


if __name__ == "__main__":  # the numbers of docs/preload.md, "The study's Functions from Python"
    import warnings

    from apexseal.runtime.scenes.scene import embedded_scene_path

    warnings.simplefilter("ignore")
    scene = apexseal.load_scene(embedded_scene_path("soft-contacts.toml"),
                                overrides={"effects.chamber_pressure": False})
    for n in (SAMPLES, 10 * SAMPLES):
        pf = apexseal.preload_functions(scene, samples=n, min_force=10.0, compile_c=False)
        d = scene.parameters["delta_s"]
        xf, qf, theta0 = one_revolution(pf, d)
        run = apexseal.simulate(scene, revolutions=1, method="erk", samples_per_revolution=n)
        at = pf_total_at_samples(pf, xf, theta0, d)
        tv = np.abs(np.diff(np.r_[at[-1], at])).sum()
        print(f"{n} samples: quadrature {qf[0, -1] / (2 * np.pi):.4f} W, mean at the interval's samples {at.mean():.4f} "
              f"W, simulate().friction_power {run.friction_power:.4f} W, total variation at the samples / n "
              f"{tv / n:.3f} W")

    from apexseal.runtime.studies.preload.result import contact_powers
    from apexseal.runtime.studies.preload.schedule import SegmentGrid, simulate_schedule

    halves = apexseal.preload_functions(scene, samples=SAMPLES, min_force=10.0, per_interval=SAMPLES // 2,
                                        compile_c=False)
    s = halves.setup
    sim = simulate_schedule(s, halves.study, SegmentGrid(s.samples, 1, 2, s.theta_start, s.dth),
                            np.array([0.0, 2.4e-3]), s.min_force, ())
    contacts = contact_powers(s, sim)
    print(f"2 knots (0, 2.4 mm), {SAMPLES} samples: friction_power (quadrature) {sim.friction_power:.3f} W; "
          f"contact_friction_power (at the samples) {', '.join(f'{k} {v:.3f}' for k, v in contacts.items())} W, "
          f"sum {sum(contacts.values()):.3f} W")


def test_it_takes_the_study_s_quantities_as_optimise_preload_does():
    """preload_functions refused min_force="5 N", which optimise_preload takes; a text that is no force names the
    option and its range (before anything is built)."""
    with pytest.raises(PreloadStudyError, match=r"min_force = '5 mm': wrong unit.*allowed: > 0 and <= 100000 N"):
        apexseal.preload_functions("default", min_force="5 mm")


def test_a_study_coarser_than_the_pressure_table_warns_that_simulate_would_integrate_other_pressures(soft_scene):
    """The study took the chamber pressures linear over each of its output intervals, while a run cuts each into
    ``pressure_substeps`` parts until it sees every row of the pressure table (runtime/solving/run.py). With
    ``--samples 360`` on a scene whose table has 720 rows a revolution the study therefore optimised another
    pressure input than ``apexseal simulate`` of its report's scene.toml integrates, and said nothing: on a user's
    scene (2400 rpm, carbon seal) the optimum's friction power at the samples was 61.2 W in the study and 62.4 W in
    the simulation of its scene.toml, the transients after the chamber switches different from the first sample.
    Now the setup warns, naming ``samples``, its value and the samples that keep the pressures the same; at the
    table's rows, or without chamber pressure, it is silent."""
    import warnings

    rows = soft_scene.pressure.rows_per_revolution()
    assert rows == 720  # the embedded expander table
    with pytest.warns(UserWarning, match=rf"samples = 360: coarser than the scene's pressure table \({rows} rows"
                                         rf".*cuts each interval into 2.*samples >= {rows}"):
        apexseal.preload_functions(soft_scene, samples=360, compile_c=False)
    without = soft_scene.with_overrides(**{"effects.chamber_pressure": False})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        apexseal.preload_functions(soft_scene, samples=rows, compile_c=False)
        apexseal.preload_functions(without, samples=360, compile_c=False)
