"""``apexseal scene``: write a scene to start from (the embedded default), or a scene file resolved in full."""

from __future__ import annotations

import io
from pathlib import Path

import click

from .cli_common import scene_of, scene_settings, writable


@click.command()
@click.argument("scene", required=False, type=click.Path(dir_okay=False, path_type=Path))
@scene_settings
@click.option("--default", "default", is_flag=True, help="Print the embedded default scene (the paper's case study), "
              "with its comments: `apexseal scene --default > my.toml`.")
@click.option("--out", "-o", "out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="With --default or --resolved: write the scene (default.toml, scene.toml) and its pressure table "
                   "into this folder instead of printing it.")
@click.option("--resolved", is_flag=True, help="Print SCENE (default: the embedded one) with every key explicit, in SI "
              "with its unit, as a saved result's scene.toml has it (with --out: written with its pressure table).")
def scene(scene: Path | None, sets, default: bool, out: Path | None, resolved: bool) -> None:
    """Print a scene file to start from, or check SCENE and print its content hash."""
    if default and (resolved or scene or sets):
        raise click.UsageError("--default prints the embedded scene; give it alone")
    if default:
        from .runtime.scenes.scene import _scenes_folder, default_scene_text, load_scene

        table = load_scene().pressure.file
        _write({"default.toml": default_scene_text(),
                table: _scenes_folder().joinpath(table).read_text(encoding="utf-8")}, out)
        return
    if out is not None and not resolved:
        raise click.UsageError("--out writes a scene's files: give it with --default or --resolved")
    sc = scene_of(scene, sets)
    if resolved:
        from .runtime.scenes.resolved import resolved_toml

        text, files = resolved_toml(sc, header=f"scene {sc.name}, content hash {sc.content_hash()}")
        if out is not None:
            _write({"scene.toml": text, **files}, out)
        else:  # printed only: nothing is written into the current folder
            click.echo(text, nl=False)
            if files:
                click.echo(f"# its pressure table ({', '.join(files)}, in Pa) is not printed: `--out FOLDER` writes the "
                           "scene with it, and `apexseal simulate` writes it beside a result's scene.toml", err=True)
        return
    click.echo(f"{sc.name}: valid; content hash {sc.content_hash()}; effects {sc.effects.label}")
    if derived := derived_values(sc):
        click.echo(f"  derived: {derived}")
    from .derive.submodels.registry import installed

    for name, dist in installed().items():  # entry points of installed packages (docs/extending.md)
        click.echo(f"  submodel {name} from {dist}")


def derived_values(sc) -> str:
    """What a designer checks first that the scene does not state: the seal's mass, the spring's preload force, the
    housing wall's deflection at rest (Eq. 9) and the seal's protrusion (Eq. 17; Eqs. 6-8 when not given), those
    of them the scene's model has; a preload the scene schedules along the revolution at its start angle."""
    p = sc.parameters
    at_start = " at the start angle (scheduled)" if sc.schedule is not None else ""
    out = []
    if "ms" in p:
        out.append(f"seal mass ms = {p['ms'] * 1e3:.4g} g")
    if "ks" in p and "delta_s" in p:  # the spring's own law (Eq. 39), which delta_w balances
        from .derive.submodels.spring import SpringContact

        out.append(f"spring preload ks delta_s = {SpringContact.rest_force(p):.4g} N{at_start}")
    if "delta_w" in p:
        out.append(f"wall deflection at rest delta_w = {p['delta_w'] * 1e6:.4g} µm (Eq. 9){at_start}")
    if "zeta0" in p:
        how = "given" if sc.seal.zeta0 is not None else "the groove truncation of Eqs. 6-8"
        out.append(f"protrusion zeta0 = {p['zeta0'] * 1e3:.4g} mm ({how})")
    return ", ".join(out)


def _read_by_a_pipe_or_terminal() -> bool:
    """Whether stdout is a pipe or a terminal (``apexseal scene --default | less``): the scene printed is read, not
    kept as a file, so the files it reads are not written into the current folder. False where stdout has no file
    descriptor (a test's captured output) or is a file (``> my.toml``)."""
    import os
    import stat
    import sys

    try:
        mode = os.fstat(sys.stdout.fileno()).st_mode
    except (OSError, ValueError, AttributeError, io.UnsupportedOperation):
        return False
    return stat.S_ISFIFO(mode) or stat.S_ISSOCK(mode) or sys.stdout.isatty()


def _write(texts: dict[str, str], out: Path | None) -> None:
    """A scene (the first of ``texts``) on stdout, the files it reads (a pressure table) written to the current
    folder, which a redirected ``> my.toml`` shares (not when stdout is a pipe or a terminal:
    :func:`_read_by_a_pipe_or_terminal`); or, with ``out``, all of them into that folder. A file there
    that differs from what would be written is never replaced: refused with ``--out``, named on stderr without
    it."""
    main, *others = texts
    folder = out or Path(".")
    if out is not None:
        writable(out)
    differ = [n for n, text in texts.items()
              if (folder / n).exists() and (folder / n).read_text(encoding="utf-8", errors="replace") != text]
    if out is not None:
        if differ:
            raise click.BadParameter(f"{folder} already holds {' and '.join(differ)}, different from the scene's; "
                                     "allowed: a folder without them (nothing is overwritten)", param_hint="--out")
        for name, text in texts.items():
            (folder / name).write_text(text, encoding="utf-8")
        click.echo(f"wrote {' and '.join(str(folder / n) for n in texts)}")
        return
    click.echo(texts[main], nl=False)
    if others and _read_by_a_pipe_or_terminal():
        click.echo(f"# the scene reads {' and '.join(others)} beside it, not written here (the output goes to a pipe or "
                   "a terminal): `--out FOLDER` writes both, `> my.toml` writes the table beside it", err=True)
        return
    for name in others:
        if name in differ:
            click.echo(f"# kept {name} in the current folder, which differs from the scene's table: the scene "
                       "printed reads it", err=True)
        elif not (folder / name).exists():
            (folder / name).write_text(texts[name], encoding="utf-8")
            click.echo(f"# wrote the scene's pressure table {name} to the current folder", err=True)
