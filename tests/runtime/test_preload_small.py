"""A small version of the IPOPT preload study, in the default suite (issue 15: under a minute, cold build
included, on 2 cores).

The scene is the soft-contacts scene without chamber pressure: no gas-load impacts at the chamber switches, so
the tip force varies smoothly with the crank angle (the inertial load of the seal, 1.5 N at its lowest with no
preload) and IPOPT converges in about ten iterations on a coarse grid (72 samples, 4 shooting nodes). The
questions are those of the full study (tests/runtime/test_preload.py, slow): the constant optimum agrees with the
derivative-free bisection over full simulations, the schedule costs no more friction than the constant (the
constant is a feasible schedule), every re-simulated optimum satisfies its constraints between samples; the
groove-force excess quadrature is zero exactly when a bound holds, and its Jacobian row is its derivative.

The module grew to five minutes of one test process with the questions of interruption (a signal during the
bisection, the re-simulation, the writing of a report; a rerun stopped beside a completed report) and of the API's
and the command's agreement; those run again a study of their own each, and are marked slow (the second step of
the suite), so the default suite keeps its ten-minute budget on two cores.
"""

from __future__ import annotations

import re

import casadi as ca
import numpy as np
import pytest

from apexseal.runtime.studies.preload.bisect import bisect_preload
from apexseal.runtime.studies.preload.nlp import SOLVED, ShootingNlp
from apexseal.runtime.studies.preload.problem import MM, PreloadSetup, PreloadStudyError
from apexseal.runtime.studies.preload.result import DEFICIT_TOL
from apexseal.runtime.studies.preload.schedule import Schedule, SegmentGrid, simulate_schedule
from apexseal.runtime.studies.preload.shooting import study_functions
from apexseal.runtime.studies.preload.study import optimise_preload

SAMPLES, NODES, MIN_FORCE = 72, 4, 10.0
#: every study here takes the compiled units with the groove-force quadrature (one cold build, ~20 s on 2 cores); a
#: bound this high is never reached (the groove forces of this scene peak near 10 N), so its excess is exactly 0
NO_BOUND = 1e4
#: groove-force bounds at the constant optimum (1.76 mm): the force peaks at 9.7 N at the samples but near 11 N
#: between them (the excess quadrature is 0 at 11 N, 1.2e-3 N^2 rad at 10.5 N, measured), so 12 N is not reached
#: and 10.5 N cannot be met by any preload that keeps the tip force (the excess grows with the preload)
GROOVE_MAX, GROOVE_TIGHT = 12.0, 10.5


@pytest.fixture(scope="module")
def light(soft_scene):
    from apexseal.runtime.api import model_functions

    scene = soft_scene.with_overrides(**{"effects.chamber_pressure": False})
    return scene, model_functions(scene)


def _setup(light, groove=NO_BOUND):
    scene, functions = light
    return PreloadSetup(scene, functions, MIN_FORCE, (), SAMPLES, max_groove_force=groove)


def run_studies(light):
    """The constant optimum, the bisection, the 2-knot schedule, and the constant under the groove-force bound it
    does not reach."""
    scene = light[0]
    free = _setup(light)
    c = optimise_preload(scene, min_force=MIN_FORCE, nodes=NODES, setup=free)
    b = bisect_preload(scene, min_force=MIN_FORCE, nodes=NODES, setup=free, tol=0.01 * MM, scan_step=0.5 * MM)
    s = optimise_preload(scene, min_force=MIN_FORCE, nodes=NODES, knots=2, start=c, setup=free)
    cg = optimise_preload(scene, min_force=MIN_FORCE, nodes=NODES, setup=_setup(light, GROOVE_MAX))
    return c, b, s, cg


def tight_study(light):
    """The constant under the groove-force bound no preload can meet (its search of a feasible start says so)."""
    return optimise_preload(light[0], min_force=MIN_FORCE, nodes=NODES, setup=_setup(light, GROOVE_TIGHT))


@pytest.fixture(scope="module")
def studies(light):
    return run_studies(light)


def test_constant_optimum_agrees_with_the_bisection(studies):
    c, b = studies[0], studies[1]
    assert c.ok and c.ipopt_status in SOLVED, c.message
    assert c.ipopt_iterations <= 40
    # within the bisection's bracket plus the NLP's tolerance (its deficit may exceed the bound by 5 %)
    assert abs(c.delta_s - b.delta_s) <= (b.delta_s - b.lower) + 0.01 * b.delta_s, (c.delta_s, b.lower, b.delta_s)
    assert c.deficit <= 1.05 * DEFICIT_TOL and c.periodic_change < 1e-5
    assert abs(c.delta_s - c.start_delta_s) > 0.05 * c.delta_s  # the optimum is not the start
    assert c.min_measure >= MIN_FORCE - 0.5  # at the samples too


def test_schedule_costs_less_friction_and_resimulates_feasibly(studies):
    c, s = studies[0], studies[2]
    assert s.ok, s.message
    assert s.friction_power < c.friction_power - 0.1  # the schedule spends the preload where it is needed
    assert s.deficit <= 1.05 * DEFICIT_TOL and s.periodic_change < 1e-5
    assert len(s.knots) == 2 and min(s.knots) >= -1e-9


def test_an_inactive_groove_force_bound_is_met_and_changes_nothing(studies):
    c, cg = studies[0], studies[3]
    assert c.groove_excess == 0.0 and c.groove_peak < GROOVE_MAX
    assert cg.ok, cg.message
    assert cg.groove_excess <= 1.05 * DEFICIT_TOL and cg.groove_peak <= GROOVE_MAX
    assert cg.delta_s == pytest.approx(c.delta_s, rel=0.01)
    assert "groove forces: excess" in cg.describe()


def test_a_groove_force_bound_no_preload_can_meet_is_reported_infeasible(light):
    """At 10.5 N the groove forces between samples exceed the bound at every preload that keeps the tip force: the
    study says so (it does not return an optimum that breaks the bound), from its search of a feasible start,
    without IPOPT: the search took the first preload that kept the tip force, groove forces unchecked, and IPOPT
    then took 29 iterations to find the bound infeasible."""
    tight = tight_study(light)
    assert not tight.ok and tight.ipopt_iterations == 0 and tight.start_delta_s is None, tight.message
    found = re.match(r"infeasible: at the least constant preload that keeps the contact force >= 10 N, ([\d.]+) mm "
                     r"\(to 1 %\), the seal-groove contact forces exceed max_groove_force = 10.5 N: excess ",
                     tight.message)
    assert found, tight.message
    # the least preload that keeps the force is the constant optimum without the bound (1.7565 mm), to 1 %
    assert float(found.group(1)) == pytest.approx(1.7565, rel=0.011)
    assert "Raise max_groove_force (--max-groove-force)" in tight.message
    # preloads that keep the tip force were tried (the bound, not the force, is what no preload meets)
    assert any(deficit <= DEFICIT_TOL for _, _, deficit in tight.history)


def test_a_groove_force_bound_met_only_below_the_scenes_preload_starts_from_the_least_preload(light, studies):
    """At 10.8 N the scene's preload (2 mm, the search's first) keeps the tip force but not the groove bound; less
    preload meets both: the search bisects down to the least preload that keeps the force (to 1 %), a feasible
    start, and IPOPT finds the unbounded study's optimum from there (it must not be reported infeasible)."""
    c = studies[0]
    bounded = optimise_preload(light[0], min_force=MIN_FORCE, nodes=NODES, setup=_setup(light, 10.8))
    assert bounded.ok, bounded.message
    assert bounded.start_delta_s == pytest.approx(c.delta_s, rel=0.015) and bounded.start_delta_s < 2 * MM
    assert bounded.delta_s == pytest.approx(c.delta_s, rel=1e-3) and bounded.groove_excess <= 1.05 * DEFICIT_TOL


def test_the_design_over_delta_s_and_ks_is_the_curve_of_one_spring_force(studies, light):
    """The same spring force ks delta_s at a quarter to four times the scene's ks gives the same friction power and
    force deficit (to within the ks s and spring-damping terms): the joint optimum is the curve ks delta_s = F0*."""
    from apexseal.runtime.studies.preload.stiffness import stiffness_valley

    c = studies[0]
    points = stiffness_valley(_setup(light), c, nodes=NODES, factors=(0.25, 1.0, 4.0))
    assert [p.ks for p in points] == pytest.approx([1250.0, 5000.0, 20000.0])
    assert all(p.ks * p.delta_s == pytest.approx(c.spring_force, rel=1e-3) for p in points)
    assert points[1].friction_power == pytest.approx(c.friction_power, rel=1e-6)  # the optimum itself
    for p in points:
        assert p.friction_power == pytest.approx(c.friction_power, rel=1e-3)
        assert p.deficit == pytest.approx(c.deficit, rel=0.05)
    with pytest.raises(PreloadStudyError, match="constant-preload"):
        stiffness_valley(_setup(light), studies[2])


def _light_cli(out, *args) -> list[str]:
    """optimise-preload on the small study's scene (the soft-contacts scene, --set chamber pressure off), with the
    units of the studies above (the groove quadrature: a bound never reached)."""
    from apexseal.runtime.scenes.scene import embedded_scene_path

    return ["optimise-preload", str(embedded_scene_path("soft-contacts.toml")), "--set",
            "effects.chamber_pressure=false", "--min-force", "10 N", "--samples", str(SAMPLES), "--max-groove-force",
            f"{NO_BOUND} N", "--out", str(out), *args]


def test_a_study_run_from_python_writes_the_command_s_report(studies, light, tmp_path):
    """From Python the study's report could not be written (only the command wrote one): save_preload_report
    writes the command's files from the results in memory, with the scene the study ran; a failed result beside a
    completed report is kept aside, and what is not a study's result of the right kind is refused by name. Its
    preload.json recorded `"overrides": {}` for a scene loaded with overrides (scene.toml had them), and scene.toml
    the scene's 3600 samples per revolution where the study ran 72 (`apexseal simulate scene.toml` differed)."""
    import dataclasses
    import json

    import apexseal
    from apexseal.runtime.results.folder import KeptAsideWarning
    from apexseal.runtime.scenes.scene import load_scene

    c, s = studies[0], studies[2]
    out = tmp_path / "report"
    assert apexseal.save_preload_report(out, c, s) == out
    assert sorted(p.name for p in out.iterdir()) == ["preload.json", "preload.md", "preload.png", "pressure.csv",
                                                     "scene.toml", "schedule.toml"]  # the scene's pressure table too
    data = json.loads((out / "preload.json").read_text())
    as_json = lambda r: json.loads(json.dumps(r.to_dict(), default=str))  # noqa: E731 (tuples as lists)
    assert data["status"] == "completed" and data["constant"] == as_json(c) and data["schedule"] == as_json(s)
    assert data["saved_friction_power_W"] == c.friction_power - s.friction_power
    assert data["options"]["schedule_knots"] == 2 and data["options"]["min_force_N"] == MIN_FORCE
    assert data["overrides"] == {"effects.chamber_pressure": False} == light[0].overrides
    written = load_scene(out / "scene.toml")
    assert written.solver.samples_per_revolution == SAMPLES == c.samples != light[0].solver.samples_per_revolution
    assert written.content_hash() == light[0].with_overrides(**{"solver.samples_per_revolution": SAMPLES}).content_hash()
    assert f"the samples the study ran (the scene's {light[0].solver.samples_per_revolution})" in \
        (out / "scene.toml").read_text()
    # preload.md says how to simulate the constant optimum (scene.toml keeps the scene's preload) and the schedule
    # (schedule.toml): the --set value it gives is the optimum to 6 digits
    md = (out / "preload.md").read_text()
    given = re.search(r'`apexseal simulate scene.toml --set spring.delta_s="([^"]+)" -n 3 -o ../constant-run`',
                      md).group(1)
    optimum = load_scene(out / "scene.toml", overrides={"spring.delta_s": given}).spring.delta_s
    assert optimum == pytest.approx(c.delta_s, rel=1e-5) and written.spring.delta_s == c.scene_delta_s != optimum
    assert "`apexseal simulate schedule.toml -o ../schedule-run`" in md and data["schedule_file"] == "schedule.toml"
    assert f"for its 3 revolutions: the line \"last revolution\" of its summary is the study's re-simulated " \
           f"revolution, {s.friction_power:.3f} W here" in md
    _simulates_the_schedule(out / "schedule.toml", s, written)
    failed = dataclasses.replace(c, ok=False, message="interrupted by the user")
    failed.__dict__["scene"] = c.scene
    with pytest.warns(KeptAsideWarning):
        aside = apexseal.save_preload_report(out, failed)
    assert aside != out and json.loads((aside / "preload.json").read_text())["status"] == "failed"
    assert json.loads((out / "preload.json").read_text())["run_id"] == data["run_id"]  # the completed one stays
    with pytest.raises(PreloadStudyError, match="^constant: a result of 2 knots; the constant optimum has one"):
        apexseal.save_preload_report(tmp_path / "x", s)
    with pytest.raises(PreloadStudyError, match="^schedule: expected the PreloadResult .* not dict"):
        apexseal.save_preload_report(tmp_path / "x", c, s.to_dict())
    with pytest.raises(PreloadStudyError, match="^constant: this result holds no scene"):
        apexseal.save_preload_report(tmp_path / "x", dataclasses.replace(c))
    assert not (tmp_path / "x").exists()


def test_a_schedule_of_another_scene_is_refused_naming_the_keys_that_differ(studies, tmp_path):
    """save_preload_report refused a schedule studied on another scene by content hashes alone (a schedule started
    from PreloadResult.load, whose scene is the report's scene.toml, with the study's samples): it names the keys
    that differ and the call that studies the loaded optimum's scene."""
    import dataclasses

    import apexseal

    c, s = studies[0], studies[2]
    other = dataclasses.replace(s)
    other.__dict__["scene"] = c.scene.with_overrides(**{"solver.samples_per_revolution": 360})
    with pytest.raises(PreloadStudyError, match=r"schedule: a study of another scene .*: "
                                                r"solver.samples_per_revolution = 360 against 3600; .*"
                                                r"optimise_preload\(start.scene, ..., start=start\)"):
        apexseal.save_preload_report(tmp_path / "x", c, other)
    assert not (tmp_path / "x").exists()


def _simulates_the_schedule(path, s, written) -> None:
    """schedule.toml is scene.toml with the schedule's knots as its [spring.schedule], and `apexseal simulate` of
    it from the study's first node over the study's revolutions ends in the study's re-simulated revolution of the
    schedule: within 2e-3 of each state's range at the scene's rtol 1e-6 (the study's DAE carries its quadratures in
    the error control, and tests/runtime/test_schedule.py shows the two converge as the tolerance shrinks), where a
    schedule 5 degrees late moves the states by a quarter of their range (``python tests/runtime/test_schedule.py``
    prints it for its 2-knot schedule)."""
    import warnings

    import apexseal
    from apexseal.generated.layout import HybridLayout
    from apexseal.generated.scaling import to_physical
    from apexseal.runtime.scenes.scene import load_scene

    scene = load_scene(path)
    angles, values = zip(*sorted(zip(np.radians(np.mod(s.knot_angles_deg, 360.0)), s.knots, strict=True)), strict=True)
    np.testing.assert_allclose(scene.schedule.angles, angles, atol=1e-12)
    np.testing.assert_allclose(scene.schedule.values["delta_s"], values, rtol=1e-12)
    assert scene.with_overrides(**{"spring.schedule": None, "spring.delta_s": written.spring.delta_s,
                                   "operation.start_angle": f"{written.operation.start_angle!r} rad",
                                   "operation.revolutions": written.operation.revolutions}) == written
    # the study re-simulates from the scene's initial state at its first node (the first knot, 60 deg here), not at
    # the scene's start angle, over its revolutions: schedule.toml starts there and runs them (it ran one revolution
    # from the scene's start, whose start-up from rest hid the schedule's saving)
    sim, first = s.simulation, np.radians(s.knot_angles_deg[0])
    n = sim.thetas.size
    assert scene.operation.start_angle == pytest.approx(first, abs=1e-12) != written.operation.start_angle
    assert scene.operation.revolutions == s.revolutions == 3
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the soft contacts' penetration warnings
        run = apexseal.simulate(scene, interpreted=True)  # as `apexseal simulate schedule.toml` runs it
    assert run.status == "completed" and run.n == s.revolutions * n + 1
    # the same crank angles, within whole turns (the study counts its first node from the scene's start)
    turns = (sim.thetas - run.theta[-n:] - first) / (2 * np.pi)
    np.testing.assert_allclose(turns, np.round(turns[0]), atol=1e-9)
    np.testing.assert_allclose(run.outputs["delta_s"][-n:], sim.delta_s, rtol=1e-9, atol=1e-15)
    lay = HybridLayout(tuple(run.state_names), tuple(run.guard_names))
    X_study = to_physical(sim.z[lay.x][:, 1:], scene.omega, lay.state_names)
    gap = max(np.abs(run.state[i, -n:] - X_study[i]).max() / np.ptp(X_study[i]) for i in range(X_study.shape[0]))
    assert gap < 2e-3, gap


def _report(folder) -> tuple[dict, list, dict]:
    """A preload report's JSON and Markdown (its lines, not the blank ones), but for what names how it was asked (the
    command: the scene's path and its --set keys; save_preload_report: the scene's name) and its run; and its
    options."""
    import json

    data = json.loads((folder / "preload.json").read_text())
    for key in ("run_id", "scene", "overrides"):
        data.pop(key)
    md = [line for line in (folder / "preload.md").read_text().splitlines()
          if line and not line.startswith(("# Preload study of ", "Scene keys replaced (--set): "))]
    return data, md, data.pop("options")


@pytest.mark.slow
def test_the_command_and_save_preload_report_report_the_same_results_alike(studies, light, tmp_path, monkeypatch):
    """The command decided its report's status and top line by one rule, save_preload_report by another: for a
    schedule IPOPT did not solve the command's report said "failed" without saying why, and for a constant-only study
    the function wrote "schedule": null where the command wrote none; a study interrupted in its schedule from Python
    was reported "failed" ("the schedule failed: interrupted by ..."), by the command "interrupted". Now one rule
    (report.report_status) decides both, and the same results give the same report: constant only, a failed
    schedule, an interrupted one (the command's stages return the small study's results here, without IPOPT).

    The options both record (report.study_options) are the same too: the command recorded "samples": null for the
    scene's own samples per revolution, where the function recorded the number the study ran, and "schedule_knots":
    null for a schedule that found no design (its result now keeps the knots' angles from its start); and the saving the
    command prints is the one its report records (report.saved_friction_power, once computed in three places)."""
    import dataclasses
    import json
    import os
    import signal

    from click.testing import CliRunner

    import apexseal
    import apexseal.signals
    from apexseal.cli import main
    from apexseal.runtime.studies.preload import study

    c, s = studies[0], studies[2]
    failed = dataclasses.replace(s, ok=False, message="IPOPT returned Restoration_Failed after 7 iterations.")
    failed.__dict__["scene"] = s.scene
    solve = ShootingNlp.solve

    def ctrl_c(self, *args, **kwargs):  # Ctrl-C in the schedule's IPOPT, from Python: the result so far, returned
        os.kill(os.getpid(), signal.SIGINT)
        return solve(self, *args, **kwargs)

    with monkeypatch.context() as m:
        m.setattr(ShootingNlp, "solve", ctrl_c)
        m.setattr(apexseal.signals, "interactive", lambda: True)
        with pytest.warns(apexseal.RunInterruptedWarning):
            stopped = optimise_preload(light[0], min_force=MIN_FORCE, nodes=NODES, knots=2, start=c,
                                       setup=_setup(light))
    assert stopped.interrupted_by == "the user (Ctrl-C, SIGINT)" and not stopped.ok
    assert stopped.knots is None and len(stopped.knot_angles_deg) == 2  # nothing solved; the knots asked

    def schedule_interrupted():  # under the command's own signal handling the stage is abandoned, and the result it
        try:  # held goes with the interruption (study._kept_on_interrupt)
            os.kill(os.getpid(), signal.SIGINT)
            raise AssertionError("not reached: the command's handler raises")
        except KeyboardInterrupt as err:
            err.preload_result = stopped
            raise

    cases = [("constant", (), None, 0, "completed", ""), ("schedule", ("--schedule", "2"), s, 0, "completed", ""),
             ("failed", ("--schedule", "2"), failed, 2, "failed",
              "the schedule failed: IPOPT returned Restoration_Failed after 7 iterations"),
             ("interrupted", ("--schedule", "2"), stopped, 130, "interrupted",
              "interrupted by the user (Ctrl-C, SIGINT) during the schedule")]
    for name, args, schedule, code, status, why in cases:
        ran = schedule_interrupted if name == "interrupted" else lambda schedule=schedule: schedule
        monkeypatch.setattr(study, "optimise_preload", lambda scene, knots=1, ran=ran, **kw: c if knots == 1 else ran())
        cli = _light_cli(tmp_path / f"{name}-command", *args, "--no-check", "--quiet")
        if name == "constant":  # the scene's own samples per revolution: the same study, no --samples given
            at = cli.index("--samples")
            cli[at:at + 2] = ["--set", f"solver.samples_per_revolution={SAMPLES}"]
        r = CliRunner().invoke(main, cli)
        assert r.exit_code == code, r.output
        *command, command_options = _report(tmp_path / f"{name}-command")
        *saved, saved_options = _report(apexseal.save_preload_report(tmp_path / f"{name}-python", c, schedule))
        shared = set(command_options) & set(saved_options)
        assert len(shared) == 7 and {k: command_options[k] for k in shared} == {k: saved_options[k] for k in shared}
        if name == "schedule":
            assert f"schedule saves {command[0]['saved_friction_power_W']:.3f} W" in r.output
        assert command[0]["status"] == saved[0]["status"] == status, name
        assert command[0].get("stopped", "") == saved[0].get("stopped", "") == why, name
        if name == "interrupted":  # the stage's result so far, in both (the command dropped it)
            assert command[0]["schedule"] == json.loads(json.dumps(stopped.to_dict(), default=str))
        assert command == saved, name


@pytest.mark.slow
def test_cli_writes_the_report_with_the_groove_bound_and_the_stiffness_valley(light, tmp_path, caplog):
    """The report records what ran: the --set keys in preload.json and preload.md, and the scene itself (every value
    explicit) in scene.toml, which loads as the scene the study ran; the stiffness valley reports each simulation
    (it ran silently)."""
    import json
    import logging

    from click.testing import CliRunner

    from apexseal.cli import main
    from apexseal.runtime.scenes.scene import load_scene

    out = tmp_path / "out"
    args = _light_cli(out, "--vary-stiffness", "--no-check", "--quiet")
    args[args.index(f"{NO_BOUND} N")] = f"{GROOVE_MAX} N"
    with caplog.at_level(logging.INFO, logger="apexseal"):
        r = CliRunner().invoke(main, args)
    assert r.exit_code == 0, r.output
    data = json.loads((out / "preload.json").read_text())
    assert data["constant"]["max_groove_force"] == GROOVE_MAX and data["constant"]["groove_excess"] == 0.0
    assert len(data["stiffness_valley"]) == 5 and "the spring's force at rest (Eq. 39)" in r.output
    md = (out / "preload.md").read_text()
    assert "the same spring force at other stiffnesses" in md
    assert data["status"] == "completed" and data["overrides"] == {"effects.chamber_pressure": False}
    assert data["options"]["samples"] == SAMPLES and data["scene_file"] == "scene.toml"
    assert "Scene keys replaced (--set): effects.chamber_pressure=false." in md
    ran = load_scene(out / "scene.toml")
    assert not ran.effects.chamber_pressure and ran.solver.samples_per_revolution == SAMPLES  # --samples: the grid
    assert ran.content_hash() == light[0].with_overrides(**{"solver.samples_per_revolution": SAMPLES}).content_hash()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # nothing left beside it
    valley = [m for m in caplog.messages if "stiffness valley: ks = " in m]
    assert len(valley) == 5 and "(0 of 5 done" in valley[0] and "(4 x the scene's)" in valley[-1], caplog.messages


@pytest.mark.slow
def test_a_constant_optimum_ipopt_does_not_reach_fails_the_study_and_the_bisection_answers(light, tmp_path):
    """IPOPT stopped short of the constant optimum (--max-iter 1): the report said "completed" though the command
    ended with exit code 2, replaced the completed report at <out>, and the bisection, which needs only the feasible
    start, did not run. Now the report is "failed", says why at its top, is kept beside the completed one, and
    holds the bisection's bracket, which brackets the completed study's optimum."""
    import json

    from click.testing import CliRunner

    from apexseal.cli import main

    out = tmp_path / "o"
    r = CliRunner().invoke(main, _light_cli(out, "--no-check", "--quiet"))
    assert r.exit_code == 0, r.output
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    solved = json.loads(before["preload.json"])["constant"]
    r = CliRunner().invoke(main, _light_cli(out, "--max-iter", "1", "--quiet"))
    assert r.exit_code == 2, r.output
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before  # the completed report, untouched
    (beside,) = [p for p in tmp_path.iterdir() if p.name != "o"]
    data = json.loads((beside / "preload.json").read_text())
    assert data["status"] == "failed" and data["options"]["max_iter"] == 1 and not data["constant"]["ok"]
    assert data["stopped"].startswith("the constant optimum failed: IPOPT returned Maximum_Iterations_Exceeded after "
                                      "1 iterations"), data["stopped"]
    assert "Raise max_iter (--max-iter)" in data["stopped"]
    assert (beside / "preload.md").read_text().startswith(f"**{data['stopped']}.**")
    b = data["bisection"]
    assert b["lower"] < solved["delta_s"] <= b["delta_s"] * (1 + 0.01), (b["lower"], solved["delta_s"], b["delta_s"])
    assert "this is the study's answer for a constant preload" in r.output


def _interrupted(out, when, signum, *args):
    """The small study as a subprocess, sent ``signum`` once a line of its stderr satisfies ``when``; its exit code
    and stderr."""
    import subprocess
    import threading

    from apexseal.cli import command

    proc = subprocess.Popen(command(*_light_cli(out, *args)), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True)
    lines, sent = [], threading.Event()

    def read():
        for line in proc.stderr:
            lines.append(line)
            if not sent.is_set() and when(line):
                sent.set()
                proc.send_signal(signum)

    reader = threading.Thread(target=read)
    reader.start()
    code = proc.wait(timeout=600)
    reader.join()
    assert sent.is_set(), "".join(lines)
    return code, "".join(lines)


@pytest.mark.slow
def test_an_interrupted_rerun_keeps_the_earlier_report_and_its_own_beside_it(light, tmp_path):
    """A study rerun into the folder of a complete report and stopped by Ctrl-C in the schedule's IPOPT: the earlier
    report stays as it was (it was overwritten file by file: the checkpoint of the new study, then its interrupted
    report), the new one, holding its constant optimum, is kept beside it in <out>.partial-<run id>; the IPOPT stage
    the signal ended is logged as abandoned (it said "done")."""
    import json
    import signal

    from click.testing import CliRunner

    from apexseal.cli import main

    out = tmp_path / "o"
    r = CliRunner().invoke(main, _light_cli(out, "--no-check", "--quiet"))
    assert r.exit_code == 0, r.output
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    # with the chamber pressure off the scene's table is not read, but its scene.toml keeps it beside (pressure.csv)
    assert sorted(before) == ["preload.json", "preload.md", "preload.png", "pressure.csv", "scene.toml"]
    earlier = json.loads(before["preload.json"])
    ipopt = "IPOPT (round 1: 2 knots"
    seen = {"schedule": False}

    def schedule_iterating(line):  # the schedule's IPOPT under way: its first iteration after the start
        seen["schedule"] = seen["schedule"] or line.startswith(f"apexseal: {ipopt}")
        return seen["schedule"] and "IPOPT iteration 1:" in line

    code, err = _interrupted(out, schedule_iterating, signal.SIGINT, "--schedule", "2", "--no-check")
    assert code == 130, err
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before  # the earlier report, untouched
    beside = [p for p in tmp_path.iterdir() if p.name != "o"]
    assert [p.name for p in beside] == [f"o.partial-{json.loads((beside[0] / 'preload.json').read_text())['run_id'][:12]}"]
    data = json.loads((beside[0] / "preload.json").read_text())
    assert data["status"] == "interrupted" and data["run_id"] != earlier["run_id"]
    assert data["stopped"] == "interrupted by the user (Ctrl-C, SIGINT) during the schedule"
    assert data["constant"]["ok"] and data["schedule"]["best_feasible"] is not None  # the schedule's so far, too
    assert sorted(p.name for p in beside[0].iterdir()) == sorted(before)
    assert f"so the completed report at {out} was kept; this study's report is in {beside[0]}/" in err
    stage = [line for line in err.splitlines() if line.startswith(f"apexseal: {ipopt}")]
    assert len(stage) == 2 and "abandoned after" in stage[1] and "done in" not in stage[1], err


def _after_a_round_of_probes(line: str) -> bool:
    """A round of the bisection under way after the check of the feasible start (1 probe) and the first round of the
    scan down from it (8), both simulated and checkpointed."""
    import re

    found = re.search(r"bisection: .*\((\d+) so far, ", line)
    return found is not None and int(found.group(1)) >= 9


def _check_probes_so_far(b: dict) -> None:
    """A bisection report that did not end holds each probe's verdict and the bracket they establish."""
    assert b["complete"] is False and len(b["probes"]) >= 9 and b["simulations"] == len(b["probes"]), b
    for p in b["probes"]:
        assert p["passed"] == (p["deficit"] <= DEFICIT_TOL and p["groove_excess"] <= DEFICIT_TOL), p
        assert p["friction_power"] > 0 and np.isfinite(p["min_measure"]), p
    passed = [p["delta_s"] for p in b["probes"] if p["passed"]]
    failed = [p["delta_s"] for p in b["probes"] if not p["passed"]]
    # the scan down from the feasible start: the smallest preload of the passing run, the failing one below it
    assert passed and failed and b["delta_s"] in passed and b["lower"] in failed, b
    assert b["lower"] < b["delta_s"] and all(d < b["lower"] or d > b["delta_s"] for d in passed + failed
                                             if d not in (b["lower"], b["delta_s"])), b
    at = next(p for p in b["probes"] if p["delta_s"] == b["delta_s"])
    assert (b["deficit"], b["friction_power"], b["min_measure"]) == (at["deficit"], at["friction_power"],
                                                                     at["min_measure"])


@pytest.mark.slow
def test_an_interrupted_bisection_keeps_its_probes_and_their_bracket(light, tmp_path):
    """SIGTERM during the bisection, after its first rounds of probes: the report said the bisection was interrupted
    but kept none of the preloads it had simulated. Now preload.json holds each probe (preload, passes, force
    deficit, groove-force excess, friction power, smallest force) and the bracket they establish, which contains
    the constant optimum, and preload.md lists them."""
    import json
    import signal

    out = tmp_path / "o"
    code, err = _interrupted(out, _after_a_round_of_probes, signal.SIGTERM)
    assert code == 143, err
    data = json.loads((out / "preload.json").read_text())
    assert data["status"] == "interrupted" and data["stopped"].endswith("during the bisection"), data["stopped"]
    b = data["bisection"]
    _check_probes_so_far(b)
    assert b["lower"] < data["constant"]["delta_s"] <= b["delta_s"] * (1 + 0.01), (b, data["constant"]["delta_s"])
    md = (out / "preload.md").read_text()
    assert f"**The bisection did not end.** Its {b['simulations']} simulations" in md
    rows = [line for line in md.splitlines() if line.startswith("| ") and line[2].isdigit()]
    assert [float(r.split("|")[1]) for r in rows] == pytest.approx([p["delta_s"] / MM for p in b["probes"]], abs=1e-4)
    assert f"and the bisection's {b['simulations']} simulations so far" in err


@pytest.mark.slow
def test_a_bisection_killed_outright_leaves_its_probes_in_the_checkpoint(light, tmp_path):
    """SIGKILL during the bisection, after its first rounds of probes: the checkpoint beside <out> held the constant
    optimum alone. Now each round of probes is checkpointed as the constant optimum is."""
    import json
    import signal

    out = tmp_path / "o"
    code, err = _interrupted(out, _after_a_round_of_probes, signal.SIGKILL)
    assert code == -signal.SIGKILL, err
    assert not out.exists()
    (partial,) = [p for p in tmp_path.iterdir() if p.name.startswith("o.partial-")]
    data = json.loads((partial / "preload.json").read_text())
    assert data["status"] == "interrupted" and data["constant"]["ok"]
    assert data["stopped"].startswith(f"written after the bisection's {data['bisection']['simulations']} simulations "
                                      "so far, while the study went on"), data["stopped"]
    _check_probes_so_far(data["bisection"])
    assert "**The bisection did not end.**" in (partial / "preload.md").read_text()
    assert sorted(p.name for p in partial.iterdir()) == ["preload.json", "preload.md", "preload.png", "pressure.csv",
                                                          "scene.toml"]  # the figure and scene files kept with it


@pytest.mark.slow
def test_a_study_killed_while_it_writes_its_report_leaves_each_report_whole(light, tmp_path):
    """SIGKILL while the study's second report (after the schedule) is being written, its figure half done:
    preload.json and preload.md held the schedule while preload.png still showed the constant optimum alone, and a
    0-byte .preload.png.<random>.tmp was left. Now the report of the constant optimum stays whole in
    <out>.partial-<run id>, no report is at <out>, and the next study into <out> sweeps away what the killed one
    was writing."""
    import hashlib
    import json
    import os
    import signal

    from fork_helpers import require_fork

    from apexseal.runtime.results import figures

    require_fork()
    out, log = tmp_path / "o", tmp_path / "figures.log"
    pid = os.fork()
    if pid == 0:  # the study, in a child that kills itself half-way through its second figure
        try:
            from click.testing import CliRunner

            from apexseal.cli import main

            save = figures.save_png

            def killed_in_the_second(fig, path, dpi):
                if log.exists():  # the second report's figure: half of it, then SIGKILL
                    with open(path.parent / f".{path.name}.half.tmp", "wb") as fh:
                        fh.write(b"\x89PNG half")
                    os.kill(os.getpid(), signal.SIGKILL)
                save(fig, path, dpi)
                log.write_text(hashlib.sha256(path.read_bytes()).hexdigest())

            figures.save_png = killed_in_the_second
            CliRunner().invoke(main, _light_cli(out, "--schedule", "2", "--no-check", "--quiet"))
        finally:
            os._exit(3)  # not reached: killed
    _, status = os.waitpid(pid, 0)
    assert os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGKILL, status
    assert not out.exists()  # no report was complete at the end: none replaced anything
    partial = [p for p in tmp_path.iterdir() if p.name.startswith("o.partial-")]
    assert len(partial) == 1
    data = json.loads((partial[0] / "preload.json").read_text())
    assert data["constant"]["ok"] and "schedule" not in data and data["status"] == "interrupted"
    assert data["stopped"].startswith("written after the constant optimum, while the study went on")
    assert "## schedule" not in (partial[0] / "preload.md").read_text()
    assert hashlib.sha256((partial[0] / "preload.png").read_bytes()).hexdigest() == log.read_text()
    assert sorted(p.name for p in partial[0].iterdir()) == ["preload.json", "preload.md", "preload.png",
                                                             "pressure.csv", "scene.toml"]  # no temporary file
    writing = [p for p in tmp_path.iterdir() if p.name.startswith(".o.writing-")]
    assert len(writing) == 1  # what it was writing, hidden beside the folder
    from apexseal.runtime.studies.preload.report import report_folder

    report_folder(out)  # the next study into it
    assert not writing[0].exists() and partial[0].is_dir()


def test_groove_excess_is_zero_exactly_when_the_bound_holds_between_samples(light):
    """The quadrature against the force at the samples: zero for a bound far above, positive below the peak at the
    samples, and falling as the bound rises (interpreted integrators, no compile)."""
    excess = {}
    for bound in (1e4, 11.0, 10.0, 9.0):
        setup = _setup(light, bound)
        sf = study_functions(setup, SAMPLES // NODES, compile_c=False)
        sim = simulate_schedule(setup, sf, SegmentGrid(SAMPLES, NODES, 1, setup.theta_start, setup.dth),
                                np.array([3.0 * MM]), MIN_FORCE, ())
        excess[bound] = sim.groove_excess
        peak = sim.groove_peak
    assert excess[1e4] == 0.0
    assert peak > 10.0 and excess[10.0] > 0.0 and excess[9.0] > excess[10.0] > excess[11.0] >= 0.0


def test_the_deficit_over_each_interval_sums_to_the_revolution_s_and_says_where_it_builds_up(light):
    """A user's study did not say where the force deficit that held its optimum built up (between the samples, far
    from the smallest force at them), so no --exclude window could be chosen: the quadrature is now kept per output
    interval, and the report names the span holding most of it."""
    from apexseal.runtime.studies.preload.result import deficit_span

    setup = _setup(light, NO_BOUND)
    sf = study_functions(setup, SAMPLES // NODES, compile_c=False)
    sim = simulate_schedule(setup, sf, SegmentGrid(SAMPLES, NODES, 1, setup.theta_start, setup.dth),
                            np.array([0.5 * MM]), MIN_FORCE, ())
    assert sim.deficit > 0 and sim.deficit_at.shape == (SAMPLES,) and (sim.deficit_at >= -1e-12).all()
    assert sim.deficit_at.sum() == pytest.approx(sim.deficit, rel=1e-9)
    start, end, share = deficit_span(sim.thetas, sim.deficit_at, setup.dth)
    assert 0.5 < share <= 1.0
    weakest = np.degrees(sim.thetas[np.argmin(sim.measure)]) % 360.0  # the tip's weakest sample lies in the span
    assert (weakest - start) % 360.0 <= (end - start) % 360.0


def test_the_deficit_span_grows_around_its_densest_interval_across_zero():
    from apexseal.runtime.studies.preload.result import deficit_span

    n = 36
    thetas = np.radians(10.0 * (np.arange(n) + 1))  # interval k ends at 10 (k + 1) deg
    d = np.zeros(n)
    d[[34, 35, 0, 1]] = [0.5, 4.0, 1.0, 0.001]  # 340-360, 0-20 deg; the last below 1 % of the densest
    start, end, share = deficit_span(thetas, d, np.radians(10.0))
    assert (start, end) == pytest.approx((340.0, 10.0)) and share == pytest.approx(5.5 / 5.501)
    assert deficit_span(thetas, np.zeros(n), np.radians(10.0)) is None
    from apexseal.runtime.studies.preload.result import PreloadResult

    everywhere = deficit_span(thetas, np.ones(n), np.radians(10.0))  # no interval stands out: the whole circle
    res = PreloadResult(True, "", 5.0, [], deficit_span_deg=list(everywhere[:2]), deficit_span_share=everywhere[2])
    assert res._deficit_where() == ["  the deficit is spread over the whole revolution (no window of it stands out)"]


def test_a_first_solve_stuck_beyond_the_bounded_filter_s_reach_is_given_up():
    """The lift-off scene's first IPOPT solve spent its 100 iterations far beyond the force-deficit bound before the
    study solved again with the filter bounded (a user's design spent most of its study there too): from a
    start without gradient, 25 iterations in a row above THETA_MAX_FACT x the bound now stop it (User_Requested_Stop)
    and the bounded solve follows at once. An iterate back within reach restarts the count; without give_up, none
    stops it."""
    from apexseal.runtime.studies.preload.nlp import STUCK_ITERATIONS, THETA_MAX_FACT, _Progress

    def run(progress, deficits):
        return [int(progress.eval([np.zeros(1), 1.0, np.r_[np.zeros(2), d], np.zeros(1), np.zeros(3),
                                   np.zeros(0)])[0]) for d in deficits]

    far = 33 * THETA_MAX_FACT
    stuck = run(_Progress(1, 3, 2, give_up=True), [0.0] + [far] * (STUCK_ITERATIONS - 1) + [1.0] + [far] * STUCK_ITERATIONS)
    assert stuck == [0] * (2 * STUCK_ITERATIONS) + [1]  # the count restarted at the iterate back within reach
    patient = _Progress(1, 3, 2)
    assert run(patient, [far] * (2 * STUCK_ITERATIONS)) == [0] * (2 * STUCK_ITERATIONS) and not patient.gave_up


def _two_knot_nlp(light):
    """The NLP of a 2-knot schedule (1.7, 1.8 mm) whose groove forces exceed a 10 N bound between samples, at the
    simulated schedule's node states: (the NLP, its point, the hand-assembled Jacobian there, the simulation, a
    central difference of row ``row`` along variable ``i`` with step ``h``). The study's compiled units, shared with
    the studies above through the cache."""
    setup = _setup(light, 10.0)  # the excess is smooth in the preload here: 8.0e-3, 8.9e-3, 9.8e-3 at 1.70, 1.75,
    sf = study_functions(setup, SAMPLES // NODES)  # 1.80 mm (measured)
    g0 = SegmentGrid(SAMPLES, NODES, 2, setup.theta_start, setup.dth)
    kn = np.array([1.7, 1.8]) * MM
    sim = simulate_schedule(setup, sf, g0, kn, MIN_FORCE, ())
    nlp = ShootingNlp(setup, sf, sim, NODES, 2, MIN_FORCE, (), DEFICIT_TOL, "friction")
    v0 = np.r_[kn / MM, nlp.W0]
    V = ca.MX.sym("V", v0.size)
    J = np.array(ca.Function("J", [V], [ca.jacobian(nlp.G(V), V)])(v0))

    def fd(row, i, h):
        e = np.zeros(v0.size)
        e[i] = h
        return (float(nlp.G(v0 + e)[row]) - float(nlp.G(v0 - e)[row])) / (2 * h)

    return nlp, v0, J, sim, fd


def test_groove_row_of_the_jacobian_is_the_constraint_derivative(light):
    """The hand-assembled Jacobian's groove-excess row (compiled forward sensitivities) against central
    differences."""
    nlp, v0, J, _, fd_row = _two_knot_nlp(light)
    row = nlp.n_con - 1  # the groove excess: after the defects and the deficit
    assert J.shape[0] == nlp.n_con + 1 and abs(J[row, :2]).max() > 0

    def fd(i, h):
        return fd_row(row, i, h)

    for i in (0, 1):  # both knots: ~186 and ~60 per mm (the excess over its bound); the node states move it by
        # less than the rtol noise of a difference quotient (measured: 0.08, 0.16, 2.4, -3.6 for steps 3e-2..1e-3)
        a, b = fd(i, 1e-2), fd(i, 3e-3)
        assert a == pytest.approx(b, rel=0.02)
        assert J[row, i] == pytest.approx(b, rel=0.02)


def test_the_objective_is_the_cycle_mean_friction_power_and_its_row_its_derivative(light):
    """The NLP's objective at the simulated schedule's states is the schedule's cycle-mean friction power (W), and
    its Jacobian row is its derivative: a scaling of the objective (the power without its division by 2 pi) left
    every optimum test passing, since IPOPT finds the same optimum of a scaled objective."""
    nlp, v0, J, sim, fd = _two_knot_nlp(light)
    row = nlp.n_con  # the objective: the last entry of G
    # to the cycle's closure: the NLP's revolution starts at nodes shifted from the simulation's grid
    # (_node_offset), through states of a last revolution that is periodic only to its settling (0.1 % here)
    assert float(nlp.G(v0)[row]) == pytest.approx(sim.friction_power, rel=1e-2) and sim.friction_power > 0
    for i in (0, 1):
        b = fd(row, i, 3e-3)
        assert abs(b) > 0 and J[row, i] == pytest.approx(b, rel=0.02)


def test_a_schedule_wraps_from_its_last_knot_to_its_first():
    """delta_s(theta) is periodic: before the first knot it runs on the line from the last knot to the first
    (wrapping at 360 deg instead held the first knot's value there)."""
    k1, k2, k3 = 2.0e-3, 5.0e-3, 3.0e-3
    sched = Schedule((10.0, 130.0, 250.0), (k1, k2, k3))
    assert sched(5.0) == pytest.approx(k3 + (k1 - k3) * 115 / 120)
    assert sched(370.0) == pytest.approx(k1) and sched(70.0) == pytest.approx((k1 + k2) / 2)


if __name__ == "__main__":  # python tests/runtime/test_preload_small.py: the numbers of README's preload section
    import time
    import warnings

    import apexseal
    from apexseal.runtime.api import model_functions
    from apexseal.runtime.scenes.scene import embedded_scene_path

    warnings.simplefilter("ignore")
    t0 = time.perf_counter()
    sc = apexseal.load_scene(embedded_scene_path("soft-contacts.toml")).with_overrides(
        **{"effects.chamber_pressure": False})
    pair = (sc, model_functions(sc))
    (c, b, s, cg), tight = run_studies(pair), tight_study(pair)
    for name, r in (("constant", c), ("schedule, 2 knots", s), (f"constant, groove forces <= {GROOVE_MAX:g} N", cg),
                    (f"constant, groove forces <= {GROOVE_TIGHT:g} N", tight)):
        print(f"## {name}\n{r.describe()}\n")
    print(f"bisection over full simulations: [{b.lower / MM:.4f}, {b.delta_s / MM:.4f}] mm ({b.simulations} "
          f"simulations); schedule saves {c.friction_power - s.friction_power:.3f} W; "
          f"total {time.perf_counter() - t0:.1f} s")
    from apexseal.runtime.studies.preload.stiffness import describe, stiffness_valley

    print(describe(stiffness_valley(_setup(pair), c, nodes=NODES), c.deficit_tol))


def test_a_constant_above_its_boundary_is_lowered_to_it(light, studies):
    """The polish of a constant optimum (study._polish_constant): from 20 % above the optimum (as where IPOPT stopped on
    the default scene with an inexact gradient) it bisects down to the bisection's bracket and records the start;
    at the optimum itself it changes nothing."""
    from apexseal.runtime.studies.preload.periodic import periodic
    from apexseal.runtime.studies.preload.result import PreloadResult
    from apexseal.runtime.studies.preload.study import _polish_constant

    c, b = studies[0], studies[1]
    setup = _setup(light)
    sf = study_functions(setup, SAMPLES // NODES)
    grid = SegmentGrid(SAMPLES, NODES, 1, setup.theta_start, setup.dth)
    high = np.array([1.2 * c.delta_s])
    res = PreloadResult(False, "", MIN_FORCE, [])
    knots, sim = _polish_constant(setup, sf, grid, high, periodic(setup, sf, grid, high, MIN_FORCE, ()), MIN_FORCE,
                                  (), DEFICIT_TOL, res)
    assert res.ipopt_delta_s == pytest.approx(high[0])
    assert b.lower - 0.01 * b.delta_s <= knots[0] <= b.delta_s + 0.01 * b.delta_s, (knots[0], b.lower, b.delta_s)
    assert sim.deficit <= DEFICIT_TOL
    same = PreloadResult(False, "", MIN_FORCE, [])
    at = np.array([c.delta_s])
    k2, _ = _polish_constant(setup, sf, grid, at, None, MIN_FORCE, (), DEFICIT_TOL, same)
    assert k2[0] == c.delta_s and same.ipopt_delta_s is None
    assert res.active == same.active == c.active == "deficit"
    assert "lowered by bisection" in "\n".join(res._holding()) and "lowered" not in "\n".join(same._holding())


@pytest.mark.slow
def test_a_constant_optimum_that_needs_no_preload_says_the_bound_holds_it(light):
    """At 0.1 N the seal's inertial load alone (1.5 N at its lowest) keeps the tip pressed: the optimum is no
    preload, where only the bound delta_s >= 0 is active. The report said 'IPOPT stopped at ... mm, above the
    feasible boundary: lowered by bisection' though no bisection ran (the polish halved down to 0.1 um and kept
    that) and no constraint was active; now it says the bound holds the optimum, at 0 mm, both from IPOPT's point
    and from 4 um above it (not from further: the tip lifts off between the samples at preloads of about 0.02 to
    0.09 mm here, measured, so a polish from 1.5 mm stops at 0.095 mm, the deficit active there)."""
    from apexseal.runtime.studies.preload.periodic import periodic
    from apexseal.runtime.studies.preload.result import PreloadResult
    from apexseal.runtime.studies.preload.study import _polish_constant

    scene, functions = light
    setup = PreloadSetup(scene, functions, 0.1, (), SAMPLES, max_groove_force=NO_BOUND)
    r = optimise_preload(scene, min_force=0.1, nodes=NODES, setup=setup)
    assert r.ok and r.delta_s == 0.0 and r.active == "zero" and r.deficit == 0.0, r.describe()
    text = r.describe()
    assert "only the bound delta_s >= 0" in text and "bisection" not in text and "boundary:" not in text, text
    sf = study_functions(setup, SAMPLES // NODES)
    grid = SegmentGrid(SAMPLES, NODES, 1, setup.theta_start, setup.dth)
    high = np.array([0.004 * MM])
    res = PreloadResult(False, "", 0.1, [])
    knots, sim = _polish_constant(setup, sf, grid, high, periodic(setup, sf, grid, high, 0.1, ()), 0.1, (),
                                  DEFICIT_TOL, res)
    assert knots[0] == 0.0 and sim.deficit == 0.0 and res.active == "zero" and res.ipopt_delta_s == high[0]
    said = "\n".join(res._holding())
    assert "IPOPT stopped at 0.0040 mm" in said and "lowered to the bound (no boundary to bisect)" in said, said


def test_a_bisection_whose_scan_passes_down_to_zero_probes_zero(light):
    """Where every preload scanned passes down to the last above 0, the bisection took 0 as its largest failing
    preload without simulating it, and bisected down to a small positive 'smallest passing preload' with the
    bracket [0, ...] claiming 0 fails. It now probes 0: here (0.1 N, below 0.01 mm, where nothing lifts the tip
    off) 0 passes, and the answer is 0 with no failing preload below it."""
    scene, functions = light
    setup = PreloadSetup(scene, functions, 0.1, (), SAMPLES, max_groove_force=NO_BOUND)
    b = bisect_preload(scene, min_force=0.1, nodes=NODES, setup=setup, upper=0.01 * MM, scan_step=0.004 * MM,
                       tol=0.001 * MM)
    assert 0.0 in [p.delta_s for p in b.probes] and b.delta_s == 0.0 and b.lower == 0.0, b
    assert b.deficit <= DEFICIT_TOL and b.monotone


def test_schedules_simulated_together_are_those_simulated_one_at_a_time(light):
    """``periodic_many`` (the derivative-free check's rounds of probes) integrates several schedules in one threaded
    map of the compiled interval integrator: the same re-simulations, bit for bit, as one schedule at a time, for
    constant preloads and for 2-knot schedules, the groove-force quadrature included."""
    from apexseal.runtime.studies.preload.periodic import periodic, periodic_many

    setup = _setup(light)
    sf = study_functions(setup, SAMPLES // NODES)
    for knots, designs in ((1, [[1.0], [3.0], [0.2]]), (2, [[1.0, 3.0], [2.5, 0.5]])):
        grid = SegmentGrid(SAMPLES, NODES, knots, setup.theta_start, setup.dth)
        designs = [np.array(d) * MM for d in designs]
        together = periodic_many(setup, sf, grid, designs, MIN_FORCE, ())
        assert len(together) == len(designs)
        for d, sim in zip(designs, together, strict=True):
            one = periodic(setup, sf, grid, d, MIN_FORCE, ())
            assert np.array_equal(one.z, sim.z) and np.array_equal(one.measure, sim.measure)
            assert np.array_equal(one.thetas, sim.thetas) and np.array_equal(one.delta_s, sim.delta_s)
            assert (one.deficit, one.friction_power, one.change, one.groove_excess, one.groove_peak) == \
                (sim.deficit, sim.friction_power, sim.change, sim.groove_excess, sim.groove_peak)
        assert len({sim.friction_power for sim in together}) == len(designs)  # the designs differ: so do their runs


def test_the_feasible_start_is_the_smallest_passing_multiple_of_the_scenes_preload(light):
    """The start search simulates its candidates (the scene's preload x 1.5^k) a round at a time on every core and
    keeps the first that passes: the history lists the candidates in order up to it, every one before it failing;
    with max_preload below it, none passes and the message says so."""
    from apexseal.runtime.studies.preload.result import PreloadResult
    from apexseal.runtime.studies.preload.study import _feasible_start

    setup = _setup(light)
    sf = study_functions(setup, SAMPLES // NODES)
    grid = SegmentGrid(SAMPLES, NODES, 1, setup.theta_start, setup.dth)
    res = PreloadResult(False, "", MIN_FORCE, [])
    d = _feasible_start(setup, sf, grid, 0.2 * MM, 0.1, DEFICIT_TOL, res)
    ds = [h[0] for h in res.history]
    assert ds == [0.2 * MM * 1.5**k for k in range(len(ds))] and d == ds[-1] and len(ds) > 2
    assert res.history[-1][2] <= DEFICIT_TOL and all(h[2] > DEFICIT_TOL for h in res.history[:-1])
    low = PreloadResult(False, "", MIN_FORCE, [])
    assert _feasible_start(setup, sf, grid, 0.2 * MM, ds[-2], DEFICIT_TOL, low) is None
    assert [h[0] for h in low.history] == ds[:-1] and low.message.startswith("infeasible")
    # the tip presses on the housing at every preload of this scene (its inertial load alone gives 1.5 N): the
    # message names the smallest force and says it is below the force asked, not that the tip lifts off (it did)
    force = low.history[-1][1]
    assert 0 < force < MIN_FORCE and f"the smallest force at the samples is {force:.3g} N" in low.message
    assert "lifts off" not in low.message and f"with less than the {MIN_FORCE:g} N asked" in low.message


def test_a_schedule_knot_on_its_bound_is_reported_within_it(light):
    """IPOPT relaxes its bounds (bound_relax_factor): the soft-contacts schedule's knot on the bound 0 came back as
    -1e-11 m and was printed "-0.000 mm". Relaxed far more here, the knot it drives to 0 is still >= 0."""
    from apexseal.runtime.studies.preload.result import PreloadResult

    scene = light[0]
    start = PreloadResult(True, "", MIN_FORCE, [], knot_angles_deg=[0.0], knots=[1.7565 * MM], delta_s=1.7565 * MM)
    s = optimise_preload(scene, min_force=MIN_FORCE, nodes=NODES, knots=2, start=start, setup=_setup(light),
                         ipopt_options={"bound_relax_factor": 1e-3})
    assert s.ok, s.message
    assert min(s.knots) == 0.0 and "-0.000" not in s.describe(), s.knots


def test_the_stiffness_valley_says_which_stiffnesses_keep_the_force_feasible():
    """The --vary-stiffness table marks a stiffness at which the optimum's spring force leaves the deficit above its
    bound: it printed the ratio without saying so. It judges as the study accepts its own re-simulated optimum
    (within ALLOWANCE of the bound): the optimum itself, at the scene's ks with 1.0004 x the bound on the small
    study's scene, was marked "no"."""
    from apexseal.runtime.studies.preload.result import ALLOWANCE
    from apexseal.runtime.studies.preload.stiffness import ValleyPoint, describe

    points = [ValleyPoint(1250.0, 7.0259e-3, 8.782, 26.850, 0.9, 0.0),
              ValleyPoint(5e3, 1.7565e-3, 8.782, 26.849, 1.0004, 0.0),
              ValleyPoint(2e4, 0.4391e-3, 8.782, 26.843, 1.01 * ALLOWANCE, 0.0),
              ValleyPoint(1e4, 0.8782e-3, 8.782, 26.847, 0.5, 2.0)]
    rows = describe(points, 1.0).splitlines()[2:]
    assert rows[0].endswith("yes") and rows[1].endswith("yes (within the 5 % the study allows its optimum)")
    assert rows[2].endswith("no: force deficit above its bound")
    assert rows[3].endswith("no: groove-force excess above its bound")


def test_ctrl_c_in_a_script_stops_the_study_and_carries_what_it_had(light, monkeypatch):
    """From Python, a Ctrl-C during IPOPT's iterations came back as a result with ok False and the status
    User_Requested_Stop, and the script went on (the Ctrl-C swallowed), unlike apexseal.simulate. Now the stage is
    abandoned and RunInterrupted carries the result as far as it got, as for a run; in an interactive session it is
    returned with a warning."""
    import os
    import signal

    import apexseal.signals
    from apexseal.runtime.api import RunInterruptedWarning
    from apexseal.signals import RunInterrupted

    solve = ShootingNlp.solve

    def interrupted(self, *args, **kwargs):
        os.kill(os.getpid(), signal.SIGINT)  # noted by the study's handler, raised at once (IPOPT abandoned)
        return solve(self, *args, **kwargs)

    monkeypatch.setattr(ShootingNlp, "solve", interrupted)
    scene = light[0]
    with pytest.raises(RunInterrupted, match="the preload study was interrupted by Ctrl-C") as info:
        optimise_preload(scene, min_force=MIN_FORCE, nodes=NODES, setup=_setup(light))
    res = info.value.result
    assert not res.ok and res.message.startswith("interrupted by the user (Ctrl-C, SIGINT) before the study ended")
    monkeypatch.setattr(apexseal.signals, "interactive", lambda: True)
    with pytest.warns(RunInterruptedWarning, match="the preload study was interrupted by Ctrl-C"):
        res = optimise_preload(scene, min_force=MIN_FORCE, nodes=NODES, setup=_setup(light))
    assert not res.ok and "interrupted" in res.message
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # the handler is given back

    def as_casadi_does(self, *args, **kwargs):  # the interruption raised inside a CasADi call becomes its error
        os.kill(os.getpid(), signal.SIGINT)
        raise NotImplementedError("Wrong number or type of arguments")

    monkeypatch.setattr(ShootingNlp, "solve", as_casadi_does)
    monkeypatch.setattr(apexseal.signals, "interactive", lambda: False)
    with pytest.raises(RunInterrupted) as info:  # the CasADi error it became escaped, and the result with it
        optimise_preload(scene, min_force=MIN_FORCE, nodes=NODES, setup=_setup(light))
    assert not info.value.result.ok


@pytest.mark.slow
def test_the_api_takes_quantities_and_windows_as_the_command_line_does(light):
    """`optimise_preload(min_force="5 N")`, `max_preload="10 mm"` and `exclude=["180:200"]` were refused (a number
    in N, pairs only) where the command line takes `--min-force 5N` and `--exclude 180:200`."""
    import pint

    from apexseal.runtime.studies.preload.problem import quantity_of, windows

    assert quantity_of("min_force", "5 N", "N", 1e5) == 5.0 and quantity_of("max_preload", "10 mm", "m", 1) == 0.01
    assert quantity_of("max_preload", pint.UnitRegistry().Quantity(2, "cm"), "m", 1) == pytest.approx(0.02)
    assert quantity_of("min_force", 5.0, "N", 1e5) == 5.0
    with pytest.raises(PreloadStudyError, match=r"min_force = '5 mm': wrong unit: expected a force in N .*; allowed: "
                                                 r"> 0 and <= 100000 N"):
        quantity_of("min_force", "5 mm", "N", 1e5)
    assert windows(["180:200", (350, 10)]) == ((180.0, 200.0), (350.0, 10.0))
    scene = light[0]
    a = optimise_preload(scene, min_force=f"{MIN_FORCE} N", nodes=NODES, max_preload="100 mm", setup=_setup(light))
    assert a.ok and a.min_force == MIN_FORCE


def test_max_rate_takes_a_rate_per_angle_and_is_checked_against_the_knots(light):
    """`max_rate="0.01 mm/deg"` was refused with "must be > 0 m per degree" though positive (quantity texts were
    taken by min_force and max_preload only); a number meant in mm per degree, as the command line's --max-rate
    takes it, was a bound 1000x looser that never bound, silently (now a warning naming the units); with knots=1
    max_rate was silently ignored (now refused)."""
    from apexseal.runtime.studies.preload.problem import max_rate_of, max_rate_problem, max_rate_unbinding

    assert max_rate_of("0.01 mm/deg") == pytest.approx(1e-5) and max_rate_of(2e-5) == 2e-5
    assert max_rate_of(None) is None
    with pytest.raises(PreloadStudyError, match=r"max_rate = '0.01 mm': expected a length per angle"):
        max_rate_of("0.01 mm")  # pint reads it per radian
    with pytest.raises(PreloadStudyError, match=r"max_rate = '5 N/deg': wrong unit"):
        max_rate_of("5 N/deg")
    assert max_rate_problem(1e-5, 4) is None and max_rate_unbinding(1e-5, 4, 0.01) is None
    scene = light[0]
    with pytest.raises(PreloadStudyError) as err:
        optimise_preload(scene, min_force=MIN_FORCE, nodes=NODES, knots=1, max_rate="0.01 mm/deg", setup=_setup(light))
    for w in ["max_rate = '0.01 mm/deg' (= 1e-05 in SI units)", "knots = 1", "knots >= 2"]:
        assert w in str(err.value), str(err.value)
    # 0.05 meant in mm per degree: a bound no schedule within 0..10 mm can reach, said as the study starts (the
    # lone text of exclude then stops it before any work)
    with pytest.warns(UserWarning, match=r"max_rate = 0.05 m per degree never binds \(4 knots 90 deg apart within "
                                         r"0..max_preload = 0.01 m change by at most 0.000111 m per degree\)") as w, \
            pytest.raises(PreloadStudyError, match="exclude = '0:10'"):
        optimise_preload(scene, min_force=MIN_FORCE, nodes=NODES, knots=4, max_rate=0.05, max_preload="10 mm",
                         exclude="0:10", setup=_setup(light))
    assert "'0.01 mm/deg'" in str(w[0].message) and w[0].filename == __file__


@pytest.mark.slow
def test_a_signal_during_the_re_simulation_keeps_ipopt_s_answer(light, tmp_path, monkeypatch):
    """A signal after "IPOPT ... done" but before its re-simulation ended lost IPOPT's finished answer: from Python
    the result said "nothing solved yet", the command "nothing to report" and wrote no report. Now the result keeps
    it as ``ipopt_knots``, marked not re-simulated (``knots`` stay None), and the command's report holds it."""
    import json
    import os
    import signal

    from click.testing import CliRunner

    import apexseal.signals
    from apexseal.cli import main
    from apexseal.runtime.studies.preload import study

    resimulate = study.periodic

    def stopped_there(*args, **kwargs):  # the signal lands as IPOPT's answer is re-simulated
        os.kill(os.getpid(), signal.SIGINT)
        return resimulate(*args, **kwargs)

    monkeypatch.setattr(study, "periodic", stopped_there)
    monkeypatch.setattr(apexseal.signals, "interactive", lambda: True)
    with pytest.warns(apexseal.RunInterruptedWarning, match=r"IPOPT's answer, not re-simulated"):
        res = optimise_preload(light[0], min_force=MIN_FORCE, nodes=NODES, setup=_setup(light))
    assert not res.ok and res.knots is None and len(res.ipopt_knots) == 1 and res.ipopt_knots[0] > 0
    assert "IPOPT's answer is kept, not re-simulated (ipopt_knots: " in res.message, res.message
    out = tmp_path / "o"
    r = CliRunner().invoke(main, _light_cli(out, "--no-check", "--quiet"))
    assert r.exit_code == 130 and "nothing to report" not in r.output, r.output
    (folder,) = [p for p in tmp_path.iterdir() if (p / "preload.json").is_file()]
    data = json.loads((folder / "preload.json").read_text())
    assert data["status"] == "interrupted" and data["constant"]["knots"] is None, data
    assert data["constant"]["ipopt_knots"] == pytest.approx(res.ipopt_knots, rel=1e-6)
    assert "IPOPT's answer is kept, not re-simulated" in (folder / "preload.md").read_text()


@pytest.mark.slow
def test_a_saved_study_loads_back_and_its_constant_optimum_starts_a_schedule(studies, light, tmp_path):
    """A saved study could not be loaded back: PreloadResult had no ``load`` and was not exported from apexseal, and
    ``start=`` took only a result in memory, so a schedule could not continue from a saved constant optimum."""
    import json

    import apexseal

    c, s = studies[0], studies[2]
    out = apexseal.save_preload_report(tmp_path / "report", c, s)
    as_json = lambda r: json.loads(json.dumps(r.to_dict(), default=str))  # noqa: E731 (tuples as lists)
    loaded = apexseal.PreloadResult.load(out)
    assert loaded.to_dict() == as_json(c) and loaded.schedule(123.0) == c.schedule(123.0)
    assert apexseal.PreloadResult.load(out, "schedule").to_dict() == as_json(s)
    assert loaded.scene.content_hash() == light[0].with_overrides(
        **{"solver.samples_per_revolution": SAMPLES}).content_hash()  # the scene.toml beside it, as the study ran
    with pytest.raises(PreloadStudyError, match=r"no readable preload study report there"):
        apexseal.PreloadResult.load(tmp_path)
    only = apexseal.save_preload_report(tmp_path / "constant-only", c)
    with pytest.raises(PreloadStudyError, match=r"its report holds no schedule result \(its status: completed\)"):
        apexseal.PreloadResult.load(only, "schedule")
    again = optimise_preload(light[0], min_force=MIN_FORCE, nodes=NODES, knots=2, start=loaded, setup=_setup(light))
    assert again.ok and again.knots == pytest.approx(s.knots, rel=1e-6), (again.knots, s.knots)


def _ctrl_c_at(monkeypatch, iteration: int, stage: str = "") -> None:
    """Ctrl-C as IPOPT reports its ``iteration`` (its progress line), in the IPOPT stage whose line starts with
    ``stage`` ("" any): the signal lands before that iteration is looked at, inside IPOPT's callback."""
    import os
    import signal

    from apexseal.runtime.studies.preload import nlp, study

    seen = {"stage": not stage}
    announce, begin = nlp.announce, study.stage

    def stage_of(text, *args, **kwargs):
        seen["stage"] = seen["stage"] or text.startswith(stage)
        return begin(text, *args, **kwargs)

    def line(text, *args, **kwargs):
        if seen["stage"] and f"IPOPT iteration {iteration}:" in text:
            os.kill(os.getpid(), signal.SIGINT)
        return announce(text, *args, **kwargs)

    monkeypatch.setattr(nlp, "announce", line)
    monkeypatch.setattr(study, "stage", stage_of)


def test_a_signal_during_ipopt_s_iterations_keeps_its_best_feasible_iterate(light, monkeypatch):
    """Ctrl-C during the constant optimum's IPOPT iterations kept nothing of the feasible iterates IPOPT had visited
    ("nothing solved yet"). Now the result keeps the best feasible one (``best_feasible``: lowest objective among
    the iterates within IPOPT's constr_viol_tol of every constraint), marked interrupted and not optimal; simulated
    from the scene's start, that preload meets the requirement."""
    import apexseal.signals
    from apexseal.runtime.studies.preload.periodic import periodic
    from apexseal.runtime.studies.preload.result import ALLOWANCE

    _ctrl_c_at(monkeypatch, 2)
    monkeypatch.setattr(apexseal.signals, "interactive", lambda: True)
    with pytest.warns(apexseal.RunInterruptedWarning, match=r"IPOPT's best feasible iterate, not optimal"):
        res = optimise_preload(light[0], min_force=MIN_FORCE, nodes=NODES, setup=_setup(light))
    best = res.best_feasible
    assert not res.ok and res.interrupted_by and res.knots is None and best is not None, res.message
    assert best["iteration"] in (0, 1) and 0 < best["knots"][0] <= res.start_delta_s * (1 + 1e-12), best
    assert best["deficit"] <= DEFICIT_TOL * (1 + 1e-3) and best["max_defect"] <= 1e-3, best
    assert "best feasible iterate so far is kept, NOT OPTIMAL and not re-simulated" in res.message, res.message
    assert res.describe().startswith("preload study interrupted: ")
    setup = _setup(light)
    sf = study_functions(setup, SAMPLES // NODES)
    grid = SegmentGrid(SAMPLES, NODES, 1, setup.theta_start, setup.dth)
    sim = periodic(setup, sf, grid, np.array(best["knots"]), MIN_FORCE, ())
    assert sim.deficit <= DEFICIT_TOL * ALLOWANCE, sim.deficit


@pytest.mark.slow
def test_the_command_reports_an_interrupted_schedule_s_best_feasible_knots(studies, light, tmp_path, monkeypatch):
    """Ctrl-C during the schedule's IPOPT iterations: the command's report held the constant optimum and dropped the
    schedule stage, which from Python is returned as far as it got. Now the report holds the schedule's result as
    the study keeps it (its best feasible knots, at worst its start, the constant optimum: a feasible schedule),
    through the same status rule as save_preload_report (status interrupted, "during the schedule")."""
    import json

    from click.testing import CliRunner

    from apexseal.cli import main
    from apexseal.runtime.studies.preload import study

    real = study.optimise_preload
    monkeypatch.setattr(study, "optimise_preload",  # the constant optimum the studies above found, not solved again
                        lambda scene, knots=1, **kw: studies[0] if knots == 1 else real(scene, knots=knots, **kw))
    _ctrl_c_at(monkeypatch, 2, "IPOPT (round 1: 2 knots")
    out = tmp_path / "o"
    r = CliRunner().invoke(main, _light_cli(out, "--schedule", "2", "--no-check", "--quiet"))
    assert r.exit_code == 130, r.output
    data = json.loads((out / "preload.json").read_text())
    assert data["status"] == "interrupted" and data["stopped"].endswith("during the schedule"), data
    c, s = data["constant"], data["schedule"]
    assert c["ok"] and not s["ok"] and s["interrupted_by"] and s["knots"] is None, s
    best = s["best_feasible"]
    assert len(best["knots"]) == 2 and best["iteration"] in (0, 1), best
    assert best["objective"] <= c["nlp_friction_power"] * (1 + 1e-3) + 1e-6, (best, c["nlp_friction_power"])
    assert "preload study interrupted: " in (out / "preload.md").read_text()


@pytest.mark.parametrize("cli, api", [
    (("--min-force", "5 mm"), {"min_force": "5 mm"}), (("--min-force", "0"), {"min_force": 0.0}),
    (("--max-groove-force", "3 m"), {"max_groove_force": "3 m"}), (("--max-preload", "2 m"), {"max_preload": "2 m"}),
    (("--nodes", "65"), {"nodes": 65}), (("--max-iter", "0"), {"max_iter": 0}),
    (("--deficit-tol", "1e4"), {"deficit_tol": 1e4}), (("--schedule", "73"), {"knots": 73}),
    (("--schedule", "4", "--max-rate", "-1"), {"knots": 4, "max_rate": "-1 mm/deg"}),
    (("--samples", "10"), {"samples": 10}),
])
def test_the_command_and_the_api_refuse_an_option_with_the_same_message(cli, api):
    """The command checked its options with its own ranges and words (click's "65 is not in the range 2<=x<=64",
    "'5 mm': ...; allowed: ..., e.g. 5N"), the API with others ("nodes = 65: must be an integer in 2..64"), and
    declared its defaults apart. Now the command checks each option with the study's check (study.check_option)
    and takes its defaults from the study's declaration (options.py): both name the same option, value and range."""
    from click.testing import CliRunner

    from apexseal.cli import main
    from apexseal.runtime.scenes.scene import embedded_scene_path

    scene = embedded_scene_path("soft-contacts.toml")
    with pytest.raises(PreloadStudyError) as err:
        optimise_preload(str(scene), **api)
    r = CliRunner().invoke(main, ["optimise-preload", str(scene), *cli, "--quiet"])
    assert r.exit_code == 2 and str(err.value) in " ".join(r.output.split()), (str(err.value), r.output)


@pytest.mark.parametrize("knots", ["0", "1", "-3"])
def test_a_schedule_of_fewer_than_two_knots_is_refused_in_the_command_s_range(knots):
    """--schedule 0 was refused as "must be an integer in 1..72 (1: a constant preload)", and then --schedule 1 as
    "a schedule has KNOTS >= 2": the command's range is 2..72."""
    from click.testing import CliRunner

    from apexseal.cli import main

    r = CliRunner().invoke(main, ["optimise-preload", "--schedule", knots, "--quiet"])
    assert r.exit_code == 2 and f"knots = {knots}: must be an integer in 2..72 (a schedule; 1 knot is the constant " \
        "preload" in " ".join(r.output.split()), r.output


@pytest.mark.parametrize("cli, api, given", [
    (("--schedule", "4", "--max-rate", "-1"), {"knots": 4, "max_rate": "-1 mm/deg"}, "'-1 mm/deg'"),
    (("--max-preload", "-2 mm"), {"max_preload": "-2 mm"}, "'-2 mm'"),
])
def test_a_refused_quantity_is_named_as_it_was_given(cli, api, given):
    """``--max-rate -1`` (mm per degree on the command line) was refused as "max_rate = -0.001: must be > 0 m per
    degree": a value the user never typed. A quantity's text is named as given, then in SI units, by both."""
    from click.testing import CliRunner

    from apexseal.cli import main
    from apexseal.runtime.scenes.scene import embedded_scene_path

    scene = embedded_scene_path("soft-contacts.toml")
    with pytest.raises(PreloadStudyError, match="in SI units") as err:
        optimise_preload(str(scene), **api)
    name = list(api)[-1]
    assert str(err.value).startswith(f"{name} = {given} (= "), str(err.value)
    r = CliRunner().invoke(main, ["optimise-preload", str(scene), *cli, "--quiet"])
    assert r.exit_code == 2 and given in r.output and str(err.value) in " ".join(r.output.split()), r.output


def test_the_command_s_defaults_are_the_api_s():
    """The command's defaults were written in it apart from optimise_preload's ("5 N" and 5.0, "100 mm" and 0.1)."""
    import inspect

    from click.testing import CliRunner

    from apexseal.cli import main
    from apexseal.runtime.studies.preload.options import DEFAULTS

    params = inspect.signature(optimise_preload).parameters
    assert {k: params[k].default for k in DEFAULTS} == DEFAULTS
    text = " ".join(CliRunner().invoke(main, ["optimise-preload", "--help"]).output.split())
    for shown in ("[default: 5 N]", "[default: 100 mm]", "[default: 100]", "[default: 4]", "[default: friction]"):
        assert shown in text, text
