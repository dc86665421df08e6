"""``apexseal optimise-preload``: the preload (constant, or a schedule over the revolution) that costs least friction
while the seal tip stays on the housing (IPOPT)."""

from __future__ import annotations

import contextlib
import sys
from pathlib import Path

import click

from .cli_common import Choice, default_folder, remove_made, report_target, scene_label, scene_of, scene_settings
from .runtime.studies.preload.options import DEFAULTS, OBJECTIVES, default_text


def _checked(ctx, param, value):
    """An option converted and range-checked by the study's own check (study.check_option: the API's, with its
    message naming the option, its value and the allowed range); None where not given (the API's default is then
    the option's own default, from runtime/studies/preload/options.py)."""
    from .runtime.studies.preload.problem import MAX_KNOTS, PreloadStudyError
    from .runtime.studies.preload.study import check_option

    name = param.name
    if value is None:
        return DEFAULTS.get(name)
    if name == "max_rate":  # a bare number is in mm per degree on the command line (m per degree from Python)
        value = value if any(c.isalpha() for c in value) else f"{value} mm/deg"
    elif name in ("knots", "nodes", "samples", "max_iter"):
        value = _parsed(value, int)
    elif name in ("deficit_tol", "min_force", "max_groove_force", "max_preload"):  # a bare number: in the SI unit
        value = _parsed(value, float)
    # the study's range, 1..MAX_KNOTS, holds the constant preload, which is no schedule: refused in the command's
    # own range (0 was refused as "must be in 1..72", and then 1 as "a schedule has KNOTS >= 2"); the rest as the
    # study refuses it, in the same words as the API
    if name == "knots" and isinstance(value, int) and value < 2:
        raise click.BadParameter(f"knots = {value!r}: must be an integer in 2..{MAX_KNOTS} (a schedule; 1 knot is the "
                                 "constant preload, which the study always optimises)")
    try:
        value = check_option(name, value, knots=ctx.params.get("knots") if name == "max_rate" else None)
    except PreloadStudyError as err:
        raise click.BadParameter(str(err)) from None
    return value


def _parsed(text: str, kind: type):
    """A bare number's text as ``kind`` (int or float); anything else as it is: a quantity's text ("5 N") for the
    study to convert, or what its check refuses."""
    try:
        return kind(text)
    except ValueError:
        return text


def _windows(ctx, param, values) -> tuple:
    from .runtime.studies.preload.problem import PreloadStudyError, parse_window, windows

    try:
        return windows(tuple(parse_window(v) for v in values))
    except PreloadStudyError as err:
        raise click.BadParameter(str(err).replace("exclude = ", "")) from None


@contextlib.contextmanager
def _kept(results: dict, key: str):
    """A study stage whose interruption keeps, as ``results[key]``, what the study held when a signal stopped it, as
    ``apexseal.optimise_preload`` returns it from Python (study.py, ``_kept_on_interrupt``): IPOPT's answer where the
    signal landed during its re-simulation (``ipopt_knots``), its best feasible iterate where it landed during its
    iterations (``best_feasible``). The schedule's result is kept whatever it holds (the report holds the constant
    optimum, and says the schedule was stopped before it had one), the constant optimum's where it holds a preload
    (``has_answer``): without one there is nothing to report."""
    try:
        yield
    except BaseException as err:
        kept = getattr(err, "preload_result", None)
        if kept is not None and (key != "constant" or kept.has_answer):
            results[key] = kept
        raise


@click.command("optimise-preload")
@click.argument("scene", required=False, type=click.Path(dir_okay=False, path_type=Path))
@scene_settings
@click.option("--min-force", default=default_text("min_force"), show_default=True, callback=_checked, metavar="FORCE",
              help="Smallest contact force of the tip on the housing, everywhere outside --exclude (a force, e.g. 5N; "
                   "a bare number is in N).")
@click.option("--max-groove-force", default=None, callback=_checked, metavar="FORCE",
              help="Bound on every seal-groove contact force (Eq. 63), everywhere on the revolution, between samples "
                   "too (a force, e.g. 400N; a bare number is in N) [default: none].")
@click.option("--exclude", "exclude", multiple=True, callback=_windows, metavar="START:END",
              help="Crank-angle window in degrees where the force is not required (repeatable, up to 4), e.g. 180:200; "
                   "angles are taken modulo 360, so 350:10 crosses 0 and 200:180 leaves only 180-200 required.")
@click.option("--schedule", "knots", default=None, callback=_checked, metavar="KNOTS", is_eager=True,
              help="Also optimise a periodic piecewise-linear preload schedule with KNOTS knots, started from the "
                   "constant optimum.")
@click.option("--max-rate", default=None, callback=_checked, metavar="MM_PER_DEG",
              help="Bound on |d delta_s / d theta| of the schedule in mm per degree (a bare number), or a rate "
                   "such as 0.01mm/deg [default: none].")
@click.option("--deficit-tol", default=None, callback=_checked, metavar="N2_RAD",
              help="Bound of the squared force deficit int max(0, min_force - F)^2 dtheta, in N^2 rad: how far the "
                   "force may fall short of --min-force [default: (0.2 N)^2 x 0.1 deg = 6.98e-5].")
@click.option("--max-preload", default=default_text("max_preload"), show_default=True, callback=_checked,
              metavar="LENGTH",
              help="Upper bound of the preload delta_s searched (a length, e.g. 150mm; a bare number is in m).")
@click.option("--max-iter", default=str(DEFAULTS["max_iter"]), show_default=True, callback=_checked, metavar="N",
              help="IPOPT's iterations per solve.")
@click.option("--objective", type=Choice(OBJECTIVES), default=DEFAULTS["objective"], show_default=True,
              callback=_checked,
              help="Minimise the cycle-mean friction power, or the (mean) preload.")
@click.option("--samples", callback=_checked, metavar="N",
              help="Output samples per revolution [default: the scene's samples_per_revolution].")
@click.option("--nodes", default=str(DEFAULTS["nodes"]), show_default=True, callback=_checked, metavar="N",
              help="Shooting nodes over the revolution (with the knots, their least common multiple must divide "
                   "the samples).")
@click.option("--vary-stiffness", is_flag=True,
              help="Also re-simulate the constant optimum's spring force ks*delta_s at 0.25-4 x the scene's ks: the "
                   "design over (delta_s, ks) together is the curve ks*delta_s = optimal force (docs/preload.md).")
@click.option("--check/--no-check", "check", default=True, show_default=True,
              help="Also run the derivative-free bisection of the constant preload over full simulations.")
@click.option("--out", "-o", "out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Output folder for preload.json, preload.md, preload.png, scene.toml, pressure.csv and, with "
                   "--schedule, schedule.toml, written beside it and renamed into place as a whole [default: "
                   "apexseal-out/<scene name>-preload].")
@click.option("--quiet", "-q", is_flag=True, help="No progress (stages, compilation times, IPOPT iterations).")
def optimise_preload(scene: Path | None, sets, min_force: float, max_groove_force, exclude, knots, max_rate,
                     deficit_tol, max_preload, max_iter, objective, samples, nodes, vary_stiffness, check, out,
                     quiet) -> None:
    """Optimise the spring preload delta_s of SCENE (default: the embedded case study): the least friction power
    (or preload) for which the seal tip stays pressed on the housing with at least --min-force everywhere on the
    periodic revolution (between samples too), as a constant and, with --schedule, as a schedule delta_s(theta)."""
    from . import progress

    if max_rate is not None and knots is None:
        raise click.UsageError("--max-rate bounds the slope of a schedule: give it with --schedule KNOTS")
    with progress.enabled(not quiet):  # generation, compilation (elapsed time) and IPOPT iterations on stderr
        _optimise(scene, sets, min_force, max_groove_force, exclude, knots, max_rate, objective, samples, nodes,
                  vary_stiffness, check, out, {"max_preload": max_preload, "max_iter": max_iter,
                                                               "deficit_tol": deficit_tol})


def _optimise(scene, sets, min_force, max_groove_force, exclude, knots, max_rate, objective, samples, nodes,
              vary_stiffness, check, out, limits) -> None:
    """The stages in turn (constant optimum, schedule, bisection, stiffness valley), then the report. SIGINT or
    SIGTERM abandons the stage in progress wherever it is (IPOPT included) and writes the report of the stages
    completed before it, with the reason; exit code 130 or 143.

    The report is written as a result folder is (runtime/results/folder.py, ReportFolder): after each stage but the
    last, whole, into ``<out>.partial-<run id>`` beside the output folder (what a study killed outright leaves), and
    at the end renamed to ``<out>``, replacing the report there as a whole; a report of a study that did not
    complete (a signal, a stage refused) stays in ``<out>.partial-<run id>`` when ``<out>`` holds a completed one."""
    from .runtime.results.folder import ResultStorageError
    from .runtime.studies.preload.problem import PreloadSetup, PreloadStudyError, check_grid, check_request, excluded
    from .runtime.studies.preload.report import report_folder, report_status, study_options, write_report
    from .signals import StopSignals
    from .stopwatch import Stopwatch

    sc = scene_of(scene, sets)
    try:
        check_grid(samples or sc.solver.samples_per_revolution, nodes, knots or 1)
    except PreloadStudyError as err:
        raise click.BadParameter(str(err), param_hint="--samples, --nodes, --schedule") from None
    try:  # what the study cannot answer, before a model is built or a folder made
        check_request(sc, min_force, samples, PreloadSetup.revolutions, max_groove_force)
    except PreloadStudyError as err:
        raise click.BadParameter(str(err)) from None
    out = default_folder(scene, out, "preload")
    folder, made = report_target(out, report_folder)  # a folder of other files is never replaced
    bound = f"; groove forces <= {max_groove_force:g} N" if max_groove_force is not None else ""
    click.echo(f"{scene_label(scene, sets)}; min force {min_force:g} N"
               f"{excluded(exclude)}{bound}; writing to {out}/")
    watch = Stopwatch()
    done = {"results": {"constant": None}, "bisection": None, "valley": None, "stage": "set-up"}
    options = study_options(min_force, max_groove_force, exclude, knots, objective,
                            samples or sc.solver.samples_per_revolution, nodes) \
        | {"max_rate_m_per_deg": max_rate, "vary_stiffness": vary_stiffness, "check": check,
           "max_preload_m": limits["max_preload"], "max_iter": limits["max_iter"],
           "deficit_tol_N2_rad": limits["deficit_tol"]}

    def report(stopped: str, status: str, unchanged: bool = False) -> list:
        """``unchanged``: the stages' results are those of the report in ``<out>.partial-<run id>`` (a checkpoint of
        the bisection's probes): its figure and scene files are copied, not drawn again."""
        return folder.write(lambda into: write_report(
            into, sc, str(scene or "default"), done["results"], done["bisection"], min_force, done["valley"], stopped,
            overrides=sets, options=options, run_id=folder.run_id, status=status,
            unchanged_from=folder.staging if unchanged else None))

    where = None
    try:
        with StopSignals(raising=True) as signals:

            def checkpoint(words: str, following: str, unchanged: bool = False) -> None:
                """The report of the stages done so far, written whole after each into ``<out>.partial-<run id>`` (a
                killed study leaves it there) as the ``following`` stage begins (a signal meanwhile stops that
                stage); ``unchanged``: as :func:`report`'s (the bisection's rounds of probes)."""
                done["stage"] = following
                signals.raising = False
                report(f"written after the {words}, while the study went on (a study killed then leaves this report "
                       f"in {folder.staging.name}, beside {out.name}; one that goes on replaces it)", "interrupted",
                       unchanged)
                signals.raising = True
                if signals.requested:
                    raise KeyboardInterrupt

            try:
                _stages(sc, done, watch, signals, checkpoint, min_force, max_groove_force, exclude, knots, max_rate,
                        objective, samples, nodes, vary_stiffness, check, limits)
            except PreloadStudyError as err:  # a stage refused: the stages before it are reported as they ended
                if done["results"]["constant"] is not None:
                    signals.raising = False
                    status, stopped = report_status(done["results"], stage=done["stage"], refused=str(err))
                    report(stopped, status)
                    where = folder.commit(status)
                else:
                    folder.abandon()
                raise click.BadParameter(str(err)) from None
            except BaseException:  # a signal surfaces as whatever the call it landed in made of it
                if not signals.requested:
                    raise
            signals.raising = False  # the report is written whole; a further signal is only noted
            results = done["results"]
            c = results["constant"]
            status, stopped = report_status(results, interrupted_by=signals.sender() if signals.requested else "",
                                            stage=done["stage"])
            if signals.requested:
                kept = "the report holds the stages before it" if c is not None else "nothing to report"
                if done["bisection"] is not None and not done["bisection"].complete:
                    kept += f" and the bisection's {done['bisection'].simulations} simulations so far"
                click.echo(f"  {stopped}: {kept}", err=True)
                signals.ignore_after()
            if c is not None:
                paths = report(stopped, status)
                where = folder.commit(status)
                click.echo(f"  wrote {', '.join(p.name for p in paths)} to {where}/; wall time "
                           + ", ".join(f"{k} {v:.1f} s" for k, v in watch.stages.items()))
            else:
                folder.abandon()
    except ResultStorageError as err:
        raise click.ClickException(str(err)) from err
    finally:  # nothing reported (interrupted early, refused, failed): no empty folder left behind, parents included
        remove_made(made)
        if where is not None and folder.kept_aside:
            click.echo(f"  {folder.kept_aside}; this study's report is in {where}/", err=True)
    if signals.requested:
        sys.exit(signals.exit_code())
    if status == "failed":  # IPOPT did not reach the constant optimum or the schedule
        sys.exit(2)


def _stages(sc, done, watch, signals, checkpoint, min_force, max_groove_force, exclude, knots, max_rate, objective,
            samples, nodes, vary_stiffness, check, limits) -> None:
    """Run the study's stages, each one's result kept in ``done`` once it completed (a signal that IPOPT turned into
    a failure is raised again after it, so that the stage is not kept) and written (``checkpoint``) but for the
    last, whose report the caller writes. The schedule and the stiffness valley start from the constant optimum;
    the bisection needs only the feasible start, so it runs where IPOPT found no constant optimum too (its answer
    is then the study's only one for a constant preload). ``limits``: max_preload, max_iter and deficit_tol of the
    NLPs (deficit_tol the bisection's too)."""
    from .runtime.api import model_functions
    from .runtime.studies.preload.advice import bisection_caveat
    from .runtime.studies.preload.bisect import bisect_preload
    from .runtime.studies.preload.problem import MM, PreloadSetup
    from .runtime.studies.preload.report import saved_friction_power
    from .runtime.studies.preload.study import optimise_preload as run_study

    def finished(value):
        if signals.requested:
            raise KeyboardInterrupt
        return value

    def stage(name: str, words: str):
        done["stage"] = words
        return watch.stage(name)

    results = done["results"]
    setup = PreloadSetup(sc, model_functions(sc), min_force, tuple(exclude), samples, max_groove_force=max_groove_force)
    with stage("constant", "constant optimum"), _kept(results, "constant"):
        c = results["constant"] = finished(run_study(sc, min_force=min_force, exclude=exclude, nodes=nodes,
                                                     objective=objective, setup=setup, **limits))
    feasible = c.start_delta_s is not None  # a preload that meets the requirement: what the bisection starts from
    plan = [w for w, on in (("schedule", knots and c.ok), ("bisection", check and feasible),
                            ("stiffness valley", vary_stiffness and c.ok)) if on]

    def ended(text: str, words: str, following: str | None) -> None:
        """A stage's result printed and, before a ``following`` stage, written (``checkpoint``). A signal is said
        to stop the following stage from before the print on: one sent on seeing the result stopped the stage that
        had ended, by its name, when it landed before the checkpoint named the next."""
        if following:
            done["stage"] = following
        click.echo(text)
        if following:
            checkpoint(words, following)

    ended(c.describe(), "constant optimum", plan[0] if plan else None)
    if knots and c.ok:
        with stage("schedule", "schedule"), _kept(results, "schedule"):
            results["schedule"] = finished(run_study(sc, min_force=min_force, exclude=exclude, nodes=nodes,
                                                     knots=knots, objective=objective, max_rate=max_rate, start=c,
                                                     setup=setup, **limits))
        ended(results["schedule"].describe(), "schedule", plan[1] if plan[-1] != "schedule" else None)
    if "bisection" in plan:

        def probed(so_far) -> None:  # each round's probes kept in the report, and written as the constant optimum is
            done["bisection"] = so_far
            checkpoint(f"bisection's {so_far.simulations} simulations so far", "bisection", unchanged=True)

        with stage("bisection", "bisection"):
            b = done["bisection"] = finished(bisect_preload(sc, min_force=min_force, exclude=exclude, setup=setup,
                                                            nodes=nodes, upper=c.start_delta_s,
                                                            max_preload=limits["max_preload"], progress=probed,
                                                            deficit_tol=limits["deficit_tol"]))
        against = (f"the constant optimum above ({c.delta_s / MM:.4f} mm) differs by "
                   f"{abs(b.delta_s - c.delta_s) / MM:.4f} mm" if c.ok else
                   "IPOPT found no constant optimum (above): this is the study's answer for a constant preload")
        caveat = bisection_caveat(b)
        ended(f"  bisection over full simulations: delta_s* in [{b.lower / MM:.4f}, {b.delta_s / MM:.4f}] mm "
              f"({b.simulations} simulations, {b.wall_time_s:.1f} s); {against}"
              + (f"\n  WARNING: {caveat}" if caveat else ""), "bisection",
              plan[-1] if plan[-1] != "bisection" else None)
    if c.ok and vary_stiffness:
        from .runtime.studies.preload.stiffness import describe, stiffness_valley

        with stage("stiffness", "stiffness valley"):
            valley = done["valley"] = finished(stiffness_valley(setup, c, nodes=nodes))
        click.echo(describe(valley, c.deficit_tol))
    if (saved := saved_friction_power(results)) is not None:
        s = results["schedule"]
        click.echo(f"schedule saves {saved:.3f} W of friction power against the best constant preload "
                   f"({s.friction_power:.3f} vs {c.friction_power:.3f} W)")
