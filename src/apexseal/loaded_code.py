"""Whether the code this process imported is still the code on disk.

A model's keys (the derivation's cache key, the generated code's input hash) are computed from the source files
on disk: derive/, the submodels that enter the model and their helpers, the generator's modules. A process that
imported one of those modules and whose file was edited afterwards (a notebook, a sweep, a long study) computes
the key of the edited file, but derives and generates with the code it imported; what it would write into the
cache under that key is the old model, which every later process would then load as the new one.

:func:`note` remembers, for each such file whose module this process has imported, the file's sha256 when the
process first saw it (every key computation notes its files, so the first run of a process notes what it
imported); :func:`refuse_edited` is called before the process derives or generates, and refuses when a file
changed since. ``importlib.reload`` gives the module a new spec: its file is noted again from then on.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterable
from pathlib import Path

from .files import sha256_file

#: the resolved file of a module -> (the module's spec when its file was first noted, the file's sha256 then)
_SEEN: dict[str, tuple[object, str]] = {}
#: the base name of a module's file -> the modules of that name, rebuilt when the number of imported modules changes
_BY_NAME: tuple[int, dict[str, list]] = (-1, {})


class EditedSinceImportError(RuntimeError):
    """A source file of the model changed on disk after this process imported its module."""


def _modules_by_name() -> dict[str, list]:
    global _BY_NAME
    count = len(sys.modules)
    if _BY_NAME[0] != count:
        found: dict[str, list] = {}
        for module in list(sys.modules.values()):
            file = getattr(module, "__file__", None)
            if isinstance(file, str) and file.endswith(".py"):
                found.setdefault(os.path.basename(file), []).append(module)
        _BY_NAME = (count, found)
    return _BY_NAME[1]


def _imported(paths: Iterable[Path]) -> list[tuple[str, object]]:
    """(resolved file, module) of each of ``paths`` whose module this process imported, once each."""
    by_name = _modules_by_name()
    out = {}
    for key in dict.fromkeys(os.path.realpath(path) for path in paths):
        for module in by_name.get(os.path.basename(key), ()):
            if module.__file__ == key or os.path.realpath(module.__file__) == key:
                out[key] = module
                break
    return list(out.items())


def note(paths: Iterable[Path]) -> None:
    """Remember the sha256 of each of ``paths`` whose module is imported, unless noted already for that import."""
    for key, module in _imported(paths):
        seen = _SEEN.get(key)
        if seen is None or seen[0] is not module.__spec__:
            try:
                _SEEN[key] = (module.__spec__, sha256_file(Path(key)))
            except OSError:  # gone meanwhile: nothing to compare with
                pass


def edited_since_import(paths: Iterable[Path]) -> list[tuple[Path, str]]:
    """(file, module name) of each of ``paths`` whose module was imported and whose file changed since it was
    first noted."""
    paths = list(paths)
    note(paths)
    edited = []
    for key, module in _imported(paths):
        seen = _SEEN.get(key)
        try:
            now = sha256_file(Path(key))
        except OSError:
            now = None
        if seen is not None and seen[0] is module.__spec__ and now != seen[1]:
            edited.append((Path(key), module.__name__))
    return edited


def refuse_edited(paths: Iterable[Path], doing: str) -> None:
    """Raise :class:`EditedSinceImportError` naming every file of ``paths`` edited since this process imported it
    (``doing``: what the process was about to do, e.g. "derive the model")."""
    edited = edited_since_import(paths)
    if edited:
        files = ", ".join(f"{path} (module {name})" for path, name in edited)
        raise EditedSinceImportError(
            f"{files} changed on disk after this process imported it: the process would {doing} with the code it "
            "imported and keep the result under the hash of the edited file. Start a new Python process (or "
            "importlib.reload the module) and run again.")
