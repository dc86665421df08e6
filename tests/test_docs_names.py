"""Every Python name the README and docs/ give (``from apexseal... import X``, a dotted ``apexseal.a.b`` in
backticks) resolves: a snippet that imports a module that moved (``apexseal.runtime.scene``) fails here, not in a
user's session."""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
DOCS = [REPO / "README.md", *sorted((REPO / "docs").rglob("*.md"))]
FROM_IMPORT = re.compile(r"from (apexseal[\w.]*) import ([\w, ]+)")
DOTTED = re.compile(r"`[^`\n]*?\b(apexseal(?:\.\w+)+)")
#: dotted names in the docs that are not Python names
NOT_PYTHON = {"apexseal.submodels": "the entry-point group of installed submodels",
              "apexseal.sweep": "the key of a sweep's Parquet schema metadata"}


def resolve(name: str):
    """The object ``name`` names: the longest importable module prefix, then attributes."""
    parts = name.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ModuleNotFoundError:
            continue
        for attribute in parts[i:]:
            obj = getattr(obj, attribute)
        return obj
    raise ModuleNotFoundError(name)


def names() -> list[tuple[str, str]]:
    out = []
    for path in DOCS:
        text = path.read_text(encoding="utf-8")
        where = str(path.relative_to(REPO))
        out += [(where, f"{m[1]}.{n.strip()}") for m in FROM_IMPORT.finditer(text) for n in m[2].split(",")]
        out += [(where, m[1]) for m in DOTTED.finditer(text) if m[1] not in NOT_PYTHON]
    return sorted(set(out))


def test_the_docs_name_python_objects():
    assert len(names()) > 50  # the patterns still find the docs' names


@pytest.mark.parametrize(("doc", "name"), names())
def test_a_name_in_the_docs_resolves(doc, name):
    resolve(name)
