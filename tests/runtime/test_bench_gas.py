"""apexseal bench's table of what the gas states cost (runtime/bench/gas_cost.py). No timing is asserted (the machine
is shared): what is checked is that the three pressure sources run on one machine, interleaved, and that the table
shows what the gas states add."""

from __future__ import annotations

import pytest

from apexseal.runtime.bench.config import full, quick
from apexseal.runtime.bench.gas_cost import VARIANTS, gas_md, gas_scenes


def test_the_full_benchmark_times_the_gas_states_and_the_quick_one_on_request():
    assert full().gas_revolutions > 0 and quick().gas_revolutions == 0
    assert quick().restricted(gas=True).gas_revolutions > 0
    assert full().restricted(gas=False).gas_revolutions == 0


def test_the_three_variants_differ_only_in_the_pressure_source():
    scenes = gas_scenes()
    assert [label for label, _ in VARIANTS] == list(scenes) == ["table", "chamber", "chamber+leakage"]
    table, chamber, leak = scenes.values()
    assert table.pressure.kind == "table"
    assert (chamber.assumptions.pressure_model, leak.assumptions.pressure_model) == ("chamber", "chamber+leakage")
    for s in (chamber, leak):
        for section in ("machine", "seal", "spring", "contacts", "friction", "solver"):
            assert s.to_dict()[section] == table.to_dict()[section], section


@pytest.mark.slow
def test_gas_cost_runs_interleaved_and_fills_its_table():
    from apexseal.runtime.bench.gas_cost import gas_cost

    g = gas_cost(revolutions=1, repeats=2, log=lambda _: None)
    v = g["variants"]
    assert list(v) == ["table", "chamber", "chamber+leakage"]
    assert v["table"]["states"] == 6 and v["chamber"]["states"] == v["chamber+leakage"]["states"] == 10
    assert v["table"]["rhs_instructions"] < v["chamber"]["rhs_instructions"] < v["chamber+leakage"]["rhs_instructions"]
    for x in v.values():
        assert x["status"] == "completed" and len(x["cpu_s"]) == len(x["integrate_s"]) == 2
        assert x["rhs_evaluations"] > x["steps"] > 0 and x["integrate_per_rev_s"] > 0
    assert v["table"]["integrate_ratio"] == 1.0
    md = "\n".join(gas_md(g))
    assert "| chamber+leakage | 10 |" in md and "interleaved" in md
