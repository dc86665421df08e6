"""``apexseal sweep``: run a design study (a scene varied over a design of experiments) on all cores or Dask."""

from __future__ import annotations

import importlib.resources
import json
import sys
from pathlib import Path

import click

from .cli_common import Choice, IntRange, writable
from .cores import MAX_WORKERS

EXAMPLES = ("preload-map", "sampling")


def example_path(name: str) -> Path:
    """The shipped example study ``name`` (runtime/studies/sweep/examples/<name>.toml)."""
    res = importlib.resources.files("apexseal.runtime.studies.sweep").joinpath("examples", f"{name}.toml")
    return Path(str(res))


def _quantities(ctx, param, value) -> None:
    if not value or ctx.resilient_parsing:
        return
    from .runtime.results.quantities import quantity_help

    for name, (unit, meaning) in quantity_help().items():
        click.echo(f"{name:24s} {unit:5s} {meaning}")
    ctx.exit()


def _address(ctx, param, value: str | None) -> str | None:
    """A Dask scheduler's address as distributed reads it (scheme://host:port, or host:port for tcp)."""
    if value is None:
        return None
    from distributed.comm import parse_address
    from distributed.comm.addressing import parse_host_port

    try:
        scheme, location = parse_address(value)
        if scheme in ("tcp", "tls", "ws", "wss"):
            parse_host_port(location)
    except ValueError as err:
        raise click.BadParameter(f"{value!r}: {err}; allowed: an address such as tcp://10.0.0.5:8786") from None
    return value


@click.command()
@click.argument("study", required=False, type=click.Path(dir_okay=False, path_type=Path))
@click.option("--example", type=Choice(EXAMPLES), help="Run a study shipped with apexseal instead of STUDY "
              "(preload-map: the design map of the default machine over spring preload and stiffness; sampling: its "
              "energy balance and sampled sums against the output samples per revolution).")
@click.option("--workers", "-w", type=IntRange(1, MAX_WORKERS),
              help="Worker processes of the local Dask cluster [default: every core]; 1 runs serially here.")
@click.option("--scheduler", metavar="ADDRESS", callback=_address,
              help="Address of a running Dask scheduler (e.g. tcp://10.0.0.5:8786) to send the points to.")
@click.option("--out", "-o", "out", type=click.Path(file_okay=False, path_type=Path),
              help="Output folder [default: apexseal-out/<study name>].")
@click.option("--resume/--fresh", default=True, show_default=True,
              help="Keep the points already in --out and compute only the others, or discard them.")
@click.option("--retry-failed", is_flag=True, help="Compute again the points in --out whose rows did not complete "
              "(failed, chattering, error); each row is kept until its new one replaces it.")
@click.option("--figures/--no-figures", default=True, show_default=True, help="Write the figures at the end.")
@click.option("--bench", is_flag=True, help="Measure throughput instead: serial vs every core vs a 2-worker "
              "LocalCluster, each over the whole study (results in temporary folders); writes throughput.md/json.")
@click.option("--repeats", type=IntRange(1, 20), default=3, show_default=True, help="Repeats of --bench.")
@click.option("--list-quantities", is_flag=True, expose_value=False, is_eager=True, callback=_quantities,
              help="List the quantities a study can collect, and exit.")
@click.option("--scene-of", "scene_of", type=IntRange(0), metavar="POINT",
              help="Write the scene of that point (the table's point column) to <out>/point-<POINT>.toml, every value "
              "explicit, instead of running the sweep: `apexseal simulate` of it runs the point alone with every "
              "output a run keeps.")
@click.option("--quiet", "-q", is_flag=True, help="No progress (the models' derivation and compilation stages, the bar).")
def sweep(study, example, workers, scheduler, out, resume, retry_failed, figures, bench, repeats, scene_of,
          quiet) -> None:
    """Run the design study STUDY (a TOML file, docs/sweeps.md): every point simulated, one row each in
    <out>/results.parquet, figures of each quantity and of the feasible region. Rerun to resume."""
    from .runtime.studies.sweep import StudyError, load_study, run_sweep
    from .runtime.studies.sweep.execute import SchedulerError
    from .runtime.studies.sweep.store import StoreError

    if study is not None and example is not None:
        raise click.UsageError(f"give a STUDY file or --example NAME, not both ({study} and --example {example})")
    if study is None and example is None:
        raise click.UsageError("give a STUDY file or --example NAME (e.g. apexseal sweep --example preload-map)")
    if retry_failed and not resume:
        raise click.UsageError("--retry-failed with --fresh: --fresh discards every point in --out, so none is there "
                               "to compute again; give one of them")
    if scheduler and workers:
        raise click.UsageError("--workers sizes the local cluster; with --scheduler the cluster's workers are used")
    path = example_path(example) if example else study
    try:
        st = load_study(path)
    except StudyError as err:
        raise click.ClickException(str(err)) from None
    out = out or Path("apexseal-out") / st.name
    created = not out.exists()  # removed again if a point is refused before anything is written
    writable(out)
    if bench:
        _bench(st, out, repeats)
        return
    if scene_of is not None:
        _write_point_scene(st, out, scene_of)
        return

    def accepted() -> None:  # said once the points are checked and the folder is the study's: not for a refusal
        click.echo(f"study {st.name} ({path if study else f'example {example}'}): {len(st.parameters)} parameters, "
                   f"{st.design} design; writing to {out}/")

    from .signals import StopSignals

    try:
        with StopSignals() as caught:  # the command's: it reports an interruption itself (exit code 128 + signal)
            report = run_sweep(st, out, workers=workers, scheduler=scheduler, resume=resume,
                               retry_failed=retry_failed, quiet=quiet, on_start=accepted)
    except (StudyError, SchedulerError) as err:  # refused before the folder was taken
        if created and not any(out.iterdir()):
            out.rmdir()
        raise click.ClickException(err.describe() if isinstance(err, SchedulerError) else str(err)) from None
    except StoreError as err:
        raise click.ClickException(str(err)) from None
    except OSError as err:  # e.g. no scheduler at the address
        raise click.ClickException(f"cannot run the sweep: {err}") from None
    click.echo(report.describe())
    bad = report.table[report.table["status"] != "completed"]
    for _, row in bad.head(5).iterrows():
        click.echo(f"  point {row['point']}: {row['status']}: {row['stop']}", err=True)
    if len(bad) > 5:
        click.echo(f"  ... {len(bad) - 5} more (see the status and stop columns)", err=True)
    invalid = bad["status"] == "invalid"
    if invalid.any():
        one = invalid.sum() == 1
        click.echo(f"  {int(invalid.sum())} point{'' if one else 's'} invalid: refused at the start for the values of "
                   f"{'its scene' if one else 'their scenes'} (the stop column says which key and the allowed range); "
                   "no retry can change that: change the study's values", err=True)
    budget = bad["stop"].fillna("").str.startswith("wall-time budget used up")
    if budget.any():  # the same budget stops them again: it is the study's to change (its points are kept)
        click.echo(f"  {int(budget.sum())} of them used up their wall-time budget (run.max_wall_time = "
                   f"{st.max_wall_time:g} s): raise it in the study and run it again (its finished points are kept: "
                   "an edited study keeps the points whose scene did not change)", err=True)
    if (~invalid & ~budget).any():
        click.echo("  --retry-failed computes them again (the same command, the other points kept)"
                   + (", the invalid ones excepted" if invalid.any() else ""), err=True)
    warned = report.table[report.table["warnings"].fillna("") != ""] if "warnings" in report.table else bad[:0]
    if len(warned):
        click.echo(f"  {len(warned)} point{'s' if len(warned) != 1 else ''} warned of an implausible run (the warnings "
                   f"column): point{'s' if len(warned) != 1 else ''} "
                   + ", ".join(str(p) for p in warned["point"].head(10)) + (", ..." if len(warned) > 10 else "")
                   + f"; point {warned['point'].iloc[0]}: {warned['warnings'].iloc[0]}", err=True)
    # operation.until_periodic: the points whose run did not become periodic (of those that ran: an empty table of a
    # sweep stopped before its first point said "all 0 points became periodic" of a study that never asked)
    if "periodic" in report.table and report.table["periodic"].notna().any():
        late = report.table[~report.table["periodic"].fillna(False).astype(bool)]
        if len(late):
            click.echo(f"  {len(late)} of {len(report.table)} points did not become periodic (the periodic and "
                       "periodic_change columns; their quantities are their last revolution's): point"
                       f"{'s' if len(late) != 1 else ''} " + ", ".join(str(p) for p in late["point"].head(10))
                       + (", ..." if len(late) > 10 else "") + "; more revolutions (operation.revolutions) or a "
                       "looser operation.periodic_tol", err=True)
        else:
            click.echo(f"  all {len(report.table)} points became periodic (the periodic column)")
    drawing = None
    if figures and not report.table.empty:
        from .runtime.studies.sweep.figures import sweep_figures

        with StopSignals() as drawing:  # a signal while they are drawn is noted: each figure is written whole
            paths = sweep_figures(st, report.table, out)
        click.echo(f"  wrote results.parquet, results.csv and {len(paths)} figures to {out}/")
    if st.constraints and "feasible" in report.table:
        click.echo(f"  feasible ({'; '.join(c.describe() for c in st.constraints)}): "
                   f"{int(report.table['feasible'].sum())} of {len(report.table)} points")
    if report.interrupted:
        click.echo("  interrupted: run the same command again to compute the remaining points", err=True)
        sys.exit(caught.exit_code() or 130)
    if caught.requested:  # after the last point: while the cluster closed or the table was written (both finished)
        click.echo(f"  interrupted by {caught.sender()} once every point was done (the sweep was closing its "
                   "cluster or writing its table, and finished that first): nothing to compute again", err=True)
        sys.exit(caught.exit_code())
    if drawing is not None and drawing.requested:  # every point was done: only the figures were being drawn
        click.echo(f"  interrupted by {drawing.sender()} while the figures were drawn: they were finished first",
                   err=True)
        sys.exit(drawing.exit_code())
    if len(report.table) and not (report.table["status"] == "completed").any():  # a script or CI job sees it
        click.echo(f"  error: none of the {len(report.table)} points completed (exit status 1)", err=True)
        sys.exit(1)


def _write_point_scene(st, out: Path, point: int) -> None:
    """--scene-of: the point's scene as a scene file in ``out`` (its pressure table beside it)."""
    from .runtime.studies.scene_file import write_study_scene
    from .runtime.studies.sweep import point_scene

    try:
        scene = point_scene(st, point)
    except ValueError as err:
        raise click.BadParameter(str(err).replace("point = ", ""), param_hint="--scene-of") from None
    name = f"point-{point}.toml"
    out.mkdir(parents=True, exist_ok=True)
    written, *extra = write_study_scene(out, scene, f"sweep {st.name}, point {point}", None,
                                        f"apexseal simulate {name}", name=name)
    click.echo(f"wrote {written}" + "".join(f" and {f}" for f in extra)
               + f": `apexseal simulate {written}` runs point {point} alone")


def _bench(st, out: Path, repeats: int) -> None:
    from .runtime.studies.sweep.throughput import measure, table

    click.echo(f"throughput of study {st.name}: serial vs every core vs a 2-worker LocalCluster, {repeats} repeats")
    result = measure(st, repeats=repeats, log=lambda m: click.echo(m, err=True))
    text = table(result)
    (out / "throughput.json").write_text(json.dumps(result, indent=2) + "\n")
    (out / "throughput.md").write_text(text + "\n")
    click.echo(text)
    click.echo(f"  wrote throughput.md and throughput.json to {out}/")
