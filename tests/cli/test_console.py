"""The ``apexseal`` console script: main(), then the collector frozen for Python's exit."""

from __future__ import annotations

import gc
import importlib.metadata
import subprocess

import pytest

from apexseal import cli


def test_the_installed_script_is_the_console_function():
    scripts = importlib.metadata.entry_points(group="console_scripts")
    assert scripts["apexseal"].value == "apexseal.cli:console"


def test_python_dash_m_apexseal_is_the_command_under_its_name():
    import sys

    run = subprocess.run([sys.executable, "-m", "apexseal", "simulate", "--help"], capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 0, run.stderr
    assert run.stdout.startswith("Usage: apexseal simulate [OPTIONS] [SCENE]")


@pytest.mark.parametrize("code", [0, 2])
def test_console_freezes_the_collector_after_main_whatever_its_exit(monkeypatch, code):
    calls = []

    def main(**kwargs):
        calls.append("main")
        raise SystemExit(code)  # click's main ends the process this way, success or not

    monkeypatch.setattr(cli, "main", main)
    monkeypatch.setattr(gc, "freeze", lambda: calls.append("freeze"))
    with pytest.raises(SystemExit) as ended:
        cli.console()
    assert ended.value.code == code and calls == ["main", "freeze"]


def test_the_command_line_of_a_subprocess_runs_the_console_script():
    proc = subprocess.run(cli.command("--version"), capture_output=True, text=True, check=False)
    assert proc.returncode == 0 and "version" in proc.stdout
    proc = subprocess.run(cli.command("simulate", "--rtol", "1"), capture_output=True, text=True, check=False)
    assert proc.returncode == 2 and "--rtol" in proc.stderr  # a bad option: click's exit code, through console()
