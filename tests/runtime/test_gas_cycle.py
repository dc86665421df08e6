"""The chamber gas model's scope: expanders. A compressor's design runs with it and is warned of."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import pytest

import apexseal
from apexseal.runtime.results.gas import GasCycleWarning, expander_cycle
from apexseal.runtime.results.summary import summarise
from apexseal.runtime.scenes.units import PlausibilityWarning

SCENE = "runtime/scenes/expander-gas.toml"
#: a compressor's design on the expander's ports: suction 1.013 bar at the inlet, delivery 6 bar at the outlet
COMPRESSOR = {"gas.p_supply": "1.013e5 Pa", "gas.p_exhaust": "6e5 Pa"}


def _run(**over):
    """One revolution of the expander-gas scene at 1 deg output: the run, its warnings and its summary.json's
    content (what `apexseal simulate` writes there)."""
    scene = apexseal.load_scene(Path(__file__).parents[2] / SCENE)
    scene = scene.with_overrides(**{"solver.samples_per_revolution": 360, **over})
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = apexseal.simulate(scene, revolutions=1)
    return result, caught, json.loads(json.dumps(summarise(result)))


@pytest.mark.slow  # 13 s of a 2-core test process: in the second step, to keep the default suite under 10 min
def test_a_compressor_design_on_the_gas_model_is_warned_of_once_and_recorded():
    """A compressor's pressures (supply below exhaust) on the gas model, which has fixed ports and no valves, gave a
    negative inducted mass (gas pushed back out through the inlet) and negative indicated work without a word: the run
    warns once with the numbers and the remedy (a pressure table), and summary.json records it in gas.expander_cycle."""
    result, caught, summary = _run(**COMPRESSOR)
    said = [w for w in caught if issubclass(w.category, GasCycleWarning)]
    assert len(said) == 1, [str(w.message) for w in caught]
    assert issubclass(GasCycleWarning, PlausibilityWarning)  # a sweep point's row records it
    gas = summary["gas"]
    assert gas["inducted_mass_kg"] < 0 and gas["indicated_work_J"]["total"] < 0
    assert gas["expander_cycle"] == {"ok": False, "negative_inducted_mass": True, "work_into_gas": True}
    text = str(said[0].message)
    assert (f"inducted mass is {gas['inducted_mass_kg'] * 1e3:.4g} g and the indicated work "
            f"{gas['indicated_work_J']['total']:.4g} J") in text, text
    for part in ("not an expander's", "no valves", "expanders only", 'pressure.source = "table"', "pressure.file"):
        assert part in text, part


def test_the_expander_gas_scene_is_an_expanders_cycle():
    """The example expander's cycle is not flagged: gas in at the inlet, work out on the rotor, no warning."""
    result, caught, summary = _run()
    assert not [w for w in caught if issubclass(w.category, GasCycleWarning)]
    assert summary["gas"]["expander_cycle"] == {"ok": True, "negative_inducted_mass": False, "work_into_gas": False}
    assert summary["gas"]["inducted_mass_kg"] > 0 and summary["gas"]["indicated_work_J"]["total"] > 0


@pytest.mark.parametrize(("inducted", "work", "ported", "ok"), [
    (1e-3, 10.0, True, True), (-1e-3, 10.0, True, False), (1e-3, -10.0, True, False),
    (0.0, -1e-3, False, True)])  # closed ports: the leakage's loss alone, no cycle of either kind
def test_the_expander_check_reads_both_signs(inducted, work, ported, ok):
    assert expander_cycle(inducted, work, ported=ported)["ok"] is ok


def test_the_console_prints_the_warning_from_the_summary(capsys):
    """`apexseal simulate` silences the run's warnings and prints them with its summary; `show` reads them from
    there too: the gas cycle's warning is printed once, on stderr."""
    from apexseal.cli_common import describe_result

    result, _, _ = _run(**COMPRESSOR)
    describe_result(result, summarise(result))
    err = capsys.readouterr().err
    assert err.count("not an expander's") == 1, err


def test_the_run_s_checks_are_computed_once_for_its_warnings_and_its_summary(monkeypatch):
    """run_scene computed the lift-off and the gas cycle (and the penetrations and mouth corners) for its warnings,
    and summarise computed them all again from every sample when the run was saved. They are kept with the result
    (runtime/results/checked.py): the summary holds the very objects the warnings were made from, computing
    nothing again."""
    import apexseal.runtime.results.checked as module

    scene = apexseal.load_scene(Path(__file__).parents[2] / SCENE)
    result = apexseal.simulate(scene.with_overrides(**{"solver.samples_per_revolution": 360}), revolutions=1)
    kept = module.checked(result)

    def again(*args, **kwargs):
        raise AssertionError("computed again")

    for name in ("liftoff", "gas_summary", "penetration_check", "flank_check"):
        monkeypatch.setattr(module, name, again)
    summary = summarise(result)
    assert summary["gas"] is kept.gas and summary["liftoff"] is kept.liftoff
    assert summary["plausibility"] is kept.plausibility and summary["flank"] is kept.flank
    assert kept.gas is not None and kept.liftoff is not None
