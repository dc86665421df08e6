"""The notebook-style examples of docs/examples run as they are shown in the README, and so do the code blocks of
the README's "Python API" and of docs/results.md's "Comparing results"."""

from __future__ import annotations

import re
import runpy
import shlex
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


REPO = EXAMPLES.parents[1]


def _block(page: str, heading: str, language: str) -> str:
    """The first ``language`` code block after ``heading`` in ``page`` (relative to the repository)."""
    text = (REPO / page).read_text(encoding="utf-8")
    match = re.search(rf"```{language}\n(.*?)```", text[text.index(heading):], re.S)
    assert match, f"no {language} block after {heading!r} in {page}"
    return match.group(1)


def test_the_readme_python_api_block_runs_as_written(tmp_path, monkeypatch):
    """README, "Python API": the block runs, and ``b`` is the result its comment shows. Only the long run's length
    is cut (50 and 80 revolutions, every sample of each written), to 2 and 3."""
    code = _block("README.md", "## Python API", "python")
    for long, short in (("revolutions=50,", "revolutions=2,"), ("revolutions=80)", "revolutions=3)")):
        assert code.count(long) == 1, long
        code = code.replace(long, short)
    monkeypatch.chdir(tmp_path)
    space: dict = {}
    exec(compile(code, "README.md, Python API", "exec"), space)
    shown = re.search(r"^b +# (SimulationResult\(.*), \.\.\.\)$", code, re.M).group(1)
    assert repr(space["b"]).startswith(shown + ", ")
    assert space["longer"].status == "completed" and space["longer"].revolutions == 3
    assert space["longer"].info["run_id"] == space["long"].info["run_id"]  # continued, one run
    assert [r.status for r in space["runs"]] == ["completed"] * 3
    assert (tmp_path / "stiff.nc").stat().st_size > 0 and (tmp_path / "out" / "stiff" / "scene.toml").is_file()


def test_the_compare_commands_of_docs_results_run_as_written(tmp_path, monkeypatch):
    """docs/results.md, "Comparing results": the three commands, and the difference the page names."""
    from click.testing import CliRunner

    from apexseal.cli import main

    monkeypatch.chdir(tmp_path)
    lines = _block("docs/results.md", "## Comparing results", "bash").splitlines()
    assert len(lines) == 3
    for line in lines:
        words = shlex.split(line)
        assert words[0] == "apexseal"
        r = CliRunner().invoke(main, words[1:])
        assert r.exit_code == 0, r.output
    assert re.search(r"^spring\.ks +5000 N/m +20000 N/m$", r.output, re.M), r.output
    assert "every run: erk, rtol 1e-06" in r.output  # the page: the runs' methods and rtol, and the noise
    assert sorted(p.name for p in (tmp_path / "runs" / "compared").iterdir()) == [
        "comparison.csv", "comparison.png", "noise.csv", "scene-differences.csv"]
