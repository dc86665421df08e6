"""``apexseal calibrate``: fit the contact parameters the paper does not print to the features it reports."""

from __future__ import annotations

import math
import shlex
import sys
from pathlib import Path

import click

from .cli_common import IntRange, default_folder, remove_made, report_target, scene_label, scene_of, scene_settings
from .runtime.studies.calibration.fit import COUNTS


def _unknowns(ctx: click.Context, param: click.Parameter, items: tuple[str, ...]):
    """``--unknown NAME=LOW:HIGH`` given, in order, as the study's ranges (None: the default ones); the names and
    ranges are checked by the study, with the same messages as the API's."""
    if not items:
        return None
    ranges: dict[str, tuple[float, float]] = {}
    for item in items:
        name, _, bounds = item.partition("=")
        low, _, high = bounds.partition(":")
        name = name.strip()
        if name in ranges:
            raise click.BadParameter(f"{name} given twice: allowed: each unknown once", ctx, param)
        try:
            ranges[name] = (float(low), float(high))
            if not all(map(math.isfinite, ranges[name])):
                raise ValueError
        except ValueError:
            raise click.BadParameter(f"{item!r}: allowed: NAME=LOW:HIGH with finite numbers in SI units, e.g. "
                                     "kw=1e9:5e9 (N/m) or zeta_w=0.05:0.2 (a damping ratio)", ctx, param) from None
    return ranges


@click.command()
@click.argument("scene", required=False, type=click.Path(dir_okay=False, path_type=Path))
@scene_settings
@click.option("--unknown", "unknowns", multiple=True, callback=_unknowns, metavar="NAME=LOW:HIGH",
              help="Fit NAME (kw, kg, zeta_w or zeta_g) within LOW..HIGH, in SI units (N/m; a damping ratio), inside "
                   "its plausible range; repeat for each unknown, and only those given are fitted [default: all four "
                   "over their plausible ranges, less a damping ratio whose damping is off].")
@click.option("--grid", type=IntRange(*COUNTS["grid"][:2]), default=3, show_default=True,
              help="Grid points per unknown (log-spaced over its range).")
@click.option("--polish", type=IntRange(*COUNTS["polish"][:2]), default=20, show_default=True,
              help="Nelder-Mead simulations after the grid (0: none).")
@click.option("--revolutions", "-n", type=IntRange(*COUNTS["revolutions"][:2]), default=2, show_default=True,
              help="Revolutions per simulation; the last one is analysed.")
@click.option("--out", "-o", "out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Output folder for calibration.json, scene.toml and pressure.csv, written beside it and renamed into "
                   "place as a whole [default: apexseal-out/<scene name>-calibration].")
@click.option("--quiet", "-q", is_flag=True, help="No line per simulation on stderr.")
def calibrate(scene: Path | None, sets, unknowns, grid, polish, revolutions, out, quiet) -> None:
    """Fit kw, kg (kg1..kg4), zeta_w and zeta_g of SCENE (default: the embedded case study) within their plausible
    ranges (or the unknowns and ranges of --unknown) to the paper's Fig. 14 main peak and the crank angle of the
    largest x (Fig. 12a), and say which features no plausible set matches and why. Ctrl-C or SIGTERM stops it: the
    simulations completed are written (exit code 130 or 143), beside a completed report in the folder rather than
    over it."""
    from .runtime.results.folder import ResultStorageError
    from .runtime.studies.calibration import CalibrationError
    from .runtime.studies.calibration import calibrate as run_study
    from .runtime.studies.calibration.fit import CalibrationInterrupted
    from .runtime.studies.calibration.report import SCENE_FILE, report_folder, rerun_line, save_report, simulate_line
    from .signals import StopSignals

    sc = scene_of(scene, sets)
    out = default_folder(scene, out, "calibration")
    folder, made = report_target(out, report_folder)  # a folder of other files is never replaced
    fitted = "" if unknowns is None else "; unknowns " + ", ".join(f"{n} {lo:g}..{hi:g}" for n, (lo, hi) in
                                                                  unknowns.items())
    click.echo(f"{scene_label(scene, sets)}{fitted}; grid {grid}, polish {polish}, "
               f"{revolutions} revolutions per simulation; writing to {out}/")
    say = None if quiet else (lambda line: click.echo(line, err=True))
    try:
        # the command's: a signal stops the study, whose simulations completed are written whole (a further signal
        # is only noted meanwhile), and the command exits with 128 + the signal itself
        with StopSignals() as signals:
            try:
                result = run_study(sc, ranges=unknowns, grid=grid, polish=polish, revolutions=revolutions, progress=say,
                                   run_id=folder.run_id)
            except CalibrationInterrupted as err:
                click.echo(str(err), err=True)
                signals.ignore_after()
                sys.exit(err.exit_code)
            except CalibrationError as err:  # an unknown or its range (--unknown), or the scene's effects
                raise click.BadParameter(str(err), param_hint="--unknown" if unknowns else None) from None
            where = save_report(result, out, folder)
            if signals.requested:
                signals.ignore_after()
    except ResultStorageError as err:
        raise click.ClickException(str(err)) from err
    finally:  # nothing reported (interrupted before a candidate completed, refused): no empty folder left behind
        remove_made(made)
    click.echo(result.describe())
    click.echo(f"  wrote calibration.json and {SCENE_FILE} to {where}/ (run {result.run_id[:12]})")
    if folder.kept_aside:
        click.echo(f"  {folder.kept_aside}; this calibration's report is in {where}/", err=True)
    scene_file = shlex.quote(str(where / SCENE_FILE))
    click.echo(f"  re-run: {rerun_line(result, scene_file)}")
    click.echo(f"  simulate the best set: {simulate_line(result, scene_file)}")
    if result.exit_code:
        sys.exit(result.exit_code)
