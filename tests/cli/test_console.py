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

    class Main:
        def main(self, **kwargs):
            calls.append("main")
            raise SystemExit(code)  # sys.exit in a command

    monkeypatch.setattr(cli, "main", Main())
    monkeypatch.setattr(gc, "freeze", lambda: calls.append("freeze"))
    with pytest.raises(SystemExit) as ended:
        cli.console()
    assert ended.value.code == code and calls == ["main", "freeze"]


def test_ctrl_c_before_a_run_catches_it_exits_with_130(monkeypatch, capsys):
    """Ctrl-C while the command imports, reads the scene or compiles (before the run's own handling): exit code
    130 as for a run it stops, not click's 1 ("Aborted!")."""
    import apexseal.commands_simulate as simulate

    def interrupted(*args):
        raise KeyboardInterrupt

    monkeypatch.setattr(simulate, "_simulate", interrupted)
    monkeypatch.setattr("sys.argv", ["apexseal", "simulate"])
    monkeypatch.setattr(gc, "freeze", lambda: None)
    with pytest.raises(SystemExit) as ended:
        cli.console()
    assert ended.value.code == cli.INTERRUPTED == 130 and "Aborted (Ctrl-C)" in capsys.readouterr().err


def test_a_reader_that_stops_reading_ends_the_command_quietly(tmp_path):
    """`apexseal scene --resolved | head -1`: a broken pipe ends the command with no traceback."""
    proc = subprocess.Popen(cli.command("scene", "--resolved"), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            cwd=tmp_path)
    proc.stdout.close()  # the reader is gone before the command writes
    stderr = proc.stderr.read().decode()
    proc.stderr.close()
    assert proc.wait(timeout=120) in (0, 1) and "Traceback" not in stderr, stderr


def test_the_default_scene_piped_writes_nothing_here_and_redirected_writes_its_table(tmp_path):
    """`apexseal scene --default | less` wrote the scene's pressure table into the current folder, unasked: a pipe
    (or a terminal) reads the scene, it does not keep it. Redirected to a file (`> my.toml`), the table is still
    written beside it, so the file loads."""
    piped = subprocess.run(cli.command("scene", "--default"), capture_output=True, text=True, cwd=tmp_path,
                           check=False)
    assert piped.returncode == 0 and piped.stdout.startswith("# apexseal default scene")
    assert list(tmp_path.iterdir()) == [] and "not written here" in piped.stderr and "--out FOLDER" in piped.stderr
    with open(tmp_path / "my.toml", "w") as file:
        kept = subprocess.run(cli.command("scene", "--default"), stdout=file, stderr=subprocess.PIPE, text=True,
                              cwd=tmp_path, check=False)
    assert kept.returncode == 0 and (tmp_path / "expander-pressure.csv").exists(), kept.stderr


def test_the_command_line_of_a_subprocess_runs_the_console_script():
    proc = subprocess.run(cli.command("--version"), capture_output=True, text=True, check=False)
    assert proc.returncode == 0 and "version" in proc.stdout
    proc = subprocess.run(cli.command("simulate", "--rtol", "1"), capture_output=True, text=True, check=False)
    assert proc.returncode == 2 and "--rtol" in proc.stderr  # a bad option: click's exit code, through console()


#: long option -> the short form it has on every command that takes it (-h for --help comes from the group's
#: context settings, and click caches each command's help option, so it is not read here)
SHORT_FORMS = {"--out": "-o", "--quiet": "-q", "--revolutions": "-n"}


@pytest.mark.parametrize("name", sorted(cli.COMMANDS))
def test_every_command_spells_the_shared_options_alike(name):
    """A user who typed ``-o`` for one command's output folder can type it for every command's."""
    import click

    group = click.Context(cli.main, info_name="apexseal", **cli.main.context_settings)
    command = cli.main.get_command(group, name)
    ctx = click.Context(command, info_name=name, parent=group)
    options = [p for p in command.get_params(ctx) if isinstance(p, click.Option)]
    for option in options:
        for long_form, short in SHORT_FORMS.items():
            if long_form in option.opts:
                assert short in option.opts, f"apexseal {name} {long_form} has no {short}"
    shorts = [o for option in options for o in option.opts if not o.startswith("--")]
    assert len(shorts) == len(set(shorts)), f"apexseal {name}: a short option used twice: {shorts}"


def test_a_warning_reads_as_a_message_not_a_source_line():
    """A plausibility warning printed Python's `<file>.py:<line>: PlausibilityWarning: ...` and the source line."""
    proc = subprocess.run(cli.command("scene", "--set", "spring.delta_s=2.0"), capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.startswith("warning: scene default: spring.delta_s = 2.0: 2000 mm is far outside")
    assert proc.stderr.rstrip().endswith("(PlausibilityWarning)") and ".py:" not in proc.stderr, proc.stderr
