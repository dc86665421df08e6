"""Inputs that could exhaust the machine or mislead: pressure tables bounded, impossible starts named before a step."""

from __future__ import annotations

import math
import os
import time
from pathlib import Path

import numpy as np
import pytest

import apexseal
from apexseal.runtime.scenes import pressure as pressure_mod
from apexseal.runtime.scenes.errors import SceneError
from apexseal.runtime.scenes.pressure import load_table

TABLE = "theta_deg,Pa,Pb\n0,1e5,2e5\n90,3e5,2e5\n180,1e5,2e5\n270,3e5,2e5\n"


def _message(name, folder) -> str:
    with pytest.raises(SceneError) as info:
        load_table(str(name), folder)
    (problem,) = info.value.errors
    assert problem.key == "pressure.file"
    return problem.message


def test_bom_and_crlf_are_accepted(tmp_path):
    (tmp_path / "plain.csv").write_text(TABLE)
    (tmp_path / "excel.csv").write_bytes(b"\xef\xbb\xbf" + TABLE.replace("\n", "\r\n").encode())
    plain, excel = load_table("plain.csv", tmp_path), load_table("excel.csv", tmp_path)
    assert np.array_equal(plain.Pa(np.linspace(0, 6, 50)), excel.Pa(np.linspace(0, 6, 50)))


def test_an_endless_pipe_is_refused_without_reading(tmp_path):
    os.mkfifo(tmp_path / "pipe.csv")  # opening it would block: the file type is checked first
    assert "not a regular file" in _message("pipe.csv", tmp_path)


def test_a_device_is_refused():
    assert "not a regular file" in _message(os.devnull, Path("."))


@pytest.mark.skipif(not Path("/proc/self/environ").exists(), reason="no proc file system")
def test_a_virtual_file_is_refused_without_echoing_it():
    message = _message("/proc/self/environ", Path("."))
    assert "virtual file system" in message and len(message) < 300
    assert not any(f"{k}={v}" in message for k, v in os.environ.items() if len(v) > 3)


def test_a_table_over_the_size_limit_is_refused(tmp_path, monkeypatch):
    monkeypatch.setattr(pressure_mod, "MAX_TABLE_BYTES", 1000)
    (tmp_path / "big.csv").write_text(TABLE + "# padding\n" * 200)
    assert "allowed: at most" in _message("big.csv", tmp_path)


def test_messages_quote_a_short_excerpt(tmp_path):
    (tmp_path / "long.csv").write_text("x" * 100_000 + "\n0,1,2\n")
    message = _message("long.csv", tmp_path)
    assert len(message) < 300 and "more characters" in message
    (tmp_path / "nul.csv").write_bytes(b"theta_deg,Pa,Pb\n0,1\x00,2\n")
    assert "binary file" in _message("nul.csv", tmp_path)


# ---------------------------------------------------------------- impossible runs named before the first step
@pytest.mark.parametrize("override,fragments", [
    ({"operation.initial_state.x": "1 m"}, ["operation.initial_state.x = 1 m", "inside a wall", "guard xs5"]),
    ({"operation.initial_state.phi": "40 deg"}, ["operation.initial_state.phi = 40 deg", "inside a wall"]),
    ({"operation.initial_state.y": "1 mm"}, ["operation.initial_state.y = 0.001 m", "inside a wall"]),
    ({"operation.initial_state.y": "5 mm"}, ["operation.initial_state.y = 0.005 m", "geometry is not defined",
                                              "is not finite"]),
    ({"operation.rpm": 1e-300}, ["operation.rpm = 1e-300 rpm is too slow", "allowed: rpm >="]),
    # sunk into the groove: -1 m ran until it "chattered" (only +1 m was caught); -0.35 mm is just past the bound
    ({"operation.initial_state.x": "-1 m"}, ["operation.initial_state.x = -1 m", "groove mouth corner on the seal's "
                                             "tip arc", "allowed: both mouth corners on the seal's flat sides, for x "
                                             "alone -0.308086 mm < x < 7.28999 mm"]),
    ({"operation.initial_state.x": "-0.35 mm"}, ["operation.initial_state.x = -0.00035 m", "tip arc"]),
])
@pytest.mark.filterwarnings("ignore::apexseal.runtime.results.plausibility.PenetrationWarning")  # inside a wall
@pytest.mark.filterwarnings("ignore::apexseal.runtime.scenes.units.PlausibilityWarning")  # 1e-300 rpm
def test_impossible_start_is_named_before_integrating(default_scene, default_functions, override, fragments):
    scene = default_scene.with_overrides(**override)
    t = time.perf_counter()
    r = apexseal.simulate(scene, functions=default_functions.sx, samples_per_revolution=72, compile_c=False)
    assert time.perf_counter() - t < 5.0
    assert r.status == "failed" and r.n == 1
    assert all(f in r.stop.reason for f in fragments), r.stop.reason


@pytest.mark.parametrize("key, named", [
    ("machine.L", "machine.L = 1e+303 mm (engineering practice: 2 to 2000 mm)"),
    ("seal.Wg", "seal.Wg = 1e+303 mm (engineering practice: 0.3 to 30 mm)"),
    ("seal.ro", "seal.ro = 1e+303 mm (engineering practice: 0.2 to 10000 mm)"),
    ("operation.rpm", "operation.rpm = 1e+300 rpm (engineering practice: 1 to 50000 rpm)"),
])
@pytest.mark.filterwarnings("ignore::apexseal.runtime.scenes.units.PlausibilityWarning")
def test_a_run_that_fails_on_an_absurd_value_names_its_key(default_scene, default_functions, key, named):
    """No range refuses a machine 1e300 m long, a flat tip or a fast rotor (the scene warns), but at 1e300 the
    model's numbers overflow and the run failed with a reason that named no key (a right-hand side that is not
    finite, a step size below its minimum): it now names the values far outside engineering practice."""
    scene = default_scene.with_overrides(**{key: 1e300})
    r = apexseal.simulate(scene, functions=default_functions.sx, samples_per_revolution=72, compile_c=False)
    assert r.status == "failed" and r.n == 1
    assert "values far outside engineering practice, the likely cause: " + named in r.stop.reason, r.stop.reason


@pytest.mark.filterwarnings("ignore::apexseal.runtime.scenes.units.PlausibilityWarning")
def test_a_run_that_fails_on_a_table_in_the_wrong_unit_names_the_unit(default_scene, default_functions):
    """The default's table is in Pa; read as bar, its pressures of 1e10 Pa throw the seal out of its geometry. The
    scene warned at the start, but the failure's reason advised stiffer contacts and named no key."""
    scene = default_scene.with_overrides(**{"pressure.unit": "bar"})
    r = apexseal.simulate(scene, functions=default_functions.sx, samples_per_revolution=72, compile_c=False)
    assert r.status == "failed", r.stop
    assert 'the likely cause: pressure.unit = "bar": the table\'s absolute pressures span 1.013e+10..6e+10 Pa' in \
        r.stop.reason, r.stop.reason
    assert "as stiff as metal" in r.stop.reason and "stiffer contacts" not in r.stop.reason
    from apexseal.runtime.solving.preflight import far_outside_practice

    constant = default_scene.with_overrides(**{"pressure": {"source": "constant", "Pa": 0.0, "Pb": 1e5}})
    p = constant.parameter_vector(default_functions.sx.parameter_names)  # a constant pressure has no table: nothing
    assert far_outside_practice(default_functions.sx, p, constant.pressure) == ""  # (it raised, found by hypothesis)


def test_every_hard_scene_passes_the_preflight(default_functions):
    """The bounds refuse only impossible starts: no hard scene (start on a guard, 60 rpm, ...) is refused."""
    from hard_helpers import SCENES, load

    from apexseal.runtime.api import initial_state
    from apexseal.runtime.solving.preflight import flank_problem, speed_problem, start_problem

    fns = default_functions.sx
    for name in SCENES:
        sc = load(name)
        p, th = sc.parameter_vector(), sc.operation.start_angle
        u = np.asarray(sc.pressure.interval_means(np.array([th, th + 1e-3])), float)[:, 0] \
            if sc.effects.chamber_pressure else np.zeros(2)
        assert speed_problem(fns, p) is None, name
        assert start_problem(fns, p, th, initial_state(sc), u) is None, name
        assert flank_problem(fns, p, th, initial_state(sc), np.zeros(len(fns.guard_names)), u) is None, name


def test_the_start_s_lowest_x_is_where_the_scene_check_puts_the_groove_mouth(default_scene, default_functions):
    """The start check's bound on x is the scene's zeta0 bound (checks.mouth_on_flank) moved by x: a start just
    inside it is not refused, just outside it is, and a tilt moves one corner towards the arc."""
    from apexseal.runtime.scenes.checks import mouth_on_flank
    from apexseal.runtime.solving.preflight import flank_problem

    fns = default_functions.sx
    p = default_scene.parameter_vector(tuple(fns.parameter_names))
    s = default_scene.seal
    bound = s.ro * (1 - math.cos(math.asin(s.Ws / (2 * s.ro)))) - s.zeta0  # zeta0 + x > ro (1 - cos beta_o)
    assert mouth_on_flank(s, s.zeta0 + bound - 2e-6, "v") and not mouth_on_flank(s, s.zeta0 + bound + 2e-6, "v")
    a, u = np.zeros(len(fns.guard_names)), np.zeros(2)
    for x, refused in ((bound + 2e-6, False), (bound - 2e-6, True)):
        assert (flank_problem(fns, p, 0.0, np.array([x, 0, 0, 0, 0, 0.0]), a, u) is not None) is refused, x
    tilted = np.array([bound + 2e-6, 0, math.radians(2), 0, 0, 0.0])
    assert flank_problem(fns, p, 0.0, tilted, a, u) is not None


def _beyond_each_bound():
    from apexseal.derive.submodels.registry import parameters

    for p in parameters(all_inputs=True):
        if p.key is None:
            continue
        for kind, bound in (("gt", p.gt), ("ge", p.ge), ("lt", p.lt), ("le", p.le)):
            if bound is not None:
                step = max(abs(bound), 1e-9) * 1e-6  # just past a closed bound; an open one is its own value
                value = {"gt": bound, "ge": bound - step, "lt": bound, "le": bound + step}[kind]
                yield pytest.param(p.key, value if p.unit == "1" else f"{value!r} {p.unit}", id=f"{p.key}-{kind}")


def _scene_reading(default_scene, key: str):
    """An embedded scene whose laws read ``key`` (the default, else the chamber gas scene, for the [gas] keys),
    with the first effect or modelling choice its ``needs`` names made where the scene lacks it. A value no law
    reads is out of range with a warning only (docs/scenes.md), so each bound is checked where the value is read."""
    from apexseal.derive.options import needed_effects
    from apexseal.derive.submodels.registry import is_read, needing, parameters
    from apexseal.runtime.scenes.scene import embedded_scene_path

    p = next(q for q in parameters(all_inputs=True) if q.key == key)
    for scene in (default_scene, apexseal.load_scene(embedded_scene_path("expander-gas.toml"))):
        if is_read(p, scene.effects, scene.assumptions):
            return scene
        slot, _, choice = (needed_effects(needing(p)) or ("",))[0].partition("=")
        made = scene.with_overrides(**({f"assumptions.{slot}": choice} if choice else {f"effects.{slot}": True}))
        if is_read(p, made.effects, made.assumptions):
            return made
    pytest.fail(f"no embedded scene reads {key}")


@pytest.mark.filterwarnings("ignore::apexseal.runtime.scenes.units.PlausibilityWarning")
@pytest.mark.parametrize("key, value", list(_beyond_each_bound()))
def test_every_declared_bound_is_enforced(default_scene, key, value):
    """Each submodel's declared range (gt, ge, lt, le) refuses a value just past it, naming the key, in a scene
    whose laws read it: a bound dropped from a declaration (friction.mus < 1, which keeps the spring's friction
    below its normal force) went unnoticed by every other test."""
    scene = _scene_reading(default_scene, key)
    with pytest.raises(SceneError) as info:
        scene.with_overrides(**{key: value})
    assert key in info.value.keys()


def test_the_start_penetration_limit_is_a_tenth_of_the_seal_width(default_scene, default_functions):
    """start_problem refuses a start more than 0.1 Ws (300 um) inside a wall and takes one just inside that: y
    beyond the 30 um side clearance presses a groove contact in by about |y| - 30 um (a limit ten times larger
    passed every other test)."""
    from apexseal.runtime.solving.preflight import start_problem

    fns, p = default_functions.sx, default_scene.parameter_vector()
    u = np.array([1e5, 1e5])

    def problem(y: float):
        return start_problem(fns, p, 0.0, np.array([0.0, y, 0.0, 0.0, 0.0, 0.0]), u)

    assert problem(320e-6) is None
    refused = problem(350e-6)
    assert refused is not None and "inside a wall" in refused and "0.1 Ws = 300 µm" in refused


def test_the_start_check_shows_each_state_as_its_scene_key_does():
    """The keys of operation.initial_state, their units and limits, and the unit in which the start check names a
    culprit come from one declaration, the seal body's states (``State.show``, ``State.initial_limit``): the tilt
    reads in deg in both; an entry beyond the seal's (a chamber gas state, which no scene key sets) by its index."""
    import math

    from apexseal.derive.names import STATE_NAMES
    from apexseal.derive.submodels.seal import SealBody
    from apexseal.runtime.scenes.schema import InitialState, validator_of
    from apexseal.runtime.solving.preflight import state_shown

    assert tuple(InitialState.model_fields) == STATE_NAMES
    for i, st in enumerate(SealBody.states):
        field = validator_of(InitialState, st.name)
        assert (field.unit, field.range.ge, field.range.le) == (st.unit, -st.initial_limit, st.initial_limit)
        assert state_shown(i, 0.5).startswith(f"operation.initial_state.{st.name} = ")
        assert state_shown(i, 0.5).endswith(f" {field.show}")
    assert state_shown(STATE_NAMES.index("phi"), math.radians(40)) == "operation.initial_state.phi = 40 deg"
    assert state_shown(len(STATE_NAMES), 1.5) == f"operation.initial_state.[{len(STATE_NAMES)}] = 1.5"


def test_a_guard_declared_closed_at_rest_is_no_penetration_at_the_start():
    """A contact closed at rest by design (a preloaded pad, as the spring) starts deep in its guard: the start check
    reads that from the guard's declaration, as the failure diagnosis does, not from the name "spring" (which
    refused any other such contact)."""
    from types import SimpleNamespace

    from apexseal.derive.submodels import registry
    from apexseal.derive.submodels.base import Guard, Submodel
    from apexseal.runtime.solving.preflight import start_problem

    pad = type("Pad", (Submodel,), {"name": "pad", "__module__": "elsewhere", "guards": (
        Guard("pad", "s_pad", "minus the pad's compression", output="pad_compression", sign=-1,
              closed_label="p", open_label="p0", closed_at_rest=True),)})
    functions = SimpleNamespace(guard_names=("xs5", "pad"), parameter_names=("Ws",),
                                guards=lambda theta, state, params, u: np.array([1e-6, -1e-3]))  # 1 mm > 0.1 Ws
    with registry.registered(pad):
        assert start_problem(functions, np.array([3e-3]), 0.0, np.zeros(6), np.zeros(2)) is None
