"""``apexseal compare``: result folders side by side, what their scenes differ in and what that did."""

from __future__ import annotations

from pathlib import Path

import click


@click.command()
@click.argument("folders", nargs=-1, required=True, type=click.Path(file_okay=False, exists=True, path_type=Path))
@click.option("--out", "-o", "out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Also write comparison.csv (the numbers), scene-differences.csv and comparison.png (x, y, phi and "
                   "the friction power against crank angle, a line per result) into this folder.")
def compare(folders: tuple[Path, ...], out: Path | None) -> None:
    """Compare the results in FOLDERS (two or more result folders): the scene keys whose values differ, then each
    run's numbers (named as a sweep's quantities, with units) and their change against the first folder's."""
    from .cli_common import writable
    from .runtime.results.compare import compare as compare_results
    from .runtime.results.folder import ResultFolderError

    if len(folders) < 2:
        raise click.UsageError(f"compare needs two or more result folders, got {len(folders)}")
    if out is not None:
        writable(out)  # before reading anything
    try:
        comparison = compare_results(folders)
    except ResultFolderError as err:
        raise click.ClickException(str(err)) from err
    click.echo(comparison.text())
    if out is not None:
        written = comparison.save(out)
        click.echo(f"wrote {', '.join(p.name for p in written)} to {out}/")
