"""docs/scenes.md documents every key and every solver method.

(That its error table shows the messages the code really gives is checked next to
the cases themselves, in test_scene_validation.py and test_scene_pressure.py.)
"""

import re
from pathlib import Path

import pytest

from apexseal.runtime.scenes.schema import SOLVER_METHODS, key_paths

DOCS = Path(__file__).resolve().parents[2] / "docs" / "scenes.md"


@pytest.fixture(scope="module")
def docs() -> str:
    return DOCS.read_text(encoding="utf-8")


def _users_keys() -> set[str]:
    """The scene keys of the submodels registered besides apexseal's own (a user's, an installed package's): not
    this page's to document (docs/extending.md)."""
    from apexseal.derive.submodels.base import built_in
    from apexseal.derive.submodels.registry import submodels

    theirs = [cls for cls in submodels() if not built_in(cls)]
    return ({p.key for cls in theirs for p in cls.parameters if p.key}
            | {f"{o.table}.{o.name}" for cls in theirs for o in cls.options})


@pytest.fixture
def a_users_submodel():
    """A submodel of one's own registered, as an installed package's is in every process (docs/extending.md): its keys
    are in the scene's; the checks of this page were red in a checkout where such a package was installed."""
    from apexseal.derive.options import NONE, ON, Option
    from apexseal.derive.parameters import Parameter
    from apexseal.derive.submodels import registry
    from apexseal.derive.submodels.base import Submodel

    extra = type("Extra", (Submodel,), {"name": "extra", "__module__": "elsewhere", "switch": "extra",
                                        "parameters": (Parameter("kx", "N/m", "extra stiffness", key="extra.kx", gt=0),),
                                        "options": (Option("extra", (NONE, ON), "an extra contact"),)})
    with registry.registered(extra):
        yield


def test_every_key_is_documented(docs, a_users_submodel):
    assert "extra.kx" in key_paths()
    missing = [k for k in key_paths() if f"`{k}`" not in docs and k not in _users_keys()]
    assert not missing, f"scene keys without a row in docs/scenes.md (its key reference): {', '.join(missing)}"


def test_every_solver_method_is_documented(docs):
    assert all(f'`"{m}"`' in docs for m in SOLVER_METHODS)


def test_key_paths_cover_nested_tables():
    keys = key_paths()
    assert "machine.ports.outlet.width" in keys and "operation.initial_state.phid" in keys
    assert key_paths("friction.") == ["friction.mu1", "friction.mu2", "friction.mus", "friction.v_eps"]


def test_the_keys_an_effect_needs_are_documented_as_such(docs, a_users_submodel):
    """Each key without a default that an effect reads says, in its row's default column, which effect needs it
    (registry.needing), and a schedulable one that its schedule may give it instead."""
    from apexseal.derive.submodels.registry import omissible_while_off, parameters

    rows = {line.split(" | ")[0]: line.split(" | ") for line in docs.splitlines()
            if line.startswith("| `") and line.count(" | ") == 5}  # the sections' tables: key, unit, default, ...
    for p in parameters(all_inputs=True):
        if omissible_while_off(p) and p.key not in _users_keys():
            unless = f", unless `{p.section}.schedule` gives it" if p.schedulable else ""  # runtime/scenes/schedule.py
            assert rows[f"| `{p.key}`"][2] == f"required while `{omissible_while_off(p)}` is on{unless}", p.key


_NUMBER = r"[-−]?\d[\d.]*(?:e[-+]?\d+)?"
_OP = {"<": "lt", "≤": "le", ">": "gt", "≥": "ge"}
_FLIP = {"<": ">", "≤": "≥"}
#: rows whose range is stated through other keys (stricter than the declared bound, which the scene's checks enforce)
_RANGE_IN_OTHER_KEYS = {"seal.ro": "≥ Ws/2", "seal.zeta0": "ro (1 − cos βo) < zeta0 < ds1 + ds2"}


def _si(number: str, unit: str | None, p) -> float:
    from apexseal.runtime.scenes.units import parse_quantity

    number = number.replace("−", "-")
    return parse_quantity(f"{number} {unit}", p.unit) if unit else float(number)


def _documented_bounds(cell: str, p) -> dict[str, float]:
    """The numeric bounds a row's "allowed" cell states, before its first ';': "0 ≤ value ≤ 5", "> 0, ≤ 1 mm",
    "1 < gamma < 2", "0..1", "any"; a clause through other keys ("> Ws", "≥ the port lengths") states none."""
    bounds: dict[str, float] = {}
    for clause in cell.split(";")[0].split(", "):
        clause = clause.strip()
        both = re.fullmatch(rf"({_NUMBER}) ([<≤]) \w+ ([<≤]) ({_NUMBER})(?: (\S+))?", clause)
        one = re.fullmatch(rf"([<>≤≥]) ({_NUMBER})(?: (\S+))?", clause)
        span = re.fullmatch(rf"({_NUMBER})\.\.({_NUMBER})", clause)
        if both:
            low, op_low, op_high, high, unit = both.groups()
            bounds[_OP[_FLIP[op_low]]] = _si(low, unit, p)
            bounds[_OP[op_high]] = _si(high, unit, p)
        elif one:
            bounds[_OP[one.group(1)]] = _si(one.group(2), one.group(3), p)
        elif span:
            bounds.update(ge=_si(span.group(1), None, p), le=_si(span.group(2), None, p))
    return bounds


def _rows(docs: str) -> dict[str, list[str]]:
    return {line.split(" | ")[0][2:]: line.split(" | ") for line in docs.splitlines()
            if line.startswith("| `") and line.count(" | ") == 5}


def test_the_documented_defaults_and_ranges_are_the_declared_ones(docs, a_users_submodel):
    """A law's default or range changed in its submodel (derive/submodels/) changes the scene's checks; the key
    reference said the old numbers, and no test noticed."""
    from apexseal.derive.submodels.registry import parameters

    rows = _rows(docs)
    wrong = []
    for p in (q for q in parameters(all_inputs=True) if q.key is not None and f"`{q.key}`" in rows):
        _, _, default, allowed, *_ = rows[f"`{p.key}`"]
        given = re.fullmatch(rf"({_NUMBER})(?: (\S+))?", default.strip())
        if p.default is not None and (given is None or _si(*given.groups(), p) != p.default):
            wrong.append(f"{p.key}: default {default!r}, declared {p.default!r}")
        if p.default is None and given is not None:
            wrong.append(f"{p.key}: default {default!r}, declared none")
        declared = {b: getattr(p, b) for b in ("gt", "ge", "lt", "le") if getattr(p, b) is not None}
        if p.key in _RANGE_IN_OTHER_KEYS:
            assert _RANGE_IN_OTHER_KEYS[p.key] in allowed, p.key
        elif _documented_bounds(allowed, p) != declared:
            wrong.append(f"{p.key}: allowed {allowed!r}, declared {declared}")
    assert not wrong
