"""``apexseal generate``: write (and compile) the C of a scene's model; ``--check`` the committed default."""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import click

from .cli_common import Choice, writable
from .derive.assumptions import Assumptions
from .derive.effects import Effects, off_with_parents
from .derive.options import OptionError
from .generated.compiler import FLAG_SETS

_ON = {"on": True, "true": True, "1": True, "yes": True, "off": False, "false": False, "0": False, "no": False}


def _pairs(values: tuple[str, ...], what: str) -> dict[str, str]:
    out = {}
    for item in (part for v in values for part in v.split(",") if part.strip()):
        if "=" not in item:
            raise click.BadParameter(f"{item!r}: expected NAME=VALUE", param_hint=what)
        name, value = item.split("=", 1)
        out[name.strip()] = value.strip()
    return out


def _with_overrides(base: Effects, overrides: dict[str, str]) -> Effects:
    """``base`` with these effects switched; an effect switched off takes its children with it."""
    values = base.as_dict()
    for name, raw in overrides.items():
        if raw.lower() not in _ON:
            raise click.BadParameter(f"{name}={raw}: use on/off", param_hint="--effects")
        values[name] = _ON[raw.lower()]
    off = {name for name in overrides if not values[name]}
    return Effects.from_mapping(off_with_parents(values, off, overrides))


def _scene_inputs(scene: Path | None) -> tuple[Effects, Assumptions]:
    if scene is None:
        return Effects(), Assumptions()
    from .cli_common import scene_of

    s = scene_of(scene)
    return s.effects, s.assumptions


def _check_default(echo) -> bool:
    """Is generated/default current? Compare the manifest with the inputs, then regenerate and compare bytes."""
    from .generated.generate import generate as run_generate
    from .generated.load import DEFAULT_DIR, refresh_command
    from .generated.manifest import StaleArtefactError, input_hash, verify

    refresh = f"; refresh them with `{refresh_command()}`"
    try:
        verify(DEFAULT_DIR, expected_hash=input_hash(Effects(), Assumptions()))
    except StaleArtefactError as exc:
        echo(f"STALE: {exc}{refresh}")
        return False
    with tempfile.TemporaryDirectory(prefix="apexseal-check-") as tmp:
        fresh = run_generate(out_dir=Path(tmp) / "default", compile=False, echo=None)
        differ = [n for n in fresh.files if (Path(tmp) / "default" / n).read_bytes() != (DEFAULT_DIR / n).read_bytes()]
    if differ:
        echo(f"STALE: regenerating gives different bytes for {', '.join(differ)}{refresh}")
        return False
    echo(f"generated/default is current (input hash {fresh.input_hash[:16]}, {len(fresh.files)} files)")
    return True


def _generate_into(out: Path, effects, assumptions, flags: str, no_compile: bool, quiet: bool):
    """Generate into ``out``; a write that fails (a full disk, permissions) is one line naming the folder, the path
    and the cause: a :class:`~apexseal.files.CacheError` below the cache folder, else against ``--out``."""
    from .derive.cache import cache_dir
    from .files import CacheError, cache_error, inside
    from .generated.generate import generate as run_generate

    try:
        return run_generate(effects, assumptions, out, flags=flags, compile=not no_compile,
                            echo=None if quiet else click.echo)
    except CacheError:
        raise
    except OSError as err:
        if inside(err.filename or out, cache_dir()):  # the default --out is in the cache, as are derivations
            raise cache_error(OSError(err.errno, err.strerror, str(err.filename or out)), cache_dir()) from err
        raise click.ClickException(f"cannot write the generated artefacts to {out} ({err.filename or out}: "
                                   f"{err.strerror or err}); give --out a folder you can write, on a disk with "
                                   "free space") from None


def _refuse_a_stray_default(out: Path | None) -> None:
    """Refuse ``--out .../generated/default`` that is not the committed default artefacts' folder (the command run
    outside the repository's root): it would write a copy nothing reads and leave the committed ones stale."""
    from .generated.load import DEFAULT_DIR, refresh_command

    if out is None or out.resolve().parts[-2:] != DEFAULT_DIR.parts[-2:] or out.resolve() == DEFAULT_DIR.resolve():
        return
    raise click.BadParameter(f"{out} is {out.resolve()}, not the committed default artefacts of the apexseal that "
                             f"runs ({DEFAULT_DIR}); refresh those with `{refresh_command()}` (run "
                             "from the repository's root, `--out generated/default` is that folder)", param_hint="--out")


@click.command("generate")
@click.argument("scene", required=False, type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--out", "-o", "out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Output folder [default: the cache folder load_functions uses]. "
                   "`--out generated/default`, run from the repository's root, refreshes the committed default "
                   "artefacts (elsewhere it is refused).")
@click.option("--flags", type=Choice(tuple(FLAG_SETS)), default="optimised", show_default=True,
              help="quick: -O1, for edit-and-try; optimised: -O3 -march=native, for long studies.")
@click.option("--effects", "effect_opts", multiple=True, metavar="NAME=on|off[,...]",
              help="Switch effects (on top of the scene's), e.g. --effects groove_friction=off")
@click.option("--assumptions", "assumption_opts", multiple=True, metavar="NAME=VALUE[,...]",
              help="Modelling choices, e.g. --assumptions damping=always")
@click.option("--no-compile", is_flag=True, help="Write the C only.")
@click.option("--check", is_flag=True, help="Verify that generated/default is up to date (exit 1 if stale).")
@click.option("--quiet", "-q", is_flag=True, help="No stage times: only what was written, and where.")
def generate(scene: Path | None, out: Path | None, flags: str, effect_opts: tuple[str, ...],
             assumption_opts: tuple[str, ...], no_compile: bool, check: bool, quiet: bool) -> None:
    """Generate (and compile) the C code of the model of SCENE (a TOML scene file; default: the default scene).

    Prints the time of each stage (derive, lower to CasADi, codegen, render, compile) and where the
    artefacts and the compiled library are.
    """
    if check:
        flags_given = click.get_current_context().get_parameter_source("flags") != click.core.ParameterSource.DEFAULT
        given = [what for what, value in (("SCENE", scene), ("--out", out), ("--flags", flags_given),
                                          ("--effects", effect_opts), ("--assumptions", assumption_opts),
                                          ("--no-compile", no_compile)) if value]
        if given:  # each would be silently ignored: --check verifies the committed default artefacts only
            raise click.UsageError(f"--check verifies the committed generated/default (the default model) only, and "
                                   f"takes no {', '.join(given)}; to see a scene's model, run `apexseal generate "
                                   "SCENE` without --check")
        sys.exit(0 if _check_default(click.echo) else 1)
    from .generated.manifest import input_hash

    effects, assumptions = _scene_inputs(scene)
    if effect_opts:
        try:
            effects = _with_overrides(effects, _pairs(effect_opts, "--effects"))
        except OptionError as exc:
            raise click.BadParameter(str(exc), param_hint="--effects") from None
    if assumption_opts:
        try:
            assumptions = Assumptions.from_mapping({**assumptions.as_dict(),
                                                    **_pairs(assumption_opts, "--assumptions")})
        except OptionError as exc:
            raise click.BadParameter(str(exc), param_hint="--assumptions") from None
    _refuse_a_stray_default(out)
    if out is None:
        from .derive.cache import cache_dir

        out = cache_dir() / "gen" / input_hash(effects, assumptions)
    writable(out)  # a folder that cannot be made or written is refused before the derivation, naming it
    click.echo(f"effects: {effects.label}; assumptions: {assumptions.as_dict()}")
    manifest = _generate_into(out, effects, assumptions, flags, no_compile, quiet)
    c_bytes = sum((out / n).stat().st_size for n in manifest.files if n.endswith(".c"))
    n_instr = sum(f["n_instructions"] for f in manifest.data["functions"].values())
    if not quiet:
        click.echo(f"total   {sum(manifest.timings.values()):8.2f} s")
    click.echo(f"artefacts: {out} ({len(manifest.files)} files, C {c_bytes / 1e6:.2f} MB, "
               f"{len(manifest.modes)} modes, {n_instr} SX instructions)")
    click.echo(f"input hash: {manifest.input_hash}")
    if manifest.library is not None:
        click.echo(f"library ({flags}): {manifest.library}")
    elif not no_compile:
        click.echo("library: none (no working C compiler; the interpreted Functions will be used)")
