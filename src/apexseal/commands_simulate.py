"""``apexseal simulate``: run a scene and write its result folder (parts, result.json, summary.json, figures)."""

from __future__ import annotations

import sys
import warnings
from pathlib import Path
from typing import NoReturn

import click

from .cli_common import (
    Choice,
    Setting,
    default_folder,
    describe_result,
    result_folder,
    scene_label,
    scene_of,
    scene_settings,
)
from .runtime.solving.methods import METHODS
from .stopwatch import Stopwatch

#: run setting -> the option that sets it (a bad value is reported against the option)
OPTIONS = {"revolutions": "--revolutions", "method": "--method", "rtol": "--rtol", "max_wall_time": "--max-wall-time",
           "interpreted": "solver.interpreted"}


@click.command()
@click.argument("scene", required=False, type=click.Path(dir_okay=False, path_type=Path))
@scene_settings
@click.option("--revolutions", "-n", type=Setting("revolutions", int),
              help="Revolutions to simulate (default: the scene's; 1 to 100000).")
@click.option("--method", type=Choice(list(METHODS)), help="Integration method (default: the scene's).")
@click.option("--rtol", type=Setting("rtol", float), help="Relative tolerance (default: the scene's; 1e-12 to 0.01).")
@click.option("--max-wall-time", type=Setting("max_wall_time", float), metavar="SECONDS",
              help="Wall-time budget: past it the run stops and keeps the revolutions done, as Ctrl-C does; it "
                   "counts from the run's start, a first use's compilation included (above "
                   "0, at most 1e7 s; each revolution is then cut into 36 integrator calls, written into the result's "
                   "scene.toml).")
@click.option("--out", "-o", "out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Output folder [default: apexseal-out/<scene name>].")
@click.option("--resume", "resume", type=click.Path(file_okay=False, path_type=Path), default=None,
              metavar="FOLDER",
              help="Continue the run of the result FOLDER (interrupted, failed, or a killed run's "
                   "OUT.partial-<run id>) after its last whole revolution, with its scene and settings, up to the "
                   "revolutions it was asked for or --revolutions; the same samples as a run never stopped.")
@click.option("--csv", "csv", is_flag=True, help="Also write trajectory.csv (text; slower than the binary parts; --resume "
              "writes it again, whole, when the folder it continues held one).")
@click.option("--no-figures", is_flag=True, help="Skip the figures (recorded: --resume draws none either).")
@click.option("--quiet", "-q", is_flag=True,
              help="No progress (stages, compilation times, the revolutions' bar; in a log, a line every 10 s).")
@click.option("--timings", is_flag=True, help="Print where the wall time went (startup, import, scene, load, compile, "
              "integrate, assemble, save, figures).")
def simulate(scene: Path | None, sets, revolutions, method, rtol, max_wall_time, out, resume, csv, no_figures,
             quiet, timings) -> None:
    """Simulate SCENE (a TOML file; default: the embedded case study of the paper; a result folder's scene.toml
    re-runs that result).

    Revolutions are written to disk as they finish; the folder is written beside OUT and renamed into place at
    the end. SIGINT (Ctrl-C) and SIGTERM stop the run between integrator calls, and the revolutions completed
    are written as a result with status "interrupted" (exit code 130 or 143). A run killed outright leaves its
    folder as OUT.partial-<run id>, which `SimulationResult.load` reads as an interrupted result; `--resume`
    continues any of them.
    """
    from . import progress

    with progress.enabled(not quiet):  # derivation, code generation and compilations report on stderr
        _simulate(scene, sets, revolutions, method, rtol, max_wall_time, out, resume, csv, no_figures, quiet, timings)


def _simulate(scene, sets, revolutions, method, rtol, max_wall_time, out, resume, csv, no_figures, quiet,
              timings) -> None:
    watch = Stopwatch()  # stages always timed (two clock reads each), printed with --timings
    with watch.stage("import"):  # light: matplotlib is imported by the worker
        from .runtime.results.figure_worker import FigureWorker
    no_figures = no_figures or (resume is not None and _declined_figures(resume))

    # a second process imports matplotlib while this one imports, reads the scene and integrates; stopped unless the
    # result is handed to it
    with FigureWorker.started(not no_figures) as worker:
        with watch.stage("import"):
            from .runtime.api import model_functions, run_scene, same_model
            from .runtime.results.figure_job import FigureJob
            from .runtime.results.figures import force_panels, ports_of
            from .runtime.results.folder import ResultFolder, ResultFolderError, ResultStorageError
            from .runtime.results.gas import GasCycleWarning
            from .runtime.results.liftoff import LiftOffWarning
            from .runtime.results.plausibility import FlankWarning, PenetrationWarning
            from .runtime.results.summary import summarise  # noqa: F401  (timed here; used by _save)
            from .runtime.solving.accuracy import AccuracyWarning
            from .runtime.solving.near_chatter import NearChatterWarning
            from .signals import StopSignals

            if timings:  # imported by the load stage anyway; up front, so that the split shows what importing costs
                import casadi  # noqa: F401

        with watch.stage("scene"):
            sc, settings, out, cont = _what_runs(scene, sets, revolutions, method, rtol, max_wall_time, out, resume)
        source = str(scene or "default") if cont is None else str(cont.record["info"].get("scene", resume))
        csv = csv or (cont is not None and ((cont.source / "trajectory.csv").is_file()  # asked for by the run resumed
                                            or "trajectory.csv" in cont.record["info"].get("files_asked", ())))
        if cont is not None:
            click.echo(f"continuing {resume} after {cont.revolutions} revolution(s), up to {settings.revolutions}; "
                       f"method {settings.method}; writing to {out}/")
        else:
            click.echo(f"{scene_label(scene, sets)}; method {settings.method}; writing to {out}/")
        with StopSignals() as signals:  # a second signal during the writing is noted, not raised
            try:
                with watch.stage("load"):
                    functions = _load_abandoned_on_signal(model_functions, sc, signals)
                    if worker is not None and functions is not None:  # it builds the figures' frames meanwhile
                        worker.prepare(force_panels(functions.output_names), ports_of(sc))
                if signals.requested:  # while the model was derived or compiled: no run to keep
                    _stopped_before_the_run(signals)
                with watch.stage("run"):
                    try:
                        if cont is not None:
                            same_model(cont, functions)
                        writer = ResultFolder(out) if cont is None else ResultFolder.continuing(cont)
                        writer.asked = ("trajectory.csv",) if csv else ()
                        writer.no_figures = no_figures
                    except ResultFolderError as err:
                        raise click.BadParameter(str(err), param_hint="--resume") from err
                    with warnings.catch_warnings():  # the plausibility and accuracy checks: printed below, with the summary
                        warnings.simplefilter("ignore", PenetrationWarning)
                        warnings.simplefilter("ignore", FlankWarning)
                        warnings.simplefilter("ignore", LiftOffWarning)
                        warnings.simplefilter("ignore", GasCycleWarning)
                        warnings.simplefilter("ignore", AccuracyWarning)
                        warnings.simplefilter("ignore", NearChatterWarning)
                        try:
                            with writer.discarded_if_empty():  # a crash, a full disk at the first revolution: no
                                result = run_scene(sc, settings, progress=not quiet, sink=writer,  # empty folder
                                                   functions=functions, continuation=cont)
                        except KeyboardInterrupt:  # the integrator's compilation abandoned: no step was taken
                            if not signals.requested:
                                raise
                            _stopped_before_the_run(signals, writer, resumed=cont is not None)
                watch.split("run", result.info.get("timings_s", {}))
                figures = None
                if not no_figures and result.n > 1 and not signals.requested:
                    with watch.stage("figures"):  # other processes draw while this one writes the result
                        figures = (FigureJob(result, writer.staging, ports_of(sc)).start() if worker is None else
                                   worker.submit(result, writer.staging, ports_of(sc)))
                elif worker is not None:  # stopped here, where a further Ctrl-C is still only noted
                    worker.cancel()
                figures_skipped = not no_figures and result.n > 1 and signals.requested  # said below, with the folder
                try:
                    summary, files = _save(watch, writer, result, source, csv)
                except BaseException:
                    if figures is not None:
                        figures.cancel()
                    raise
                if figures is not None:
                    with watch.stage("figures"), _said(result.n, "finishing the figures"):
                        files += [p.name for p in figures.finish()]
                with watch.stage("save"):
                    where = writer.commit()
                if signals.requested:  # the process ends with 128 + signal: a further Ctrl-C changes nothing
                    signals.ignore_after()
            except ResultStorageError as err:
                raise click.ClickException(str(err)) from err
        _report(result, summary, files, out, where, writer.kept_aside, timings, watch, signals, figures_skipped)


def _what_runs(scene, sets, revolutions, method, rtol, max_wall_time, out, resume):
    """The scene, the run's settings and output folder, and the run it continues (``--resume``; else None), checked
    before any work: a bad value is reported against its option."""
    from .runtime.api import continuing, settings_of
    from .runtime.results.folder import ResultFolderError
    from .runtime.solving.settings import SettingsError

    try:
        if resume is None:
            sc = scene_of(scene, sets)
            settings = settings_of(sc, revolutions=revolutions, method=method, rtol=rtol, max_wall_time=max_wall_time)
            out = default_folder(scene, out)
            result_folder(out)
            return sc, settings, out, None
        given = [n for n, v in (("SCENE", scene), ("--set", sets), ("--method", method), ("--rtol", rtol),
                                ("--out", out)) if v]
        if given:
            raise click.UsageError(f"--resume continues a run with its own scene, settings and folder; "
                                   f"{', '.join(given)} cannot change them")
        cont, settings = continuing(resume, revolutions=revolutions, max_wall_time=max_wall_time)
        return cont.scene, settings, cont.target, cont
    except SettingsError as err:
        key = err.errors[0].key
        raise click.BadParameter("\n".join(p.message for p in err.errors), param_hint=OPTIONS.get(key, key)) from err
    except ResultFolderError as err:
        raise click.BadParameter(str(err), param_hint="--resume") from err


def _said(samples: int, what: str):
    """A progress stage on stderr for work on a result of that many samples when it is long (seconds after the
    revolutions' bar: runtime/solving/run.py, LONG_RESULT), else nothing."""
    import contextlib

    from .progress import stage
    from .runtime.solving.run import LONG_RESULT

    return stage(what) if samples >= LONG_RESULT else contextlib.nullcontext()


def _declined_figures(folder: Path) -> bool:
    """Whether the run of the result ``folder`` was asked for no figures (``--no-figures``, recorded in its
    result.json): its continuation draws none either. False where the record cannot be read (--resume says why)."""
    from .runtime.results.folder import figures_declined
    from .runtime.results.reading import ResultFolderError, read_record

    try:
        return figures_declined(read_record(folder)["info"])
    except (ResultFolderError, OSError, KeyError, TypeError):
        return False


def _save(watch, writer, result, source: str, csv) -> tuple[dict, list[str]]:
    """summary.json and, on request, trajectory.csv (result.json and the parts are written by the run)."""
    from .runtime.results.summary import summarise

    with watch.stage("save"), _said(result.n, f"summarising {result.n:,} samples"):
        summary = summarise(result, {"source": source})
        writer.write_json("summary.json", summary)
        files = ["result.json", f"parts/ ({len(writer.parts)} files)", "scene.toml", "summary.json"]
        if (writer.staging / "pressure.csv").is_file():
            files.insert(3, "pressure.csv")
        if csv:
            from .progress import stage

            with stage(f"writing trajectory.csv ({writer.samples} samples)"):
                writer.write_csv()
            files.append("trajectory.csv")
    return summary, files


def _stopped_before_the_run(signals, writer=None, *, resumed: bool = False) -> NoReturn:
    """Exit as a signal asks before the run's first step: the folder begun for it removed (a resumed result stays
    as it was), nothing written."""
    if writer is not None and resumed:
        writer.release()
    elif writer is not None:
        writer.abandon()
    click.echo(f"  interrupted by {signals.sender()} before the run started: nothing written", err=True)
    sys.exit(signals.exit_code())


def _load_abandoned_on_signal(model_functions, scene, signals):
    """The scene's model functions, or None when a signal abandoned their derivation, generation or compilation
    where it was (:meth:`StopSignals.abandoning`: nothing is computed yet, the caches are written atomically, a
    compiler is killed and its build folder swept by the next build)."""
    try:
        return model_functions(scene)
    except KeyboardInterrupt:
        if not signals.requested:  # not one of ours: an interrupt raised by other means
            raise
        return None


def _report(result, summary, files, out, where, kept_aside, timings, watch, signals, figures_skipped) -> None:
    """What the run gave, on the console (and where the time went, with --timings); exit code of a failed run.
    ``where``: the folder the result is in, ``kept_aside``: why it is not ``out`` (ResultFolder.commit) or "";
    ``figures_skipped``: the figures were not drawn because a signal came."""
    describe_result(result, summary)
    click.echo(f"  wrote {', '.join(files)} to {where}/")
    if kept_aside:
        click.echo(f"  {kept_aside}; this run's result is in {where}/", err=True)
    if figures_skipped:
        click.echo(f"  figures not drawn (a signal came): apexseal show {where} --figures draws them", err=True)
    out = where
    if timings:
        click.echo(watch.report())
    if not result.ok:
        click.echo(f"  {result.stop.describe()}", err=True)
        if result.status == "interrupted" and result.revolutions >= 1:  # a whole revolution to continue from
            click.echo(f"  continue it: apexseal simulate --resume {out}", err=True)
        sys.exit(signals.exit_code() or 2)
    if signals.requested:  # came while the completed run was saved or drawn: said, and the exit code says it too
        click.echo(f"  interrupted by {signals.sender()} after the run completed: its result is whole", err=True)
        sys.exit(signals.exit_code())
