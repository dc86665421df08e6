"""docs/scenes.md documents every key and every solver method.

(That its error table shows the messages the code really gives is checked next to
the cases themselves, in test_scene_validation.py and test_scene_pressure.py.)
"""

from pathlib import Path

import pytest

from apexseal.runtime.scenes.schema import SOLVER_METHODS, key_paths

DOCS = Path(__file__).resolve().parents[2] / "docs" / "scenes.md"


@pytest.fixture(scope="module")
def docs() -> str:
    return DOCS.read_text(encoding="utf-8")


def test_every_key_is_documented(docs):
    missing = [k for k in key_paths() if f"`{k}`" not in docs]
    assert not missing


def test_every_solver_method_is_documented(docs):
    assert all(f'`"{m}"`' in docs for m in SOLVER_METHODS)


def test_key_paths_cover_nested_tables():
    keys = key_paths()
    assert "machine.ports.outlet.width" in keys and "operation.initial_state.phid" in keys
    assert key_paths("friction.") == ["friction.mu1", "friction.mu2", "friction.mus", "friction.v_eps"]


def test_the_keys_an_effect_needs_are_documented_as_such(docs):
    """Each key without a default that an effect reads says, in its row's default column, which effect needs it
    (registry.needing)."""
    from apexseal.derive.submodels.registry import omissible_while_off, parameters

    rows = {line.split(" | ")[0]: line.split(" | ") for line in docs.splitlines()
            if line.startswith("| `") and line.count(" | ") == 5}  # the sections' tables: key, unit, default, ...
    for p in parameters(all_inputs=True):
        if omissible_while_off(p):
            assert rows[f"| `{p.key}`"][2] == f"required while `{omissible_while_off(p)}` is on", p.key
