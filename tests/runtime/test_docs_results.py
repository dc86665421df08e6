"""docs/results is the README's "Results on the default scene": the folder `apexseal simulate --out docs/results`
writes, with the model and the default scene of this version."""

from __future__ import annotations

import json
from pathlib import Path

import apexseal
from apexseal.runtime.api import provenance
from apexseal.runtime.results.continuation import continuation
from apexseal.runtime.results.result import SimulationResult

DOCS_RESULTS = Path(__file__).resolve().parents[2] / "docs" / "results"
#: how to bring it up to date (the run replaces the folder: the gas figures of docs/gas.md are restored after it)
REFRESH = ("stale docs/results: run `apexseal simulate --out docs/results` from the repository's root, then "
           "`git checkout docs/results/fig11_pressures_gas.png docs/results/pv_diagram_gas.png`")


def test_docs_results_is_a_run_of_the_current_model_and_default_scene():
    """The folder was last written by a model and a scene form older than the repository's (model hash f007…,
    no contacts.delta_ref, no assumptions.damping_law, parts without the integrator's state), so the README's
    example result could not be continued (`apexseal simulate --resume docs/results -n 2`)."""
    result = SimulationResult.load(DOCS_RESULTS)  # every file of one run
    now = provenance(apexseal.load_scene())
    assert result.status == "completed" and result.info["scene"] == "default"
    assert result.info["model_hash"] == now["model_hash"], REFRESH
    assert result.info["scene_hash"] == now["scene_hash"] == result.scene.content_hash(), REFRESH
    assert continuation(DOCS_RESULTS).revolutions == 1  # the parts hold the state a run continues from
    summary = json.loads((DOCS_RESULTS / "summary.json").read_text())
    assert summary["run_id"] == result.info["run_id"] and summary["samples"] == result.n
