"""``apexseal show``: what a result folder holds, and whether ``simulate --resume`` can continue it."""

from __future__ import annotations

from pathlib import Path

import click

from .cli_common import describe_result


@click.command()
@click.argument("folder", type=click.Path(file_okay=False, path_type=Path))
@click.option("--figures", is_flag=True, help="Also draw the figures into FOLDER (a run stopped by a signal or "
              "killed outright has none).")
@click.option("--csv", "csv", is_flag=True, help="Also write trajectory.csv into FOLDER (a run stopped or killed "
              "before writing the one it was asked for has none).")
def show(folder: Path, figures: bool, csv: bool) -> None:
    """Check and describe the result in FOLDER (a result folder, or the OUT.partial-<run id> folder of a killed run):
    the run and its settings, where and why it stopped, the designer's numbers, and how to continue it."""
    from .runtime.api import same_model
    from .runtime.results.continuation import continuation, partial_target
    from .runtime.results.reading import ResultFolderError, read
    from .runtime.results.summary import summarise

    try:
        result = read(folder)
    except ResultFolderError as err:
        raise click.ClickException(str(err)) from err
    info = result.info
    asked = info.get("revolutions_asked", "?")
    click.echo(f"{folder}: run {str(info.get('run_id', '?'))[:12]} of scene {info.get('scene', '?')}; method "
               f"{info.get('method', '?')}, rtol {info.get('rtol', '?')}, {asked} revolution(s) asked")
    for before in info.get("continued", []):
        click.echo(f"  continued after {before['after_revolutions']} revolution(s) of a run {before['status']}")
    describe_result(result, summarise(result, {"source": str(info.get("scene", folder))}))
    if result.stop is not None:
        click.echo(f"  {result.stop.describe()}")
    if _being_written(folder):
        click.echo("  still being written by a run that is going on (its process holds the folder): shown as far as "
                   "it has written it; show it again when the run ends")
        return
    missing = [name for name in info.get("files_asked", ()) if not (folder / name).is_file()]
    if missing and not csv:
        click.echo(f"  {', '.join(missing)} asked for and not written (the run stopped before): `apexseal show "
                   f"{folder} --csv` writes it")
    target = partial_target(folder, str(info.get("run_id", "")))
    if target is not None:
        click.echo(f"  not moved into place at {target} (the run was killed, or kept this result aside so as not to "
                   f"replace the one there)" + (f"; it is complete: rename it to {target} to make it that folder's "
                                                "result" if result.status == "completed" else ""))
    periodic = info.get("periodic") or {}  # operation.until_periodic (runtime/solving/periodicity.py)
    if periodic.get("periodic"):  # more revolutions repeat its last one: no continuation to suggest
        click.echo(f"  stopped because it is periodic (operation.until_periodic) after {periodic['revolution']} of the "
                   f"{asked} revolution(s) asked: more revolutions add nothing (summary.json's last_revolution holds "
                   "its numbers)")
    else:
        try:
            cont = continuation(folder, result)  # its parts were read and checked above
            same_model(cont, None)  # as --resume checks it: the model it was computed with is the current one
        except ResultFolderError as err:
            click.echo(f"  cannot be continued: {err}")
        else:
            if isinstance(asked, int) and asked > cont.revolutions:
                click.echo(f"  continue it after its {cont.revolutions} whole revolution(s): apexseal simulate --resume "
                           f"{folder}")
            else:
                click.echo(f"  more revolutions: apexseal simulate --resume {folder} -n <total>")
    try:
        if csv:
            from .files import atomic_open
            from .runtime.results.csv_table import write_csv

            with atomic_open(folder / "trajectory.csv") as fh:
                write_csv(fh, str(info["run_id"]), result.n, [result], result.guard_names)
            click.echo(f"  wrote trajectory.csv ({result.n} samples) in {folder}/")
        if figures:
            from .runtime.results.figure_job import FigureJob
            from .runtime.results.figures import ports_of

            ports = ports_of(result.scene) if result.scene is not None else None
            drawn = FigureJob(result, folder, ports).start().finish()
            click.echo(f"  drew {', '.join(p.name for p in drawn)} in {folder}/")
    except OSError as err:  # a read-only copy of a result, a full disk: the files already there are untouched
        raise click.ClickException(f"cannot write into {folder}: {err.strerror or err} (each file is written whole "
                                   "or not at all; the result is unchanged): copy the folder somewhere writable "
                                   "and run the command there") from None


def _being_written(folder: Path) -> bool:
    """Whether a run's process holds ``folder`` (the lock a result folder's writer takes, runtime/results/folder.py):
    a run going on, not one killed, whose lock went with its process."""
    import os

    from .files import try_lock_folder

    lock = try_lock_folder(folder)
    if lock is None:
        return True
    os.close(lock)
    return False
