"""``apexseal optimise-preload``: the smallest spring preload that keeps the seal tip on the housing (IPOPT)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import click

from .cli_common import scene_and_folder
from .files import atomic_write

#: the largest min-force accepted (N): far above any contact force of a seal
MAX_FORCE = 1e5


def _force(ctx, param, value) -> float:
    from .runtime.scenes.units import QuantityError, parse_quantity

    try:
        f = parse_quantity(value, "N", key="--min-force")
    except QuantityError as err:
        raise click.BadParameter(f"{value!r}: {err}; allowed: a force > 0 and <= {MAX_FORCE:g} N, e.g. 5N") from None
    if not (0 < f <= MAX_FORCE):
        raise click.BadParameter(f"{value!r} is {f:g} N; allowed: a force > 0 and <= {MAX_FORCE:g} N, e.g. 5N")
    return f


def _windows(ctx, param, values) -> tuple:
    from .runtime.studies.preload.problem import PreloadStudyError, parse_window

    try:
        return tuple(parse_window(v) for v in values)
    except PreloadStudyError as err:
        raise click.BadParameter(str(err).replace("exclude = ", "")) from None


@click.command("optimise-preload")
@click.argument("scene", required=False, type=click.Path(dir_okay=False, path_type=Path))
@click.option("--min-force", default="5 N", show_default=True, callback=_force,
              help="Smallest contact force of the tip on the housing at every check sample (a force, e.g. 5N).")
@click.option("--exclude", "exclude", multiple=True, callback=_windows, metavar="START:END",
              help="Crank-angle window in degrees where the force is not checked (repeatable), e.g. 180:200.")
@click.option("--samples", type=click.IntRange(36, 100000),
              help="Check (output) samples per revolution [default: the scene's samples_per_revolution].")
@click.option("--nodes", type=click.IntRange(2, 64), default=4, show_default=True,
              help="Shooting nodes over the revolution (must divide the samples).")
@click.option("--check/--no-check", "check", default=True, show_default=True,
              help="Also run the derivative-free bisection over full simulations and compare.")
@click.option("--out", "out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Output folder for preload.json [default: apexseal-out/<scene name>].")
def optimise_preload(scene: Path | None, min_force: float, exclude, samples, nodes, check, out) -> None:
    """Find the smallest spring preload delta_s of SCENE (default: the embedded case study) for which the
    seal tip stays pressed on the housing with at least --min-force over the periodic revolution."""
    from .runtime.studies.preload.bisect import bisect_preload
    from .runtime.studies.preload.nlp import optimise_preload as run_study
    from .runtime.studies.preload.problem import MM, PreloadStudyError

    sc, out = scene_and_folder(scene, out)
    click.echo(f"scene {scene or '(embedded default: the paper case study)'}; min force {min_force:g} N; "
               f"writing to {out}/")
    try:
        result = run_study(sc, min_force=min_force, exclude=exclude, nodes=nodes, samples=samples)
    except PreloadStudyError as err:
        raise click.BadParameter(str(err)) from None
    payload = {"scene": str(scene or "default"), "ipopt": result.to_dict()}
    if result.ok and check:
        b = bisect_preload(sc, min_force=min_force, exclude=exclude, samples=result.samples)
        diff = abs(b.delta_s - result.delta_s)
        payload["bisection"] = b.to_dict() | {"difference_m": diff}
    atomic_write(out / "preload.json", json.dumps(payload, indent=2, default=str) + "\n")
    click.echo(result.describe())
    if "bisection" in payload:
        click.echo(f"  bisection over full simulations: delta_s* in [{b.lower / MM:.4f}, {b.delta_s / MM:.4f}] mm "
                   f"({b.simulations} simulations, {b.wall_time_s:.1f} s); IPOPT differs by {diff / MM:.4f} mm")
    click.echo(f"  wrote preload.json to {out}/")
    if not result.ok:
        sys.exit(2)
