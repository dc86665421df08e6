"""What the run commands share: the scene argument and the output folder, both checked before any work."""

from __future__ import annotations

import math
import os
import tempfile
from pathlib import Path

import click


class Choice(click.Choice):
    """click's choice of names, refused in the project's words: the value, a "did you mean" and what is allowed
    (click says only that the value is not one of the choices)."""

    def convert(self, value, param, ctx):
        if value in self.choices:
            return value
        from .suggest import did_you_mean

        self.fail(f"{value!r} is not allowed{did_you_mean(value, self.choices)}; allowed: {', '.join(self.choices)}",
                  param, ctx)


class IntRange(click.IntRange):
    """click's integer range, whose refusal of what is no integer (``abc``, ``1e20``) names the range too (click says
    only that the value is not a valid integer)."""

    def convert(self, value, param, ctx):
        if isinstance(value, str):
            try:
                int(value)
            except ValueError:
                self.fail(f"{value!r} is not an integer; allowed: {self._describe_range()}", param, ctx)
        return super().convert(value, param, ctx)


class FloatRange(click.FloatRange):
    """click's number range, which also refuses NaN (click lets it through: it fails no comparison) and names the
    range for what is no number."""

    def convert(self, value, param, ctx):
        try:
            number = float(value)
        except (TypeError, ValueError):
            self.fail(f"{value!r} is not a number; allowed: {self._describe_range()}", param, ctx)
        if math.isnan(number):
            self.fail(f"{value} is not a number; allowed: {self._describe_range()}", param, ctx)
        return super().convert(value, param, ctx)


class Setting(click.ParamType):
    """A run setting's option (``--revolutions``, ``--rtol``, ...): read as an integer or a number, its range checked
    with the scene's and the API's (runtime/solving/settings.py); what is no number is refused naming that range."""

    def __init__(self, setting: str, kind: type[int] | type[float]) -> None:
        self.setting, self.integer = setting, kind is int
        self.name = "integer" if self.integer else "float"

    def convert(self, value, param, ctx):
        if not isinstance(value, str):
            return value
        try:
            return int(value) if self.integer else float(value)
        except ValueError:
            from .runtime.solving.settings import allowed

            what = "an integer" if self.integer else "a number"
            self.fail(f"{value!r} is not {what}; allowed: {allowed(self.setting)}", param, ctx)


def writable(folder: Path, option: str = "--out", given: Path | None = None) -> None:
    """Fail before computing anything if the output folder (given by ``option``) cannot be written: created if
    missing, then a folder made and removed in it (permission bits alone do not tell: root passes them, and a
    virtual file system such as /proc refuses to create anything). ``given``: the value of the option, when
    ``folder`` is the folder it is written beside (a result's parent)."""
    given = folder if given is None else given
    beside = "" if given == folder else f" (its result is written in {folder}, then renamed into place)"
    existing = next((f for f in (folder, *folder.parents) if f.exists()), None)
    if existing is not None and not existing.is_dir():
        raise click.BadParameter(f"cannot create the output folder {given}: {existing} is a file; allowed: a folder "
                                 "(created if missing)", param_hint=option)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        os.rmdir(tempfile.mkdtemp(prefix=".apexseal-probe-", dir=folder))
    except OSError as err:
        raise click.BadParameter(f"cannot create the output folder {given}{beside}: {err.strerror}; allowed: a "
                                 "folder this user can create files in", param_hint=option) from None


def _toml_value(text: str):
    """A --set value as TOML reads it (``5e3``, ``true``, ``"5e3 N/m"``, ``[1, 2]``), else the text itself
    (``5e3 N/m``, ``erk``): the shell's quotes are gone by the time it arrives."""
    import tomllib

    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def _sets(ctx: click.Context, param: click.Parameter, items: tuple[str, ...]) -> dict[str, object]:
    out: dict[str, object] = {}
    for item in items:
        key, eq, text = item.partition("=")
        if not eq or not key.strip() or not text.strip():
            raise click.BadParameter(f"{item!r} is not KEY=VALUE, e.g. --set 'spring.ks=5e3 N/m'", param_hint="--set")
        out[key.strip()] = _toml_value(text.strip())
    from .runtime.scenes.schema import FILE_KEYS

    for key in FILE_KEYS:  # a path typed on the command line is the shell's: from the current folder
        if isinstance(out.get(key), str) and not Path(out[key]).expanduser().is_absolute():
            out[key] = str(Path(out[key]).expanduser().absolute())
    return out


#: the --set option of every command that reads a scene: scene keys replaced on the command line, checked as the
#: scene's own (Scene.with_overrides); a result's scene.toml holds the values that ran
scene_settings = click.option(
    "--set", "sets", multiple=True, metavar="KEY=VALUE", callback=_sets,
    help="Replace a scene key, e.g. --set 'spring.ks=5e3 N/m' --set effects.groove_friction=false (repeatable; "
         "values as in a scene file, with units; checked with the scene's ranges; a file, pressure.file, from the "
         "current folder).")


def scene_of(scene: Path | None, sets: dict[str, object] | None = None):
    """The loaded scene (embedded default if None) with the --set keys replaced; a scene error becomes a clean
    CLI error."""
    from .runtime.scenes.errors import SceneError
    from .runtime.scenes.scene import load_scene

    try:
        return load_scene(scene, overrides=sets)  # the keys replaced before the file is checked: --set can repair it
    except SceneError as err:
        raise click.ClickException(str(err)) from err


def scene_label(scene: Path | None, sets: dict[str, object] | None = None) -> str:
    """How a command's first line names its scene: the file (or the embedded default) and the --set keys."""
    import json

    label = f"scene {scene or '(embedded default: the paper case study)'}"
    shown = {k: v if isinstance(v, str) else json.dumps(v) for k, v in (sets or {}).items()}  # true, not True
    return label + (" with " + ", ".join(f"{k}={v}" for k, v in shown.items()) if shown else "")


def default_folder(scene: Path | None, out: Path | None, study: str = "") -> Path:
    """``out``, or ``apexseal-out/<scene name>`` (a simulation's result) or ``apexseal-out/<scene name>-<study>``
    (a study's report: never in a result folder, which a later simulation replaces as a whole)."""
    name = (scene.stem if scene else "default") + (f"-{study}" if study else "")
    return out or Path("apexseal-out") / name


def report_target(out: Path, make):
    """The report folder of a study at ``out`` (``make(out)``: its
    :class:`~apexseal.runtime.results.folder.ReportFolder`; a folder that holds other files is refused, naming
    --out) and the folders above it that are made so that it can be written (the nearest first, for
    :func:`remove_made`), the parent checked writable: all before any work."""
    from .runtime.results.folder import ResultFolderError

    try:
        folder = make(out)
    except ResultFolderError as err:
        raise click.BadParameter(str(err), param_hint="--out") from None
    parent = out.parent
    made = [f for f in (parent, *parent.parents) if not f.exists()]  # what writable() creates, the nearest first
    writable(parent)
    return folder, made


def remove_made(made: list[Path]) -> None:
    """Remove the folders :func:`report_target` made where they stayed empty (a study that wrote no report)."""
    for folder in made:
        if not folder.is_dir() or any(folder.iterdir()):
            break
        folder.rmdir()


def result_folder(folder: Path) -> None:
    """Fail before computing anything if a result cannot be written as ``folder`` (written beside it, in the
    same parent folder, then renamed into place: see runtime/results/folder.py)."""
    from .runtime.results.folder import ResultFolderError, check_replaceable

    try:
        check_replaceable(folder)
    except ResultFolderError as err:
        raise click.BadParameter(str(err), param_hint="--out") from err
    writable(folder.parent if folder.parent != Path("") else Path("."), given=folder)


def _power(total: float | None) -> str:
    return "friction power: none computed (no output interval)" if total is None else f"friction power {total:.2f} W"


def at_samples(summary: dict) -> str:
    """Where a summary's extremes and peaks were taken: "at the 3600 output samples per revolution" (the largest
    sample, not the largest of the motion between samples; a short impact between two of them is not seen)."""
    per_revolution = summary.get("samples_per_revolution")
    if per_revolution is None:  # a summary written before it was recorded
        return f"at the {summary['samples']} output samples"
    return f"at the {per_revolution} output samples per revolution"


def describe_result(result, summary: dict) -> None:
    """The designer's numbers of a result on the console (``simulate`` at its end, ``show``): status, revolutions,
    switches, displacement ranges and deepest penetrations (both at the output samples, and the line says how many
    per revolution), friction power, a warning when a penetration is implausible, the part of the run with the seal
    tip off the housing (a warning when it is most of it), the sliding speeds and Archard's sliding work (the part
    of the run sweeps read, runtime/results/wear.py), a note when the samples do not
    resolve the contacts' ringing (runtime/solving/ringing.py), a note when the method controls no error and a
    warning when its tolerances are loose (runtime/solving/accuracy.py), a note when a completed run's switches came
    close to a chatter detector's limit (runtime/solving/near_chatter.py), with until_periodic whether and where the
    revolutions repeated (runtime/solving/periodicity.py), the chamber gas's cycle (with the gas model; a warning when
    it is not an expander's, runtime/results/gas.py), the groove mouth corners' margins on the seal's flat sides (a
    warning when one left them), and for a run of two revolutions or more its last revolution's numbers (summary.json's
    ``last_revolution``)."""
    from .runtime.results.gas import describe_cycle
    from .runtime.results.liftoff import describe_liftoff
    from .runtime.results.plausibility import describe, describe_flank
    from .runtime.solving.near_chatter import describe_near_chatter
    from .runtime.solving.periodicity import describe_periodic
    from .runtime.solving.ringing import describe_sampling

    ext = summary["extremes"]
    at = at_samples(summary)
    wall = result.info.get("wall_time_s")
    before = [c.get("wall_time_s") for c in result.info.get("continued", [])]  # a continued run's earlier runs
    if wall is not None and before and all(w is not None for w in before):
        shown = f", wall {wall:.2f} s (its last run; {wall + sum(before):.2f} s in all, {len(before) + 1} runs)"
    else:
        shown = f", wall {wall:.2f} s" if wall is not None else ""
    click.echo(f"{result.status}: {summary['revolutions']:.2f} revolutions, {summary['events_total']} contact switches"
               + shown)
    click.echo(f"  x {ext['x']['min']:.3f}..{ext['x']['max']:.3f} µm, y {ext['y']['min']:.2f}..{ext['y']['max']:.2f} µm, "
               f"phi {ext['phi']['min']:.3f}..{ext['phi']['max']:.3f} mrad ({at}); "
               + _power(summary["mean_friction_power_W"].get("total", 0.0)))
    check = summary.get("plausibility")
    if check is not None and check["penetration_um"]:
        depth = ", ".join(f"{c} {d:.3g}" for c, d in check["penetration_um"].items())
        click.echo(f"  deepest penetration {at} (µm): {depth}; side clearance {check['side_clearance_um']:.3g} µm")
        if not check["ok"]:
            click.echo(f"  warning: {describe(check)}", err=True)
    lifted = summary.get("liftoff")
    if lifted is not None:  # the housing contact: the part of the run with the tip off it (runtime/results/liftoff.py)
        longest = (f", longest {lifted['longest_deg']:.4g}° from {lifted['longest_from_deg']:.4g}°"
                   if lifted["longest_from_deg"] is not None else "")
        click.echo(f"  tip off the housing: {lifted['fraction']:.2%} of the samples{longest}")
        if not lifted["ok"]:
            click.echo(f"  warning: {describe_liftoff(lifted, summary['revolutions'], result.guard_names)} "
                       "(LiftOffWarning)", err=True)
    from .runtime.results.quantities import measured_part
    from .runtime.results.wear import describe_wear

    worn = measured_part(summary).get("wear")  # the part sweeps and compare read (runtime/results/wear.py)
    if worn is not None:
        click.echo(f"  {describe_wear(worn)}" + (" (last revolution)" if worn is not summary.get("wear") else ""))
    balance = measured_part(summary).get("energy_balance")  # runtime/results/energy.py
    if balance is not None and not balance["closes"]:  # a note: the default sampling does not close it
        from .runtime.results.energy import describe_balance

        click.echo(f"  note: {describe_balance(balance, summary.get('samples_per_revolution'))}")
    sampling = summary.get("sampling")
    if sampling is not None and not sampling["resolved"]:  # a note, not a warning: the default sampling is one
        click.echo(f"  note: {describe_sampling(sampling)}")
    accuracy = summary.get("accuracy")  # a fixed step's note; a loose tolerance's warning (runtime/solving/accuracy.py)
    # (not for a run refused before its first step: it has no error to speak of)
    if accuracy is not None and accuracy["note"] and not result.info.get("refused_at_start"):
        if accuracy["error_control"]:
            click.echo(f"  warning: {accuracy['note']}", err=True)
        else:
            click.echo(f"  note: {accuracy['note']}")
    cluster = summary.get("run", {}).get("switch_cluster")  # a completed run close to the chatter detectors
    if result.status == "completed" and cluster is not None and cluster["near"]:
        click.echo(f"  note: {describe_near_chatter(cluster)}")
    gas = summary.get("gas")
    if gas is not None:  # the chamber gas model: its cycle (last revolution)
        p = gas["pressure_Pa"]
        click.echo(f"  chamber gas (last revolution): inducted {gas['inducted_mass_kg'] * 1e3:.4g} g, exhausted "
                   f"{gas['exhausted_mass_kg'] * 1e3:.4g} g, leaked {gas['leaked_mass_kg']['total'] * 1e6:.4g} mg; "
                   f"indicated work {gas['indicated_work_J']['total']:.4g} J ({gas['indicated_power_W'] / 1e3:.4g} kW); "
                   f"pressures {min(p['a']['min'], p['b']['min']) / 1e5:.3g}..{max(p['a']['max'], p['b']['max']) / 1e5:.3g}"
                   " bar")
        cycle = gas.get("expander_cycle")  # absent from the summaries written before it was recorded
        if cycle is not None and not cycle["ok"]:
            click.echo(f"  warning: {describe_cycle(gas)}", err=True)
    periodic = describe_periodic(summary.get("run", {}).get("periodic") or {})  # operation.until_periodic
    if periodic is not None:
        click.echo(f"  {periodic}")
    last = summary.get("last_revolution")
    if last is not None:  # a run of two revolutions or more: its numbers without the start-up from rest
        click.echo(f"  {describe_last_revolution(last)}")
    flank = summary.get("flank")
    if flank is not None:
        least = flank["least_mm"]
        click.echo(f"  groove mouth corners (mm): {min(least['l1'], least['l3']):.3g} from the seal's tip arc, "
                   f"{min(least['l2'], least['l4']):.3g} from its back face (least l1, l3 and l2, l4; > 0: on its "
                   "flat sides)")
        if not flank["ok"]:
            click.echo(f"  warning: {describe_flank(flank)}", err=True)


def describe_last_revolution(last: dict) -> str:
    """One line of a summary's ``last_revolution``: y's range, the housing force's peak and where, the tip off the
    housing, the friction power (each only where the model has it)."""
    y = last["extremes"]["y"]
    parts = [f"y {y['min']:.2f}..{y['max']:.2f} µm"]
    force = last["housing_force_N"]
    if force["max"] is not None:
        parts.append(f"housing force max {force['max']:.4g} N at {force['max_at_deg']:.4g}°")
    lifted = last.get("liftoff")
    if lifted is not None:
        parts.append(f"tip off the housing {lifted['fraction']:.2%}")
    parts.append(_power(last["mean_friction_power_W"].get("total", 0.0)))
    return f"last revolution ({last['from_deg']:.0f}..{last['to_deg']:.0f}°): " + ", ".join(parts)
