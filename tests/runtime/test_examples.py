"""The notebook-style examples of docs/examples run as they are shown in the README."""

from __future__ import annotations

import runpy
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[2] / "docs" / "examples"


@pytest.mark.parametrize("name", ["compare_designs.py"])
def test_example_runs(name, tmp_path, monkeypatch, capfd):
    monkeypatch.setattr(sys, "argv", [name, str(tmp_path)])
    runpy.run_path(str(EXAMPLES / name), run_name="__main__")
    assert (tmp_path / "compare.png").stat().st_size > 0
    assert (tmp_path / "stiff.nc").stat().st_size > 0
    assert (tmp_path / "stiff-spring" / "scene.toml").is_file()
    assert "Event support is experimental" not in capfd.readouterr().err  # CasADi's warning, filtered once


@pytest.mark.slow
def test_leakage_coupling_example_compares_the_two_sources(tmp_path):
    """docs/examples/leakage_coupling.py (the README's table): only the coupled model leaks, and a little."""
    mod = runpy.run_path(str(EXAMPLES / "leakage_coupling.py"))
    chamber, coupled = mod["compare"](tmp_path)
    assert chamber["status"] == coupled["status"] == "completed"
    assert chamber["leaked_mg"] == 0.0 < coupled["leaked_mg"]
    assert 0 < coupled["leaked_fraction"] < 1e-3
    assert (tmp_path / "chamber-leakage" / "scene.toml").is_file()
    assert "| chamber+leakage |" in mod["table"]([chamber, coupled])
