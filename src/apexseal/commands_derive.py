"""``apexseal derive``: run the symbolic derivation (cached) and check it against the paper."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import click

from .cli_common import scene_label, scene_of, scene_settings, writable


@click.command()
@click.argument("scene", required=False, type=click.Path(dir_okay=False, path_type=Path))
@scene_settings
@click.option("--check", is_flag=True, help="Compare every derived equation of the paper's full model, at the default "
              "scene's values whatever SCENE and --set say, with the paper's print and write the report.")
@click.option("--report", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Where --check writes its Markdown report [default: apexseal-out/paper-check.md].")
@click.option("--refresh", is_flag=True, help="Ignore the derivation cache.")
@click.option("--quiet", "-q", is_flag=True, help="No progress on stderr: only the results.")
def derive(scene: Path | None, sets, check: bool, report: Path | None, refresh: bool, quiet: bool) -> None:
    """Derive the equations of motion for SCENE's effects (default: the paper's case study), timing cold and warm."""
    from . import progress
    from .derive.cache import cached_model

    if report is not None and not check:
        raise click.UsageError("--report names where --check writes its report: give it with --check")
    report = report or Path("apexseal-out") / "paper-check.md"
    sc = scene_of(scene, sets)
    if check:
        writable(report.parent, "--report")
    t0 = time.perf_counter()
    with progress.enabled(not quiet), progress.stage("deriving the equations of motion (sympy)"):
        model = cached_model(sc.effects, sc.assumptions, refresh=refresh)
    t1 = time.perf_counter()
    cached_model(sc.effects, sc.assumptions)
    t2 = time.perf_counter()
    click.echo(f"derived: {len(model.guards)} contact guards, {len(model.outputs)} outputs, "
               f"effects: {', '.join(sc.effects.on())}")
    click.echo(f"time: first call {t1 - t0:.2f} s{' (cold, --refresh)' if refresh else ''}, cached call {t2 - t1:.3f} s")
    if check:
        from .derive.paper_check import main_check

        checking = "checking every derived equation against the paper's print (sympy)"
        with progress.enabled(not quiet), progress.stage(checking):
            code = main_check(report, echo=click.echo)
        if scene is not None or sets:
            click.echo(f"  (of the paper's full model at the default scene's values: the effects, modelling choices and "
                       f"values of {scene_label(scene, sets)} do not enter the check)")
        if code:
            sys.exit(code)
