"""``apexseal bench``: the work-precision benchmark (runtime/bench), written to ./apexseal-out/bench by default."""

from __future__ import annotations

import shlex
import sys
import time
from pathlib import Path

import click

from .cli_common import Choice, FloatRange, IntRange, writable
from .generated.compiler import FLAG_SETS


def _command_line(ctx: click.Context) -> str:
    """The command as typed, rebuilt from the options that differ from their defaults."""
    words = ["apexseal", "bench"]
    for param in ctx.command.params:
        value = ctx.params.get(param.name)
        if value is False and isinstance(param, click.Option) and param.secondary_opts and param.default is None:
            words.append(param.secondary_opts[0])  # an explicit --no-... of a tri-state switch
            continue
        if not isinstance(param, click.Option) or value in (None, "", False) or value == param.default:
            continue
        words.append(param.opts[0])
        if not param.is_flag:
            words.append(shlex.quote(str(value)))
    return " ".join(words)


@click.command()
@click.option("--quick", is_flag=True, help="Smaller run (< 2 min): default scene, fewer methods, tolerances, repeats.")
@click.option("--out", "-o", "out", type=click.Path(file_okay=False, path_type=Path), default=Path("apexseal-out/bench"),
              show_default=True, help="Folder for results.json, table.md, effects.md, work-precision.png "
              "(the repository's docs/bench/ only when asked: --out docs/bench).")
@click.option("--methods", default="", help="Comma-separated method ids to keep (e.g. erk-C,scipy-RK45).")
@click.option("--scenes", default="", help="Comma-separated scenes to keep (default, stiff).")
@click.option("--samples", type=IntRange(4, 100000), help="Output samples per span (default 360).")
@click.option("--span", "span_deg", type=FloatRange(1, 360), help="Crank angle integrated, deg (default 360).")
@click.option("--settle", type=IntRange(0, 100), help="Settling revolutions before the span (default 3).")
@click.option("--repeats", type=IntRange(1, 100), help="Timed runs after the warm-up.")
@click.option("--no-effects", is_flag=True, help="Skip the effects-cost table.")
@click.option("--no-check", is_flag=True, help="Skip checking the reference with a second method.")
@click.option("--flags", type=Choice(tuple(FLAG_SETS)), help="C compiler flag set (default optimised).")
@click.option("--e2e/--no-e2e", default=None, help="Time the stages of a warm `apexseal simulate --revolutions 20` "
              "with and without figures (default: in the full run only).")
@click.option("--pressure", type=Choice(["steps", "linear"]), help="Chamber pressures over an output interval: "
              "linear between the values at its ends (linear, default: as a run) or held at their means (steps).")
@click.option("--gas/--no-gas", default=None, help="Time the pressure table, the chamber gas model and the gas model with "
              "leakage on the expander-gas scene (default: in the full run only).")
def bench(quick, out, methods, scenes, samples, span_deg, settle, repeats, no_effects, no_check, flags, e2e,
          pressure, gas) -> None:
    """Work-precision benchmark: error against CPU time for every method, targets, effects cost."""
    from .runtime.bench.config import PRESETS
    from .runtime.bench.output import write_outputs
    from .runtime.bench.runner import NothingToMeasure, partial_results, run_benchmark
    from .signals import StopSignals

    cfg = PRESETS["quick" if quick else "full"]()
    split = lambda s: tuple(x.strip() for x in s.split(",") if x.strip())  # noqa: E731
    for option, given in (("--methods", methods), ("--scenes", scenes)):
        if given.strip() and not split(given):  # ",," kept nothing and ran every method, as no option does
            raise click.BadParameter(f"{given!r} names none; allowed: comma-separated ids, e.g. erk-C,composite-C",
                                     param_hint=option)
    try:
        cfg = cfg.restricted(methods=split(methods), scenes=split(scenes), samples=samples, span_deg=span_deg,
                             settle=settle, repeats=repeats, flags=flags, effects=False if no_effects else None,
                             check_reference=False if no_check else None, e2e=e2e, pressure=pressure,
                             gas=gas)
    except ValueError as err:
        hint = "--scenes" if str(err).startswith("unknown scene") else "--methods"
        raise click.BadParameter(str(err), param_hint=hint) from None
    writable(out)  # before the hours of measuring, not at the end
    command = _command_line(click.get_current_context())
    t0 = time.perf_counter()
    measured: dict = {}  # filled point by point: what a signal leaves of the run
    results = None
    with StopSignals(raising=True) as signals:  # Ctrl-C/SIGTERM abandon the measuring wherever it is
        try:
            results = run_benchmark(cfg, log=lambda msg: click.echo(msg, err=True), into=measured)
        except NothingToMeasure as err:
            raise click.UsageError(str(err)) from None
        except BaseException:  # a signal surfaces as whatever the call it landed in made of it (a settling run
            if not signals.requested:  # ends "interrupted", which the benchmark reports as a failed settling)
                raise
        signals.raising = False  # the report is written whole; a further signal is only noted
        if signals.requested and results is None:  # a signal as the run returned: its whole result is written
            signals.ignore_after()
            kept = partial_results(measured, cfg, f"interrupted by {signals.sender()}")
            if kept is None:
                click.echo(f"  interrupted by {signals.sender()} before the first point was measured: nothing "
                           "written", err=True)
            else:
                paths = write_outputs(kept, out, command)
                click.echo(f"  {kept['interrupted']}: wrote {', '.join(str(p) for p in paths.values())} (a partial "
                           "run: its table says so)", err=True)
            sys.exit(signals.exit_code())
        paths = write_outputs(results, out, command)
    click.echo(f"wrote {', '.join(str(p) for p in paths.values())} in {(time.perf_counter() - t0) / 60:.1f} min")
    for t in results.get("targets", []):
        click.echo(f"  [{t['status']:>7}] {t['scene']}: {t['target']}: {t['text']}")
    for name, v in (results.get("e2e") or {}).get("variants", {}).items():
        parts = ", ".join(f"{k} {s:.2f}" for k, s in v["stages_s"].items())
        click.echo(f"  end to end ({name}): {parts}; wall {v['wall_s']:.2f} s "
                   f"(integrating {100 * v['integrate_share']:.0f} %)")
    for name, v in (results.get("gas") or {}).get("variants", {}).items():
        click.echo(f"  gas states ({name}): {1e3 * v['integrate_per_rev_s']:.0f} ms integrating per revolution "
                   f"(x{v['integrate_ratio']:.2f} the table's), {v['rhs_evaluations']} RHS evaluations")
    if signals.requested:  # it came as the run returned: the whole result is written, the exit code says it came
        click.echo(f"  interrupted by {signals.sender()} once every point was measured: the whole result is written",
                   err=True)
        sys.exit(signals.exit_code())
