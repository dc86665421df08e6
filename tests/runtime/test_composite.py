"""The composite run method (runtime/solving/composite.py; its C: generated/templates/apexseal_composite.in.c).

Verified against CasADi's erk: the same switches and converging states on the default scene, on every stress
scene the outcome its own method gives (tests/runtime/test_hard_scenes.py's checks), and the run's limits
(steps, events, budgets, interpreted models) end a call with a named reason.
"""

from __future__ import annotations

import numpy as np
import pytest
from hard_helpers import SAMPLES, SCENES, load, scene_args, simulate
from test_hard_scenes import FAST, OUTCOME, _check

import apexseal

#: x, y in um, phi in mrad
SCALE = np.array([[1e6], [1e6], [1e3]])
#: the stress scenes whose stiff friction (mu N / v_eps) slows explicit steps: the composite's tight phase is RK45,
#: which DOPRI5's stiffness test hands to the exponential step, so it completes both, but in 1.6 million and 0.7
#: million steps (erk stops at its step limit on the first and runs out of the 60 s budget on the second);
#: docs/hard-cases.md: use rosenbrock
STIFF_FRICTION = ("friction-chatter-groove", "stick-slip-spring")


@pytest.fixture(scope="module")
def fns(default_functions):
    """The compiled model library's Functions: the composite runs inside it."""
    assert default_functions.library is not None, "no C compiler: the composite needs the compiled model library"
    return default_functions.c


@pytest.fixture(scope="module")
def reference(default_scene, fns):
    """One revolution of the default scene with erk at rtol 1e-11 (360 samples)."""
    return apexseal.simulate(default_scene, method="erk", rtol=1e-11, functions=fns, samples_per_revolution=SAMPLES)


def _run(scene, fns, rtol, **kw):
    return apexseal.simulate(scene, method="composite", rtol=rtol, functions=fns, samples_per_revolution=SAMPLES, **kw)


def _diff(a, b) -> float:
    return float(np.abs((a.state[:3] - b.state[:3]) * SCALE).max())


def test_composite_agrees_with_erk_and_converges(default_scene, fns, reference):
    """Every switch of erk's reference, with and without the quiet phase, and states that converge to it as rtol
    shrinks."""
    diffs = {}
    for rtol in (1e-7, 1e-9):
        r = _run(default_scene, fns, rtol)
        assert r.status == "completed", r.stop
        np.testing.assert_array_equal(r.events[:, -1], reference.events[:, -1])
        st = r.info["solver_stats"]
        assert st["n_tight_steps"] > 0 and st["n_events"] == reference.events[:, -1].sum()
        assert (st["n_quiet_steps"] > 0) == (rtol >= 1e-8)  # below, RK45 alone with events located more tightly
        assert st["n_rhs"] > 6 * st["n_tight_steps"]  # the statistics count what the C did
        assert r.info["compiled"] and r.info["solver_stats_note"] == ""  # compiled, and its counts are there
        diffs[rtol] = _diff(r, reference)
    assert diffs[1e-9] < 1e-4  # um / mrad (2.9e-7 measured; 5.9e-4 at rtol 1e-7)
    assert diffs[1e-9] < diffs[1e-7] / 10


def test_a_revolution_cut_into_calls_keeps_its_quiet_phase(default_scene, fns, reference):
    """With a wall-time budget the run makes 36 calls of 10 deg: each goes on from the last one's end, so the
    crank angle since the last event carries over (a fresh start would keep every call in the tight phase, whose
    ringing window is 20 deg)."""
    r = _run(default_scene, fns, 1e-8, max_wall_time=600)
    assert r.info["calls_per_revolution"] == 36 and r.info["solver_stats"]["n_engine_calls"] == 36
    assert r.info["solver_stats"]["n_quiet_steps"] > 0
    np.testing.assert_array_equal(r.events[:, -1], reference.events[:, -1])
    assert _diff(r, reference) < 1e-3


def test_steps_at_the_stability_boundary_start_the_quiet_phase_early(default_scene, fns, reference, monkeypatch):
    """RK45 steps that DOPRI5's stiffness test finds near their stability boundary (h |lambda| > STIFF_HLAM, 15 of
    them) hand over to the quiet phase before the 20 deg ringing window ends: a third fewer tight steps at rtol 1e-6,
    the reference's switches, and no larger a difference from it. At a lower threshold (2.0) the count is forgotten
    less often and the handover comes sooner: fewer tight steps."""
    from apexseal.runtime.solving import composite

    with monkeypatch.context() as m:
        m.setattr(composite, "STIFF_STEPS", 0)
        ring_only = _run(default_scene, fns, 1e-6)
    r = _run(default_scene, fns, 1e-6)
    for run in (ring_only, r):
        assert run.status == "completed", run.stop
        np.testing.assert_array_equal(run.events[:, -1], reference.events[:, -1])
    early, late = r.info["solver_stats"], ring_only.info["solver_stats"]
    assert early["n_tight_steps"] < 0.8 * late["n_tight_steps"]
    assert early["n_quiet_steps"] > late["n_quiet_steps"]
    assert early["n_rhs"] < 0.85 * late["n_rhs"]
    assert _diff(r, reference) <= 1.1 * _diff(ring_only, reference)
    with monkeypatch.context() as m:
        m.setattr(composite, "STIFF_HLAM", 2.0)
        sooner = _run(default_scene, fns, 1e-6)
    np.testing.assert_array_equal(sooner.events[:, -1], reference.events[:, -1])
    assert sooner.info["solver_stats"]["n_tight_steps"] < early["n_tight_steps"] < late["n_tight_steps"]


def test_quiet_steps_cross_the_output_grid_between_pressure_rows(default_scene, fns, monkeypatch):
    """The default run's 3600 samples (0.1 deg) between the pressure table's rows (0.5 deg, linear between): the
    quiet steps cross the samples (interpolated there) and end only on the rows, so they are as many as with one
    sample per row; every sample, interpolated ones included, agrees with erk at rtol 1e-11.

    Counted with the quiet phase starting only after the ringing window: the stiffness count that may start it
    earlier counts tight steps, which end at every sample, so the handover point depends on the grid."""
    from apexseal.runtime.solving import composite

    def run(method, rtol, samples):
        return apexseal.simulate(default_scene, method=method, rtol=rtol, functions=fns, revolutions=1,
                                 samples_per_revolution=samples)

    with monkeypatch.context() as m:
        m.setattr(composite, "STIFF_STEPS", 0)
        fine, rows = run("composite", 1e-8, 3600), run("composite", 1e-8, 720)
    assert fine.info["solver_stats"]["n_quiet_steps"] == rows.info["solver_stats"]["n_quiet_steps"] > 0
    assert fine.info["solver_stats"]["n_quiet_steps"] < 3600 / 3  # not one (or more) per sample
    fine = run("composite", 1e-8, 3600)  # the run method's rules
    assert fine.info["solver_stats"]["n_quiet_steps"] < 3600 / 3
    ref = run("erk", 1e-11, 3600)
    np.testing.assert_array_equal(fine.events[:, -1], ref.events[:, -1])
    assert _diff(fine, ref) < 1e-4  # um / mrad (2e-5 measured)


def test_pressures_held_at_interval_means_jump_between_steps(default_scene, fns):
    """solver.pressure = "steps": the pressures jump at every sample; every step ends there and the next interval's
    first step evaluates its own pressures, so the run converges to erk's (measured: 3.6e-6 um at rtol 1e-9)."""
    scene = default_scene.with_overrides(**{"solver.pressure": "steps"})
    ref = apexseal.simulate(scene, method="erk", rtol=1e-11, functions=fns, revolutions=1,
                            samples_per_revolution=SAMPLES)
    r = _run(scene, fns, 1e-9)
    np.testing.assert_array_equal(r.events[:, -1], ref.events[:, -1])
    assert _diff(r, ref) < 1e-4


def test_composite_needs_the_compiled_library(default_scene, default_functions, tmp_path):
    """An interpreted model has no library to run in: the error names the setting and what to do. Asked for with
    interpreted settings (solver.interpreted = true, or compile_c=False) it is refused with them, before the model
    loads and before a folder is made: it was a traceback from the command line, after "writing to ...". """
    from click.testing import CliRunner

    from apexseal.cli import main
    from apexseal.runtime.solving.settings import SettingsError

    with pytest.raises(SettingsError, match="method = \"composite\": runs in the compiled model library.*C compiler"):
        apexseal.simulate(default_scene, method="composite", functions=default_functions.sx, revolutions=1)
    interpreted = default_scene.with_overrides(**{"solver.interpreted": True})
    with pytest.raises(SettingsError, match="interpreted = true: method 'composite' runs only in the compiled model"):
        apexseal.simulate(interpreted, method="composite", revolutions=1)
    with pytest.raises(SettingsError, match="compile_c = false: .*allowed with compile_c = true"):
        apexseal.simulate(default_scene, method="composite", compile_c=False, revolutions=1)
    out = tmp_path / "o"
    r = CliRunner().invoke(main, ["simulate", "--method", "composite", "--set", "solver.interpreted=true", "-n", "1",
                                  "-o", str(out)])
    assert r.exit_code == 2 and "Invalid value for solver.interpreted: method 'composite' runs only" in r.output
    assert "Traceback" not in r.output and not out.exists()
    ran = apexseal.simulate(interpreted.with_overrides(**{"solver.method": "composite"}), compile_c=True,
                            revolutions=1, samples_per_revolution=36, progress=False)  # the keyword decides
    assert ran.ok and ran.info["method"] == "composite" and not ran.scene.solver.interpreted


def test_the_step_limit_ends_a_call_with_its_reason(default_scene, fns):
    r = _run(default_scene, fns, 1e-8, max_steps_per_interval=3)
    assert r.status == "failed" and "step limit" in r.stop.reason and "max_steps_per_interval = 3" in r.stop.reason
    assert np.isfinite(r.state).all()


def test_the_event_limit_inside_a_call_is_chattering(default_scene, fns):
    """More events in one call than the revolution allows: the C stops, the diagnosis names the guard."""
    r = _run(default_scene, fns, 1e-8, max_events_per_revolution=2)
    assert r.status == "chattering", r.stop
    assert "chattering on guard" in r.stop.reason and "max_events_per_revolution = 2" in r.stop.reason


def test_cli_runs_the_composite(tmp_path):
    from click.testing import CliRunner

    from apexseal.cli import main

    out = tmp_path / "run"
    res = CliRunner().invoke(main, ["simulate", "--method", "composite", "--revolutions", "1", "--no-figures", "-q",
                                    "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert '"method": "composite"' in (out / "result.json").read_text()


#: where the composite's revolution ends otherwise than the scene's own method's: the pivoting corner uses 70 % of
#: the chatter limit under erk at rtol 1e-6 and chatters under erk at 1e-8 (docs/hard-cases.md, "Close to the
#: chatter limit"); the composite's steps tip it over too, and it stops as chattering, naming the guard
COMPOSITE_OUTCOME = {**OUTCOME, "pivot-near-chatter": "chattering"}


@pytest.mark.parametrize("name", [s for s in SCENES if s != "friction-chatter-groove"])
def test_stress_scene_ends_as_with_its_own_method(name, fns):
    """A revolution of every stress scene (360 samples, the 60 s budget): the end its own method reaches (or the
    one :data:`COMPOSITE_OUTCOME` names), finite, events bounded, penetrations within the physical bound, modes
    consistent with the gaps."""
    scene = load(name)
    r = simulate(scene, fns, method="composite", compile_c=True, **FAST.get(name, {}))
    _check(name, scene, r, COMPOSITE_OUTCOME.get(name, "completed"))


#: pivot-near-chatter, the slowest of these (10 s), runs in the slow step
@pytest.mark.parametrize("name", [pytest.param(s, marks=pytest.mark.slow) if s == "pivot-near-chatter" else s
                                  for s in SCENES if s not in STIFF_FRICTION + ("tip-chatter",)])
def test_stress_scene_agrees_with_erk_at_the_start(name, fns):
    """The first 20 deg (5 deg of the rattling stiff groove, whose runs part at different tolerances after ~10):
    the same switches as erk at rtol 1e-10 and states within 1000 rtol of the scene's size
    (tests/runtime/test_hard_agreement.py's measure). On grazing-gap the gap b4 reaches 0 with zero rate (its yd
    bisected between a miss and a touch, runtime/scenes/hard/grazing-gap.toml): a touch of b4 may register or not."""
    scene = load(name)
    deg = 5 if name == "stiff-groove-1e9" else 20
    kw = {"revolutions": 1, "compile_c": True, "samples_per_revolution": 360}
    ref = simulate(scene, fns, method="erk", rtol=1e-10, **kw)
    r = simulate(scene, fns, method="composite", rtol=1e-8, **kw)
    k = deg + 1  # samples 0 .. deg (1 deg each)
    A, B = ref.state[:3, :k] * SCALE, r.state[:3, :k] * SCALE
    assert np.abs(A - B).max() < 1e3 * 1e-8 * max(1.0, np.abs(A).max())
    if name == "grazing-gap":  # b4 touches 0 tangentially by design: a touch (two switches) or none, both right
        touch = r.events[:, :k] - ref.events[:, :k]
        assert set(np.unique(touch[4])) <= {0, 1, 2} and not np.delete(touch, 4, axis=0).any(), touch
    else:
        np.testing.assert_array_equal(r.events[:, :k], ref.events[:, :k])


def test_stiff_friction_stops_at_the_step_limit_and_names_rosenbrock(fns):
    """mu2 = 0.9, v_eps = 1 um/s, with 20000 steps per output interval: the explicit tight phase does not pass the
    first stiff stretch, as erk's does not, and the message names rosenbrock."""
    r = simulate(load("friction-chatter-groove"), fns, method="composite", compile_c=True,
                 max_steps_per_interval=20000, calls_per_revolution=72)
    assert r.status == "failed"
    assert "step limit" in r.stop.reason and "rosenbrock" in r.stop.reason
    assert 0 < r.stop.theta < np.radians(30)


@pytest.mark.slow
def test_stiff_friction_completes_and_converges_to_rosenbrock(fns):
    """friction-chatter-groove with the run's limits: the stiffness test hands the stiff friction to the exponential
    step, so the composite completes the revolution (erk stops at its step limit), and its states approach
    rosenbrock's at rtol 1e-9 as rtol shrinks (measured in y: 24 um at rtol 1e-6, 1.6 um at 1e-8, of a 379 um
    range); rosenbrock stays the scene's method (0.10 s against 10.15 s for the composite, docs/hard-cases.md). The
    hard cases' 60 s budget is lifted: a composite run hit it on a 2-core machine running two other suites, and
    what is tested here is convergence, not speed."""
    scene = load("friction-chatter-groove")
    kw = {"revolutions": 1, "compile_c": True, "samples_per_revolution": 360, "max_wall_time": 600}
    ref = simulate(scene, fns, method="rosenbrock", rtol=1e-9, **kw)
    assert ref.status == "completed", ref.stop
    diffs = {}
    for rtol in (1e-6, 1e-8):
        r = simulate(scene, fns, method="composite", rtol=rtol, **kw)
        assert r.status == "completed", r.stop
        assert r.info["solver_stats"]["n_quiet_steps"] > 0
        diffs[rtol] = _diff(r, ref)
    assert diffs[1e-8] < diffs[1e-6] / 3
    assert diffs[1e-8] < 0.01 * float(np.ptp(ref.state[1]) * 1e6)  # um: 1 % of the y range (0.4 % measured)


def test_the_quiet_phase_is_loose_within_its_caps():
    """100x the tolerances (the rate states' 100x more) at tight rtol, never looser than the caps, never tighter than
    the tight phase."""
    from apexseal.runtime.solving.composite import QUIET_CAPS, quiet_factors

    assert quiet_factors(1e-8) == (100.0, 100.0)
    for rtol in (1e-3, 1e-5, 1e-6, 1e-7):
        loose, quiet = quiet_factors(rtol)
        assert loose >= 1 and quiet >= 1
        assert loose * rtol <= max(rtol, QUIET_CAPS[0]) * (1 + 1e-12)
        assert loose * quiet * rtol <= max(rtol, QUIET_CAPS[1]) * (1 + 1e-12)
    assert quiet_factors(1e-3) == (1.0, 1.0)


def test_below_the_quiet_rtol_events_are_located_more_tightly(fns):
    from apexseal.runtime.solving.composite import EVENTS_PER_RTOL, QUIET_RTOL_MIN, CompositeIntegrator

    def engine(rtol):
        return CompositeIntegrator(fns, n_samples=36, span=np.pi / 18, rtol=rtol, event_tol=1e-10)

    assert engine(QUIET_RTOL_MIN).ring < np.inf and engine(QUIET_RTOL_MIN).event_tol == 1e-10
    tight = engine(QUIET_RTOL_MIN / 10)
    assert tight.ring == np.inf and tight.event_tol == pytest.approx(EVENTS_PER_RTOL * QUIET_RTOL_MIN / 10)



def composite_table(stiff_hlam: float | None = None, scenes=SCENES) -> str:
    """The composite's table of docs/hard-cases.md: one revolution of every stress scene (or of ``scenes``; 360
    samples, the 60 s
    budget, compiled model library) with the scene's own method (its integrator compiled) and with the composite at
    the scene's rtol: end, contact switches, wall time; the composite's steps (tight + quiet). ``stiff_hlam``: the
    composite's stiffness threshold instead of its rule's (runtime/solving/composite.py, STIFF_HLAM)."""
    import time
    import warnings

    from apexseal.generated.load import load_functions
    from apexseal.runtime.solving import composite

    warnings.simplefilter("ignore")
    fns = load_functions().c
    if stiff_hlam is not None:
        composite.STIFF_HLAM = stiff_hlam
    rows = ["| scene | own method: end, switches, wall | composite: end, switches, RK45 + exprb32 steps, wall |",
            "|---|---|---|"]
    for name in scenes:
        scene = load(name)
        cells = []
        for method in (scene.solver.method, "composite"):
            t0 = time.perf_counter()
            r = simulate(scene, fns, method=method, compile_c=True)
            wall = time.perf_counter() - t0
            st = r.info["solver_stats"]
            steps = f"{st['n_tight_steps']:,} + {st['n_quiet_steps']:,}, " if "n_tight_steps" in st else ""
            end = r.status if r.ok else f"{r.status} ({r.stop.reason[:60]}…)"
            cells.append(f"{end}, {int(r.events[:, -1].sum())}, {steps}{wall:.2f} s")
        rows.append(f"| {name} | {scene.solver.method}: {cells[0]} | {cells[1]} |")
    return "\n".join(rows)


def stiff_friction_convergence(rtols=(1e-6, 1e-8)) -> str:
    """friction-chatter-groove with the composite at each rtol against rosenbrock at rtol 1e-9: the largest
    difference in x, y (um) and phi (mrad) over the revolution, and the reference's ranges (docs/hard-cases.md)."""
    import warnings

    from apexseal.generated.load import load_functions

    warnings.simplefilter("ignore")
    fns, scene = load_functions().c, load("friction-chatter-groove")
    kw = {"revolutions": 1, "compile_c": True, "samples_per_revolution": 360}
    ref = simulate(scene, fns, method="rosenbrock", rtol=1e-9, **kw)
    lines = [f"reference: rosenbrock at rtol 1e-9, {ref.status}, {int(ref.events[:, -1].sum())} switches; ranges "
             + ", ".join(f"{v:.3g}" for v in np.ptp(ref.state[:3] * SCALE, axis=1)) + " (x, y um; phi mrad)"]
    for rtol in rtols:
        r = simulate(scene, fns, method="composite", rtol=rtol, **kw)
        d = np.abs((r.state[:3] - ref.state[:3]) * SCALE).max(axis=1)
        lines.append(f"composite at rtol {rtol:g}: {r.status}, {int(r.events[:, -1].sum())} switches; largest "
                     "differences " + ", ".join(f"{v:.3g}" for v in d))
    return "\n".join(lines)


if __name__ == "__main__":  # python tests/runtime/test_composite.py [--stiff-hlam H] [scene ...]: hard-cases.md's table
    import sys

    args = sys.argv[1:]
    if "--stiff-hlam" in args:  # the table with another stiffness threshold (no convergence after it)
        i = args.index("--stiff-hlam")
        print(composite_table(float(args[i + 1]), scene_args(args[:i] + args[i + 2:], SCENES)))
        raise SystemExit
    print(composite_table(scenes=scene_args(args, SCENES)))
    if not args or "friction-chatter-groove" in args:
        print()
        print(stiff_friction_convergence())
