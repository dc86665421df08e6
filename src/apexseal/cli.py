"""The ``apexseal`` command: one sub-command per job, each in its own module.

A sub-command's module is imported only when that command runs (or ``--help`` lists them all), so that
``apexseal simulate`` does not pay for the imports of ``bench``, ``sweep`` or ``generate``. The console script is
:func:`console`: :func:`main`, then an exit that spares Python's cyclic collector its last pass.
"""

from __future__ import annotations

import gc
import importlib
import sys
import warnings

import click

#: command name -> "module:function" of its click command (modules of this package)
COMMANDS = {
    "simulate": "commands_simulate:simulate",
    "scene": "commands_scene:scene",
    "show": "commands_show:show",
    "compare": "commands_compare:compare",
    "derive": "commands_derive:derive",
    "generate": "commands_generate:generate",
    "optimise-preload": "commands_optimise:optimise_preload",
    "bench": "commands_bench:bench",
    "sweep": "commands_sweep:sweep",
    "calibrate": "commands_calibrate:calibrate",
}


class LazyGroup(click.Group):
    """A group whose commands are imported on first use (click's documented lazy-loading pattern)."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted({*COMMANDS, *self.commands})

    def get_command(self, ctx: click.Context, name: str) -> click.Command | None:
        if name not in self.commands and name in COMMANDS:
            module, attr = COMMANDS[name].split(":")
            self.add_command(getattr(importlib.import_module(f"{__package__}.{module}"), attr), name)
        return self.commands.get(name)

    def invoke(self, ctx: click.Context):
        from .derive.submodels.registry import RegistryError
        from .files import CacheError, TemporaryFolderError
        from .signals import command_scope

        exiting = bool((ctx.obj or {}).get(EXITING))
        try:  # a command a signal stopped heeds no further one as the process exits; from Python, they come back
            with command_scope(exiting=exiting):
                return super().invoke(ctx)
        except RegistryError as err:  # a submodel that cannot load, clashes, or whose laws are refused: it is named
            raise click.ClickException(str(err)) from None
        except (CacheError, TemporaryFolderError) as err:  # a cache or TMPDIR that cannot be written: folder, cause
            raise click.ClickException(str(err)) from None


#: key of the context's ``obj``: the command runs in the console script, whose process exits with its code
EXITING = "apexseal.exiting"


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="apexseal")
def main() -> None:
    """Derive, generate and run the apex-seal model of limaçon machines (Phung et al. 2018)."""


#: exit code of a command stopped by Ctrl-C (128 + SIGINT), whenever the signal lands
INTERRUPTED = 130


def show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A warning as the command's user reads it, ``warning: <message> (<kind>)`` on stderr: not Python's
    ``<source file>:<line>: <kind>: <message>`` and the source line that warned."""
    click.echo(f"warning: {message} ({category.__name__})", err=True)


def console() -> None:
    """The ``apexseal`` console script: :func:`main` (which ends the process with its exit code), and before the
    interpreter exits, ``gc.freeze()``. Python's shutdown otherwise runs the cyclic garbage collector over every
    object of the process (a run holds about 200 000: 45 of its 55 ms of exit, docs/performance.md); frozen, they
    are freed with the process. Everything the command writes is closed and on disk by then. In-process callers
    (click's test runner, a notebook) call :func:`main`, which does not freeze anything."""
    warnings.showwarning = show_warning
    try:
        code = main.main(prog_name="apexseal", standalone_mode=False, obj={EXITING: True})
    except click.exceptions.Abort:  # Ctrl-C before a run catches it (imports, the scene, a compilation)
        click.echo("Aborted (Ctrl-C)", err=True)
        code = INTERRUPTED
    except click.ClickException as err:  # what standalone mode does with them
        err.show()
        code = err.exit_code
    except BrokenPipeError:  # the output piped into a reader that stopped (`| head`), as standalone mode ends
        sys.stdout = None  # nothing more to flush at exit
        code = 1
    finally:
        gc.freeze()
    sys.exit(code if isinstance(code, int) else 0)


def command(*args: str) -> list[str]:
    """``apexseal ARGS`` as a subprocess runs it with this interpreter: the console script's function (timing
    tools and tests start the command this way, so that they measure and check what users run)."""
    return [sys.executable, "-c", "from apexseal.cli import console; console()", *args]
