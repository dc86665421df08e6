"""``apexseal compare``: result folders side by side, what their scenes differ in and what that did."""

from __future__ import annotations

from pathlib import Path

import click


@click.command()
@click.argument("folders", nargs=-1, required=True, type=click.Path(file_okay=False, exists=True, path_type=Path))
@click.option("--out", "-o", "out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Also write comparison.csv (the numbers), scene-differences.csv, comparison.png (x, y, phi and "
                   "the friction power against crank angle, a line per result) and noise.csv (each number's noise, "
                   "measured with --noise, else estimated from the run's tolerance) into this folder.")
@click.option("--noise", "rerun", is_flag=True,
              help="Measure the numerical noise of every number: re-run the first folder's scene at a tenth of its "
                   "rtol (as long as its run; into OUT/noise-rerun with --out) and take its change. Without it, the "
                   "noise is estimated from each run's rtol.")
@click.option("--noise-from", "noise_from", type=click.Path(file_okay=False, exists=True, path_type=Path),
              default=None, help="Measure the noise from this re-run of the first folder's scene at a tighter rtol "
                                 "(e.g. the noise-rerun folder an earlier --noise --out wrote), without running.")
def compare(folders: tuple[Path, ...], out: Path | None, rerun: bool, noise_from: Path | None) -> None:
    """Compare the results in FOLDERS (two or more result folders): the scene keys whose values differ, then each
    run's numbers (named as a sweep's quantities, with units) and their change against the first folder's, with
    the numerical noise of each: a change within it (marked ~) is not an effect of what the runs differ in."""
    from .cli_common import writable
    from .runtime.results.compare import compare as compare_results
    from .runtime.results.folder import ResultFolderError, not_into_a_result
    from .runtime.results.noise import rerun as rerun_first
    from .runtime.results.result import SimulationResult

    if len(folders) < 2:
        raise click.UsageError(f"compare needs two or more result folders, got {len(folders)}")
    if rerun and noise_from is not None:
        raise click.UsageError("--noise and --noise-from: give one (--noise runs, --noise-from reads a re-run)")
    if out is not None:
        try:
            not_into_a_result(out, "the comparison's files")
        except ResultFolderError as err:
            raise click.BadParameter(str(err), param_hint="--out") from None
        writable(out)  # before reading anything
    try:
        noise = noise_from
        if rerun:
            first = SimulationResult.load(folders[0])
            click.echo(f"re-running {folders[0]} at rtol {first.info.get('rtol', 1e-6) / 10:g} for its noise"
                       + ("" if out is not None else " (not kept: --out keeps it)"), err=True)
            noise = rerun_first(first, out=None if out is None else out / "noise-rerun", progress=True)
        comparison = compare_results(folders, noise=noise)
    except ResultFolderError as err:
        raise click.ClickException(str(err)) from err
    except ValueError as err:
        raise click.ClickException(str(err)) from err
    click.echo(comparison.text())
    if out is not None:
        written = comparison.save(out)
        click.echo(f"wrote {', '.join(p.name for p in written)} to {out}/")
