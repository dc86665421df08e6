"""A preload along the revolution, ``[spring.schedule]`` (runtime/scenes/schedule.py): read and checked as a scene
key, written back, and run by the event-locating engines with the parameters linear between the output edges
(generated/hybrid.py), which is the preload study's own re-simulation of the same schedule (its DAE adds
``dp * slope * tau`` to the parameters, runtime/studies/preload/shooting.py): two implementations that agree as
their tolerance shrinks."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import apexseal
from apexseal.runtime.scenes.errors import SceneError
from apexseal.runtime.scenes.scene import embedded_scene_path
from apexseal.runtime.solving.settings import SettingsError

KNOTS_DEG = ("0 deg", "90 deg", "180 deg", "270 deg")
KNOTS_MM = ("1.5 mm", "2.6 mm", "2.0 mm", "1.2 mm")
#: the light scene's grid: the soft-contacts scene without chamber pressure on 72 samples (5 deg), as the small
#: preload study runs it (tests/runtime/test_preload_small.py); interpreted, so nothing compiles for these runs
SAMPLES = 72


#: the 2-knot schedule the methods are held to erk on: 1 mm at the start, 3 mm half a revolution on
TWO_KNOTS = (("0 deg", "180 deg"), ("1 mm", "3 mm"))


def state_gap(X: np.ndarray, ref: np.ndarray) -> float:
    """The largest difference of the states ``X`` from ``ref`` (a row per state), over each state's range in
    ``ref``."""
    return max(np.abs(X[i] - ref[i]).max() / np.ptp(ref[i]) for i in range(ref.shape[0]))


def scheduled(scene, angles=KNOTS_DEG, values=KNOTS_MM):
    return scene.with_overrides(**{"spring.delta_s": None, "spring.schedule.angles": list(angles),
                                   "spring.schedule.delta_s": list(values)})


@pytest.fixture(scope="module")
def light():
    scene = apexseal.load_scene(embedded_scene_path("soft-contacts.toml"))
    return scene.with_overrides(**{"effects.chamber_pressure": False})


def _run(scene, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the soft contacts' penetration warnings
        return apexseal.simulate(scene, samples_per_revolution=SAMPLES, interpreted=True, **kw)


def test_the_parameters_along_a_schedule_are_the_scene_s_at_each_preload():
    """At each knot the parameter vector is the one of the same scene with ``spring.delta_s`` at the knot's value
    (delta_w of Eq. 9 follows the preload), half-way between two knots the one at their mean (linear), after the
    last knot back towards the first (periodic); ``scene.parameters`` is the vector at the start angle."""
    base = apexseal.load_scene()
    scene = scheduled(base)
    names = tuple(scene.parameters)
    path = scene.parameter_path()
    thetas = np.radians([0.0, 90.0, 180.0, 270.0, 45.0, 315.0, 360.0 + 90.0])
    P = path(thetas)
    values = [1.5, 2.6, 2.0, 1.2, (1.5 + 2.6) / 2, (1.2 + 1.5) / 2, 2.6]
    for j, mm in enumerate(values):
        own = base.with_overrides(**{"spring.delta_s": f"{mm!r} mm"}).parameter_vector(names)
        np.testing.assert_allclose(P[:, j], own, rtol=1e-12, atol=1e-18)
    assert P[names.index("delta_w"), 1] > P[names.index("delta_w"), 0]  # the rest deflection moves with it
    assert scene.parameters["delta_s"] == pytest.approx(1.5e-3, rel=1e-12)
    assert base.parameter_path() is None and base.schedule is None


@pytest.mark.parametrize("change, key, words", [
    ({"spring.delta_s": "2 mm"}, "spring.delta_s", "given together with spring.schedule.delta_s"),
    ({"spring.schedule.angles": ["0 deg", "90 deg", "80 deg", "270 deg"]}, "spring.schedule.angles",
     "must increase strictly"),
    ({"spring.schedule.angles": ["0 deg", "90 deg", "180 deg", "360 deg"]}, "spring.schedule.angles",
     "less than one revolution"),
    ({"spring.schedule.delta_s": ["1 mm", "2 mm"]}, "spring.schedule.delta_s", "2 values for 4 knots"),
    ({"spring.schedule.delta_s": ["1 mm", "2 mm", "-1 mm", "1 mm"]}, "spring.schedule.delta_s",
     "item 3 ('-1 mm'): -0.001 m is out of range; allowed: >= 0 m"),
    ({"spring.schedule.angles": [0, 90, 180, 270]}, "spring.schedule.angles", "item 1 (0): give a unit"),
    ({"spring.schedule.delta_s": "2 mm"}, "spring.schedule.delta_s", "expected an array of 2 to 360 values"),
    ({"spring.schedule.delta_s": None}, "spring.schedule", "schedules nothing"),
])
def test_a_bad_schedule_is_refused_naming_the_key_the_value_and_what_is_allowed(change, key, words):
    with pytest.raises(SceneError) as err:
        scheduled(apexseal.load_scene()).with_overrides(**change)
    assert any(p.key == key and words in p.message for p in err.value.errors), str(err.value)


def test_a_scene_without_preload_or_schedule_asks_for_either():
    with pytest.raises(SceneError, match=r"spring.delta_s = \(missing\): .*or a schedule \(\[spring.schedule\]"):
        apexseal.load_scene().with_overrides(**{"spring.delta_s": None})


def test_the_resolved_scene_writes_the_schedule_back(tmp_path):
    """scene.toml of a run re-loads to the same scene (content hash), the schedule's knots included, and a scene
    without a schedule hashes as before schedules existed (no empty table in its content)."""
    from apexseal.runtime.scenes.resolved import resolved_toml

    scene = scheduled(apexseal.load_scene())
    text, files = resolved_toml(scene)
    assert "[spring.schedule]" in text and 'delta_s = ["0.0015 m", "0.0026 m", "0.002 m", "0.0012 m"]' in text
    (tmp_path / "scene.toml").write_text(text)
    for name, body in files.items():
        (tmp_path / name).write_text(body)
    again = apexseal.load_scene(tmp_path / "scene.toml")
    assert again.content_hash() == scene.content_hash() != apexseal.load_scene().content_hash()
    assert "schedule" not in apexseal.load_scene().to_dict()["spring"]


def test_a_schedule_that_holds_one_preload_runs_as_that_constant_preload(light):
    """All knots at the scene's preload: the offsets and slopes are zero, p + 0 + 0 tau is p, and the run is the
    constant preload's to the last bit; its output delta_s is that preload at every sample."""
    mm = light.parameters["delta_s"] / 1e-3
    flat = _run(scheduled(light, ("0 deg", "120 deg", "240 deg"), [f"{mm!r} mm"] * 3))
    plain = _run(light)
    assert flat.status == plain.status == "completed"
    assert np.array_equal(flat.state, plain.state) and np.array_equal(flat.closed, plain.closed)
    assert np.all(flat.outputs["delta_s"] == light.parameters["delta_s"]) and "delta_s" not in plain.outputs


def test_a_schedule_of_a_spring_that_is_off_is_not_read(light):
    """With effects.spring = false the model has no preload (no slot for delta_s): the schedule is not read, as
    spring.delta_s is not, and the run is the scene's without a spring (it raised a KeyError from
    parameter_function before)."""
    scene = scheduled(light).with_overrides(**{"effects.spring": False})
    assert scene.schedule is None and scene.parameter_path() is None and "delta_s" not in scene.parameters
    run = _run(scene)
    assert run.status == "completed" and "delta_s" not in run.outputs
    assert np.array_equal(run.state, _run(light.with_overrides(**{"effects.spring": False})).state)


def _study_and_run(light, knots_mm, rtol, revolutions=3):
    """The study's re-simulation of a schedule (its last revolution, physical states) and the run of the scene with
    that schedule (its last revolution), on the study's grid."""
    from apexseal.generated.scaling import to_physical
    from apexseal.runtime.api import model_functions
    from apexseal.runtime.studies.preload.problem import MM, PreloadSetup
    from apexseal.runtime.studies.preload.schedule import SegmentGrid, simulate_schedule
    from apexseal.runtime.studies.preload.shooting import study_functions

    setup = PreloadSetup(light, model_functions(light), 10.0, (), SAMPLES, rtol=rtol)
    grid = SegmentGrid(SAMPLES, 4, len(knots_mm), setup.theta_start, setup.dth)
    knots = np.asarray(knots_mm) * MM
    sim = simulate_schedule(setup, study_functions(setup, SAMPLES // 4, compile_c=False), grid, knots, 10.0, (),
                            revolutions=revolutions)
    lay = setup.layout
    X_study = to_physical(sim.z[lay.x][:, 1:], setup.pmap.at("omega"), lay.state_names)
    angles = [f"{float(a)!r} deg" for a in grid.knot_angles_deg]
    run = _run(scheduled(light, angles, [f"{float(k)!r} m" for k in knots]), revolutions=revolutions, rtol=rtol)
    assert run.status == "completed"
    np.testing.assert_allclose(run.outputs["delta_s"][-SAMPLES:], sim.delta_s, rtol=1e-12)
    return X_study, run.state[:, -SAMPLES:]


def test_a_scheduled_run_is_the_preload_study_s_re_simulation_of_the_schedule(light):
    """The light scene with a 2-knot schedule (1 mm at the start, 3 mm half a revolution on), three revolutions:
    the run and the study's re-simulation differ by 2e-7 of each state's range at rtol 1e-9 (measured 1.2e-7 at
    most, in the seal's velocity xd) and by more than 10x that at rtol 1e-7 (measured 1.1e-5): they converge to one
    solution (``python tests/runtime/test_schedule.py`` prints the gaps). A run whose
    parameters were held over each 5-degree interval, or whose delta_w stayed at the start's, would differ by the
    preload's change over an interval (0.06 mm) or the rest deflection's (1e-7 m, 15 % of x's range)."""
    gaps = {rtol: gap(light, rtol) for rtol in (1e-9, 1e-7)}
    assert gaps[1e-9] < 2e-7, gaps
    assert gaps[1e-7] > 10 * gaps[1e-9], gaps


def gap(light, rtol: float) -> float:
    """The largest difference between the run and the study's re-simulation of the 2-knot schedule, over each
    state's range."""
    X_study, X_run = _study_and_run(light, [1.0, 3.0], rtol)
    return state_gap(X_run, X_study)


def cvodes_gap(light, rtol: float = 1e-9) -> float:
    """cvodes against erk on the 2-knot schedule, both at ``rtol``."""
    erk, cv = (_run(scheduled(light, *TWO_KNOTS), method=m, rtol=rtol) for m in ("erk", "cvodes"))
    assert erk.status == cv.status == "completed"
    return state_gap(cv.state, erk.state)


def euler_gaps(light, steps=(100000, 200000, 400000)) -> list[float]:
    """Explicit Euler at each of ``steps`` a revolution against erk at rtol 1e-10 on the 2-knot schedule."""
    scene = scheduled(light, *TWO_KNOTS)
    erk = _run(scene, rtol=1e-10)
    gaps = []
    for n in steps:
        eu = _run(scene, method="euler", steps_per_revolution=n)
        assert eu.status == "completed"
        gaps.append(state_gap(eu.state, erk.state))
    return gaps


def test_an_engine_that_cannot_follow_a_schedule_is_refused_naming_the_methods_that_can():
    """Every built-in method takes a schedule; a user's engine that does not list "linear" in its
    ``parameter_profiles`` (the contract's default, runtime/solving/methods.py) is refused before the run."""
    from apexseal.runtime.solving.event_integrator import EventIntegrator
    from apexseal.runtime.solving.methods import METHODS

    class Mine(EventIntegrator):
        parameter_profiles = ("constant",)

    scene = scheduled(apexseal.load_scene())
    can = ", ".join(METHODS)
    with pytest.raises(SettingsError, match=r'method = "Mine": cannot integrate parameters that follow the crank '
                                            rf"angle .*methods that can: {can}$"):
        apexseal.simulate(scene, method=Mine)


@pytest.mark.slow  # 8 s of a 2-core test process: in the second step, to keep the default suite under 10 min
def test_the_stepper_engines_follow_a_schedule_as_erk_does(light):
    """cvodes (apexseal's own event location, runtime/solving/stepper_integrator.py: the parameters' slopes ride in the
    call's vector after the pressures') runs the 2-knot schedule to erk's samples within 1e-5 of each state's range at
    rtol 1e-9 (1.2e-7; 1.6e-5 at rtol 1e-7), where the same schedule 5 degrees late moves erk's by 25 % (``python
    tests/runtime/test_schedule.py`` prints these); a schedule of one value is its constant preload's run bit for bit
    (rk, 20000 steps a revolution: fewer than its default 200000, for time)."""
    gap = cvodes_gap(light)
    assert gap < 1e-5, gap
    mm = light.parameters["delta_s"] / 1e-3
    flat = _run(scheduled(light, ("0 deg", "180 deg"), [f"{mm!r} mm"] * 2), method="rk", steps_per_revolution=20000)
    plain = _run(light, method="rk", steps_per_revolution=20000)
    assert np.array_equal(flat.state, plain.state) and np.array_equal(flat.closed, plain.closed)


@pytest.mark.slow  # 7 s of a 2-core test process: in the second step, to keep the default suite under 10 min
def test_explicit_euler_follows_a_schedule_to_first_order(light):
    """The fixed-step fold (runtime/solving/fixed_step.py: the parameters' slopes in each interval's column) on the 2-knot
    schedule: its gap to erk at rtol 1e-10 halves as its steps double (0.204, 0.092, 0.043 of a state's range at 1e5,
    2e5, 4e5 steps a revolution, as ``python tests/runtime/test_schedule.py`` prints), as a first-order method's does;
    parameters held over each 5-degree interval would leave a floor the steps cannot lower. A schedule of one value runs
    as its constant."""
    gaps = euler_gaps(light)
    assert all(1.7 < a / b < 2.6 for a, b in zip(gaps[:-1], gaps[1:], strict=True)), gaps
    mm = light.parameters["delta_s"] / 1e-3
    flat = _run(scheduled(light, ("0 deg", "180 deg"), [f"{mm!r} mm"] * 2), method="euler")
    assert np.array_equal(flat.state, _run(light, method="euler").state)


def test_the_command_line_runs_a_scheduled_scene_with_the_composite(light, tmp_path):
    """`apexseal simulate` of a scheduled scene file with the composite method (the schedule's lines in its C,
    generated/templates/apexseal_composite.in.c): the run reaches erk's at rtol 1e-10 within 1e-4 of each state's range
    (1.8e-5 at rtol 1e-6, 4e-8 at 1e-8 from the API: ``python tests/runtime/test_schedule.py``) and writes delta_s at
    every sample, a column of trajectory.csv with its unit."""
    from click.testing import CliRunner

    from apexseal.cli import main
    from apexseal.runtime.scenes.resolved import resolved_toml

    scene = scheduled(light, *TWO_KNOTS).with_overrides(
        **{"solver.samples_per_revolution": SAMPLES})
    text, files = resolved_toml(scene)
    (tmp_path / "s.toml").write_text(text)
    for name, body in files.items():
        (tmp_path / name).write_text(body)
    done = CliRunner().invoke(main, ["simulate", str(tmp_path / "s.toml"), "--method", "composite", "--quiet",
                                     "--csv", "--out", str(tmp_path / "out")])
    assert done.exit_code == 0, done.output
    header = next(line for line in (tmp_path / "out" / "trajectory.csv").read_text().splitlines()
                  if not line.startswith("#"))
    assert "delta_s [m]" in header.split(",")  # described in runtime/results/outputs.py
    run = apexseal.SimulationResult.load(tmp_path / "out")
    erk = _run(scene, rtol=1e-10)
    np.testing.assert_allclose(run.outputs["delta_s"], scene.schedule("delta_s", run.theta), rtol=1e-12)
    gap = state_gap(run.state, erk.state)
    assert run.info["method"] == "composite" and gap < 1e-4, gap


if __name__ == "__main__":  # the gaps the README and the docstrings above quote
    scene = apexseal.load_scene(embedded_scene_path("soft-contacts.toml"))
    scene = scene.with_overrides(**{"effects.chamber_pressure": False})
    for rtol in (1e-6, 1e-7, 1e-8, 1e-9):
        print(f"rtol {rtol:.0e}: largest gap between the run and the study's re-simulation {gap(scene, rtol):.2e} "
              "of a state's range")
    for rtol in (1e-9, 1e-7):
        print(f"rtol {rtol:.0e}: cvodes against erk on the 2-knot schedule {cvodes_gap(scene, rtol):.2e}")
    print("euler at 1e5, 2e5, 4e5 steps against erk at rtol 1e-10:", ", ".join(f"{g:.3f}" for g in euler_gaps(scene)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        two = scheduled(scene, *TWO_KNOTS)
        erk = _run(two, rtol=1e-10)
        for rtol in (1e-6, 1e-8):
            composite = apexseal.simulate(two, samples_per_revolution=SAMPLES, method="composite", rtol=rtol)
            print(f"rtol {rtol:.0e}: composite against erk at rtol 1e-10 {state_gap(composite.state, erk.state):.2e}")
        late = _run(scheduled(scene, ("5 deg", "185 deg"), TWO_KNOTS[1]), rtol=1e-7)
        print(f"the schedule 5 degrees late, erk at rtol 1e-7: {state_gap(late.state, _run(two, rtol=1e-7).state):.2f}")
