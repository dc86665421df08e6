"""A scene written out in full: every key with its value and unit, overrides applied, defaults made explicit.

:func:`resolved_toml` is what a saved result keeps as ``scene.toml``: loading it gives a scene with the same
content hash as the one that ran (:meth:`Scene.content_hash`), so ``apexseal simulate folder/scene.toml``
re-runs the result. Quantities are written in their SI unit with full precision (``"0.00306 m"``), so nothing
is rounded; a pressure table is written beside it (``pressure.csv``, in Pa) and named relative to it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .fields import SI, Each
from .pressure import UnreadTable
from .schema import GAS_SOURCES, SECTION_ORDER, SECTIONS, Section, _sub_model, validator_of

#: the file name of the pressure table written beside a resolved scene
TABLE_FILE = "pressure.csv"


def _quantity(value: float, unit: str) -> Any:
    if unit == "1":
        return float(value)
    text = {"kg*m^2": "kg*m^2", "N*s/m": "N*s/m", "kg/m^3": "kg/m^3"}.get(unit, unit)
    return f"{float(value)!r} {text}"


def _values(model: Section, prefix: str) -> tuple[list[tuple[str, Any]], list[tuple[str, Section]]]:
    """The plain keys of a section (value with unit) and its sub-tables."""
    plain, tables = [], []
    for name, field in type(model).model_fields.items():
        value = getattr(model, name)
        if _sub_model(field.annotation) is not None:
            if value is not None:
                tables.append((f"{prefix}.{name}", value))
            continue
        if value is None:
            continue
        spec = validator_of(type(model), name)
        if isinstance(spec, Each):  # a schedule's knots
            value = [_quantity(v, spec.unit) for v in value]
        elif isinstance(spec, SI):
            value = _quantity(value, spec.unit)
        plain.append((name, value))
    return plain, tables


def _toml_value(v: Any) -> str:
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(v)
    return '"' + str(v).replace("\\", "\\\\").replace('"', '\\"') + '"'


def _table(name: str, items: list[tuple[str, Any]]) -> list[str]:
    return [f"[{name}]", *(f"{k} = {_toml_value(v)}" for k, v in items), ""]


#: the built-in sections of model parameters, written first in this order
PARAMETER_SECTIONS = SECTION_ORDER[:SECTION_ORDER.index("pressure")]
#: the built-in sections written after them, each its own way
OTHER_SECTIONS = SECTION_ORDER[SECTION_ORDER.index("pressure"):]


def stamped_toml(scene, what: str, rerun: str, notes: tuple[str, ...] = (), *,
                 written=None) -> tuple[str, dict[str, str]]:
    """:func:`resolved_toml` of ``written`` (default: ``scene``) under the header a result or study folder's
    scene.toml carries: what wrote it (``what``: "result <run id>", "preload study <run id>"), the name and content
    hash of ``scene``, ``notes`` (one line each: how ``written`` differs from it), and how to run it again
    (``rerun``)."""
    head = [f"apexseal {what}, scene {scene.name}, content hash {scene.content_hash()}", *notes, f"re-run: {rerun}"]
    return resolved_toml(scene if written is None else written, header="\n".join(head))


def resolved_toml(scene, *, header: str = "") -> tuple[str, dict[str, str]]:
    """The scene as TOML text with every value explicit, and the extra files it names (file name -> text)."""
    lines = [f"# {line}" if line else "#" for line in header.splitlines()]
    lines += ["# every value of the scene that ran, in SI with its unit (apexseal writes this file)", ""]
    files: dict[str, str] = {}

    from apexseal.derive.submodels.registry import alternatives

    left_out = scene.left_out_keys()  # a user's or a package's submodel that is off: not written

    def walk(name: str, model: Section) -> None:
        plain, tables = _values(model, name)
        plain = [(k, v) for k, v in plain if f"{name}.{k}" not in left_out]
        given = {f"{name}.{k}" for k, _ in plain}
        # a damping coefficient given explicitly replaces its ratio, whose default is then not written either
        dropped = {b for a, b in alternatives() if a in given and b in given}
        plain = [(k, v) for k, v in plain if f"{name}.{k}" not in dropped]
        if plain:  # a section of nothing but keys left out (an effect that is off) is left out too
            lines.extend(_table(name, plain))
        for sub_name, sub in tables:
            walk(sub_name, sub)

    for section in PARAMETER_SECTIONS:
        walk(section, getattr(scene, section))
    for section, model in getattr(scene, "_sections", {}).items():  # the sections of a user's submodels
        if section not in PARAMETER_SECTIONS + OTHER_SECTIONS and model is not None:
            walk(section, model)
    p = scene.pressure
    d = p.to_dict()
    # chamber_pressure off: the table no law read is written beside all the same when its file is there and valid
    # (switching the effect on in the written scene then reads it); a file that is not stays named as the scene
    # names it, relative to the scene that ran
    table = p.load() if isinstance(p, UnreadTable) else p if d["source"] == "table" else None
    if table is not None:
        lines += _table("pressure", [("source", "table"), ("file", TABLE_FILE), ("unit", "Pa")])
        rows = "\n".join(f"{t!r},{a!r},{b!r}" for t, a, b in zip(np.asarray(table.theta_deg, float).tolist(),
                                                                  np.asarray(table.pa, float).tolist(),
                                                                  np.asarray(table.pb, float).tolist(), strict=True))
        files[TABLE_FILE] = "theta_deg,Pa,Pb\n" + rows + "\n"
    elif isinstance(p, UnreadTable):
        lines += [f"# {p.file} was not found or not valid beside the scene that ran; no law read it "
                  "(effects.chamber_pressure is off)"]
        lines += _table("pressure", [("source", "table"), ("file", p.file), ("unit", p.unit)])
    elif d["source"] == "constant":
        lines += _table("pressure", [("source", "constant"), ("Pa", _quantity(d["Pa"], "Pa")),
                                     ("Pb", _quantity(d["Pb"], "Pa"))])
    elif d["source"] in GAS_SOURCES:  # the chamber gas model: its [gas] keys follow
        lines += _table("pressure", [("source", d["source"])])
        gas = getattr(scene, "_sections", {}).get("gas")
        if gas is not None:
            walk("gas", gas)
    else:
        lines += _table("pressure", [("source", "none")])
    lines += _table("effects", [(k, v) for k, v in scene.effects.as_dict().items() if f"effects.{k}" not in left_out])
    lines += _table("assumptions", [(k, v) for k, v in scene.assumptions.as_dict().items()
                                    if f"assumptions.{k}" not in left_out])
    walk("solver", scene.solver)
    assert set(SECTIONS) >= {"machine", "pressure", "solver"}  # the sections written above
    return "\n".join(lines), files
