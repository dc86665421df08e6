"""``apexseal calibrate``: fit the contact parameters the paper does not print to the features it reports."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import click

from .cli_common import IntRange, scene_and_folder, scene_label, scene_settings
from .runtime.studies.calibration.fit import COUNTS


@click.command()
@click.argument("scene", required=False, type=click.Path(dir_okay=False, path_type=Path))
@scene_settings
@click.option("--grid", type=IntRange(*COUNTS["grid"][:2]), default=3, show_default=True,
              help="Grid points per unknown (log-spaced over its plausible range).")
@click.option("--polish", type=IntRange(*COUNTS["polish"][:2]), default=20, show_default=True,
              help="Nelder-Mead simulations after the grid (0: none).")
@click.option("--revolutions", "-n", type=IntRange(*COUNTS["revolutions"][:2]), default=2, show_default=True,
              help="Revolutions per simulation; the last one is analysed.")
@click.option("--out", "-o", "out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Output folder for calibration.json [default: apexseal-out/<scene name>-calibration].")
@click.option("--quiet", "-q", is_flag=True, help="No line per simulation on stderr.")
def calibrate(scene: Path | None, sets, grid, polish, revolutions, out, quiet) -> None:
    """Fit kw, kg (kg1..kg4), zeta_w and zeta_g of SCENE (default: the embedded case study) within their plausible
    ranges to the paper's Fig. 14 main peak and the crank angle of the largest x (Fig. 12a), and say which
    features no plausible set matches and why. Ctrl-C or SIGTERM stops it: the simulations completed are written
    (exit code 130 or 143)."""
    from .files import atomic_write
    from .runtime.studies.calibration import CalibrationError
    from .runtime.studies.calibration import calibrate as run_study
    from .runtime.studies.calibration.fit import CalibrationInterrupted

    sc, out = scene_and_folder(scene, out, sets, "calibration")
    click.echo(f"{scene_label(scene, sets)}; grid {grid}, polish {polish}, "
               f"{revolutions} revolutions per simulation; writing to {out}/")
    say = None if quiet else (lambda line: click.echo(line, err=True))
    from .signals import StopSignals

    try:
        with StopSignals():  # the command's: it writes what was completed and exits with 128 + the signal itself
            result = run_study(sc, grid=grid, polish=polish, revolutions=revolutions, progress=say)
    except CalibrationInterrupted as err:
        click.echo(str(err), err=True)
        sys.exit(err.exit_code)
    except CalibrationError as err:
        raise click.BadParameter(str(err)) from None
    atomic_write(out / "calibration.json", json.dumps(result.to_dict(), indent=2) + "\n")
    click.echo(result.describe())
    click.echo(f"  wrote calibration.json to {out}/")
    if result.exit_code:
        sys.exit(result.exit_code)
