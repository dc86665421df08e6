"""The packages stay layered: no module imports, even inside a function, a module that imports it back.

Read from the source (every ``import`` statement, deferred ones included), so a circle cannot hide behind an import
placed in a function. derive/: the declarations (options, parameters, the submodels' base) stand below the registry,
and what is validated against it (choices, effects, assumptions, symbols) above it. runtime/results/: only the
result's own methods (``summary()``, ``plot()``, ``save()``, ``load()``, ``to_pandas()``: pandas-style) reach the
modules above it.
"""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest


def _modules(package: str) -> dict[str, Path]:
    """Every module of ``package`` and its sub-packages, by dotted name."""
    root = Path(importlib.import_module(package).__file__).parent
    out = {}
    for path in root.rglob("*.py"):
        parts = path.relative_to(root).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join((package, *parts))] = path
    return out


def _imports(name: str, path: Path, known: dict[str, Path]) -> set[str]:
    """The modules of ``known`` that module ``name`` imports anywhere in its source."""
    is_package = path.name == "__init__.py"
    here = name.split(".") if is_package else name.split(".")[:-1]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = here[: len(here) - node.level + 1] if node.level else []
            target = ".".join([*base, *(node.module.split(".") if node.module else [])])
            found.add(target)
            found.update(f"{target}.{a.name}" for a in node.names)  # "from . import registry": a module
    return {m for m in found if m in known and m != name}


def _circle(graph: dict[str, set[str]]) -> list[str] | None:
    """One circle of ``graph`` (module -> modules it imports), or None."""
    state: dict[str, int] = {}
    path: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return [*path[path.index(nxt):], nxt]
            if nxt not in state:
                found = visit(nxt)
                if found:
                    return found
        path.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state:
            found = visit(node)
            if found:
                return found
    return None


def _graph(*packages: str, leaving_out: str | None = None) -> dict[str, set[str]]:
    known = {name: path for package in packages for name, path in _modules(package).items()}
    return {name: _imports(name, path, known) for name, path in known.items() if name != leaving_out}


@pytest.mark.parametrize("package", ["apexseal.derive", "apexseal.generated", "apexseal.runtime.solving",
                                     "apexseal.runtime.scenes", "apexseal.runtime.studies"])
def test_a_package_has_no_import_circle(package):
    assert _circle(_graph(package)) is None


def test_the_project_has_no_import_circle_but_the_result_s_methods():
    """Across the packages (the command line, derivation, generation, runtime), with the result's methods left out:
    no circle through two packages either (runtime/ imports derive/, generated/ and the shared helpers, not back)."""
    everything = ("apexseal", "apexseal.derive", "apexseal.generated", "apexseal.runtime")
    assert _circle(_graph(*everything, leaving_out="apexseal.runtime.results.result")) is None


def test_the_results_import_upwards_only_from_the_result_s_own_methods():
    graph = _graph("apexseal.runtime.results")
    assert _circle(graph) is not None  # the methods of SimulationResult: what this test leaves out below
    assert _circle(_graph("apexseal.runtime.results", leaving_out="apexseal.runtime.results.result")) is None


def test_the_check_finds_a_circle_hidden_in_a_function(tmp_path, monkeypatch):
    """The check itself: two modules that import each other, one of them inside a function, are a circle."""
    pkg = tmp_path / "layered_probe"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "low.py").write_text("def f():\n    from .high import g\n    return g\n")
    (pkg / "high.py").write_text("from .low import f\n\n\ndef g():\n    return f\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert _circle(_graph("layered_probe")) in (["layered_probe.high", "layered_probe.low", "layered_probe.high"],
                                                ["layered_probe.low", "layered_probe.high", "layered_probe.low"])
