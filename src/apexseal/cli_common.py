"""What the run commands share: the scene argument and the output folder, both checked before any work."""

from __future__ import annotations

import os
from pathlib import Path

import click


def writable(folder: Path) -> None:
    """Fail before computing anything if the output folder cannot be written."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise click.BadParameter(f"cannot create the output folder {folder}: {err.strerror}", param_hint="--out") from err
    if not os.access(folder, os.W_OK):
        raise click.BadParameter(f"the output folder {folder} is not writable", param_hint="--out")


def scene_of(scene: Path | None):
    """The loaded scene (embedded default if None); a scene error becomes a clean CLI error."""
    from .runtime.scenes.errors import SceneError
    from .runtime.scenes.scene import load_scene

    try:
        return load_scene(scene)
    except SceneError as err:
        raise click.ClickException(str(err)) from err


def default_folder(scene: Path | None, out: Path | None) -> Path:
    return out or Path("apexseal-out") / (scene.stem if scene else "default")


def scene_and_folder(scene: Path | None, out: Path | None):
    """The loaded scene and the output folder (default ``apexseal-out/<scene name>``), created and checked
    writable."""
    sc = scene_of(scene)
    folder = default_folder(scene, out)
    writable(folder)
    return sc, folder


def result_folder(folder: Path) -> None:
    """Fail before computing anything if a result cannot be written as ``folder`` (written beside it, in the
    same parent folder, then renamed into place: see runtime/results/folder.py)."""
    from .runtime.results.folder import ResultFolderError, check_replaceable

    try:
        check_replaceable(folder)
    except ResultFolderError as err:
        raise click.BadParameter(str(err), param_hint="--out") from err
    writable(folder.parent if folder.parent != Path("") else Path("."))
