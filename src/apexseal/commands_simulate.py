"""``apexseal simulate``: run a scene and write the trajectory, summary.json and the paper's figures."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import click

from .cli_common import scene_and_folder
from .runtime.solving.methods import METHODS


@click.command()
@click.argument("scene", required=False, type=click.Path(dir_okay=False, path_type=Path))
@click.option("--revolutions", "-n", type=click.IntRange(1, 100000), help="Revolutions to simulate (default: the scene's).")
@click.option("--method", type=click.Choice(list(METHODS)), help="Integration method (default: the scene's).")
@click.option("--rtol", type=click.FloatRange(1e-13, 1e-1), help="Relative tolerance (default: the scene's).")
@click.option("--out", "out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Output folder [default: apexseal-out/<scene name>].")
@click.option("--no-figures", is_flag=True, help="Skip the figures.")
@click.option("--quiet", "-q", is_flag=True, help="No progress bar.")
def simulate(scene: Path | None, revolutions, method, rtol, out, no_figures, quiet) -> None:
    """Simulate SCENE (a TOML file; default: the embedded case study of the paper)."""
    from .runtime.api import simulate as run_scene
    from .runtime.results.figures import write_figures
    from .runtime.results.summary import summarise

    sc, out = scene_and_folder(scene, out)
    click.echo(f"scene {scene or '(embedded default: the paper case study)'}; method "
               f"{method or sc.solver.method}; writing to {out}/")
    result = run_scene(sc, revolutions=revolutions, method=method, rtol=rtol, progress=not quiet and sys.stderr.isatty())
    result.save(out)
    summary = summarise(result, {"source": str(scene or "default")})
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    files = ["trajectory.csv", "trajectory.npz", "result.json", "summary.json"]
    if not no_figures and result.n > 1:
        ports = {k: {"angle_deg": v.angle_deg, "width_deg": v.width_deg} for k, v in sc.machine.ports.items()} \
            if getattr(sc.machine, "ports", None) else None
        files += [p.name for p in write_figures(result, out, ports)]
    ext = summary["extremes"]
    click.echo(f"{result.status}: {summary['revolutions']:.2f} revolutions, {summary['events_total']} contact switches, "
               f"wall {result.info['wall_time_s']:.2f} s")
    click.echo(f"  x {ext['x']['min']:.3f}..{ext['x']['max']:.3f} µm, y {ext['y']['min']:.2f}..{ext['y']['max']:.2f} µm, "
               f"phi {ext['phi']['min']:.3f}..{ext['phi']['max']:.3f} mrad; "
               f"friction power {summary['mean_friction_power_W'].get('total', 0.0):.2f} W")
    click.echo(f"  wrote {', '.join(files)} to {out}/")
    if not result.ok:
        click.echo(f"  {result.stop.describe()}", err=True)
        sys.exit(2)
