"""The source text a registered submodel puts into the derivation's cache key.

A submodel's laws may sit in helper modules of its own: a ``laws.py`` beside the class, imported at the top of the
file or inside :meth:`~.base.Submodel.contacts`. The key therefore covers the file that declares the class and
every module of the same package (for a module outside any package: every module directly in its folder, not
the packages or virtual environments below it) that it imports, directly or through another such module,
wherever the import statement stands. The imports are read from the files'
syntax trees, so a helper counts whether or not it has been imported yet. Other libraries enter the key by their
versions only where the derivation names them (sympy); apexseal's own derivation is keyed by
:func:`apexseal.derive.cache.source_digest`, so a built-in submodel contributes its file alone.
"""

from __future__ import annotations

import ast
import functools
import hashlib
import importlib.util
import inspect
import sys
from pathlib import Path

from ...files import remembered, settled, stat_key
from ...loaded_code import note
from .base import built_in

#: class -> (the stat of each of its files, :func:`source_files`): its import graph changes only with its files
_FOUND: dict[type, tuple[tuple, tuple | None]] = {}


def source_key(cls) -> str:
    """sha256 of :func:`source_text`, remembered while none of the class's files changes (a notebook that edits
    and reloads a helper gets a new key; a run that asks for the key again reads no file)."""
    found = _found(cls)
    if found is None:  # a class without a file: its source cannot change without a new class
        return _key_without_file(cls)
    _, own, helpers = found
    note([own, *helpers])  # what this process imported of them (loaded_code: derive and generate compare)
    return remembered(("submodel source", cls.__module__, cls.__qualname__), [own, *helpers],
                      lambda: hashlib.sha256(source_text(cls, found).encode()).hexdigest())


def files_of(cls) -> list[Path]:
    """The files :func:`source_key` reads for a submodel class: the file that declares it and its helpers (none
    for a class without a file)."""
    found = _found(cls)
    return [] if found is None else [found[1], *found[2]]


@functools.cache
def _key_without_file(cls) -> str:
    return hashlib.sha256(source_text(cls).encode()).hexdigest()


def _found(cls) -> tuple | None:
    cached = _FOUND.get(cls)
    if cached is not None:
        stats, found = cached
        try:
            if all(stat_key(Path(s[0])) == s for s in stats):
                return found
        except OSError:
            pass
    found = source_files(cls)
    files = [found[1], *found[2]] if found else []
    try:  # the files and their folders: a helper created since (a folder's times change) is looked for again
        stats = tuple(stat_key(p) for p in [*files, *sorted({f.parent for f in files})])
    except OSError:  # a file vanished meanwhile: find them again next time
        return found
    if settled(stats):
        _FOUND[cls] = (stats, found)
    return found


def source_text(cls, found: tuple | None = None) -> str:
    """The text a submodel class contributes to the cache key (see the module docstring): the source of the file
    that declares it, then, for each helper of :func:`source_files`, its path relative to the package's (or
    folder's) root and its source. A class defined without a file (a notebook cell) gives its own source; one
    without any source, its declarations."""
    found = found or source_files(cls)
    if found is None:
        try:
            return inspect.getsource(cls)
        except (OSError, TypeError):  # defined where no source is available: its declarations stand in
            return repr((cls.parameters, cls.options, cls.guards, cls.switch, cls.enters_with))
    root, own, helpers = found
    return own.read_text(encoding="utf-8") + "".join(
        f"\n{f.relative_to(root).as_posix()}\n{f.read_text(encoding='utf-8')}" for f in helpers)


def source_files(cls) -> tuple[Path, Path, list[Path]] | None:
    """The root folder, the file that declares a submodel class, and its helpers in sorted order: unless the
    class is one of apexseal's own, the modules below the root that the file imports, transitively. None for a
    class without a source file."""
    try:
        path = inspect.getsourcefile(cls)
    except TypeError:
        return None
    if path is None or not Path(path).is_file():
        return None
    path = Path(path).resolve()
    module = cls.__module__
    if built_in(cls):
        return path.parent, path, []
    root = _root(module, path)
    flat = not _package_of(module, path)
    return root, path, sorted(_imported_files(path, module, root, flat) - {path})


def _top(module: str) -> str:
    """The top-level package of a module's name (whatever its folder is called: a setuptools ``package-dir`` may
    put package ``mysub`` in a folder ``code``)."""
    return module.split(".")[0]


def _root(module: str, path: Path) -> Path:
    """The folder whose modules belong to the submodel: its top-level package's, or its own file's folder."""
    package = _package_of(module, path)
    if package:
        top = sys.modules.get(package.split(".")[0])
        where = getattr(top, "__path__", None)
        if where:
            return Path(list(where)[0]).resolve()
        return path.parents[package.count(".")]  # not imported (yet): the folder as many levels up as it is deep
    return path.parent


def _package_of(module: str, path: Path) -> str:
    """The package that relative imports in ``module`` (file ``path``) resolve against."""
    if path.name == "__init__.py":
        return module
    return module.rpartition(".")[0] if module != "__main__" else ""


def _imported_files(start: Path, module: str, root: Path, flat: bool) -> set[Path]:
    """``start`` and every file below ``root`` that it imports, transitively (``flat``: a module outside any
    package, whose helpers are the modules directly in its folder, not the packages or virtual environments
    below it)."""
    seen: set[Path] = set()
    todo = [(start, module)]
    while todo:
        path, name = todo.pop()
        if path in seen:
            continue
        seen.add(path)
        try:
            tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
        except (OSError, SyntaxError, ValueError):
            continue
        for target in _targets(tree, _package_of(name, path)):
            found = _file_of(target, root, flat, _top(module))
            if found is not None and found not in seen:
                todo.append((found, target))
    return seen


def _targets(tree: ast.AST, package: str) -> set[str]:
    """The absolute names of the modules an import statement of ``tree`` may load (``from p import n``: p, and
    p.n in case n is a module)."""
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                if not package:
                    continue
                try:
                    base = importlib.util.resolve_name("." * node.level + base, package)
                except ImportError:
                    continue
            if base:
                names.add(base)
            names.update(f"{base}.{alias.name}" if base else alias.name for alias in node.names if alias.name != "*")
    return names


def _file_of(name: str, root: Path, flat: bool, top: str) -> Path | None:
    """The source file of module ``name`` if it belongs to the submodel's code, found on the file system alone:
    nothing is imported (a helper with an error is not run to hash it; ``find_spec`` would import its parent).
    ``root`` is the folder of the top-level package ``top`` (``flat``: the folder of a module outside any package,
    whose own modules are the files directly in it)."""
    parts = name.split(".")
    if flat:
        candidates = [root / f"{name}.py"] if len(parts) == 1 else []
    elif parts[0] != top:
        candidates = []
    else:
        base = root.joinpath(*parts[1:])
        candidates = ([base.with_name(base.name + ".py")] if len(parts) > 1 else []) + [base / "__init__.py"]
    return next((f.resolve() for f in candidates if f.is_file()), None)
