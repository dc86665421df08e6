"""The design of experiments: which scenes a sweep runs.

* ``grid``: every combination of the parameters' values (``values``, or ``points`` from ``from`` to ``to``,
  evenly spaced, or evenly spaced in log for ``scale = "log"``);
* ``sobol``, ``halton``, ``lhs``: a low-discrepancy or Latin-hypercube design (``scipy.stats.qmc``, scrambled
  with ``design.seed``) of ``design.points`` points in the box ``from``-``to`` (log scale in log space);
* ``random``: uniform random points (numpy's generator seeded with ``design.seed``).

A parameter given by ``values`` in a sampled design is categorical: the sample picks one of its values.
Values are in the scene key's SI unit, so every point is a set of scene overrides.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Any

import numpy as np
from pydantic_core import PydanticCustomError

from ...scenes.errors import Problem
from ...scenes.units import ANGULAR, registry


@dataclass(frozen=True)
class Parameter:
    """One varied scene key: its values (grid) or bounds (sampled designs), in the key's SI unit."""

    key: str
    unit: str  # SI unit of the key (pint syntax), "1" for plain numbers, "" for words and flags
    values: tuple[Any, ...] | None  # explicit values, or the grid of from/to/points
    low: float | None = None
    high: float | None = None
    scale: str = "linear"
    display_unit: str = ""  # the unit the study file wrote the values in (for figures)
    listed: bool = False  # values listed in the study file (a sampled design picks among them)

    @property
    def numeric(self) -> bool:
        return self.unit != ""


def key_validator(key: str):
    """The scene's validator of a dotted key (SI / Int / Choice / Flag / Text), or None if no such key."""
    from ...scenes.schema import SECTIONS, model_at, validator_of

    parts = key.split(".")
    if len(parts) < 2 or parts[0] not in SECTIONS:
        return None
    model = model_at(SECTIONS[parts[0]][0], parts[1:-1])
    if model is None or parts[-1] not in model.model_fields:
        return None
    return validator_of(model, parts[-1])


def _unit_written(value: Any) -> str:
    """The unit a value was written with ("3 mm" -> "mm"), "" for bare numbers."""
    if not isinstance(value, str):
        return ""
    try:
        q = registry().Quantity(value.strip())
    except Exception:  # noqa: BLE001 - reported by parse_quantity
        return ""
    return f"{q.units:~}" if hasattr(q, "units") and tuple(q.unit_items()) else ""


def parameter_of(key: str, ps, *, sampled: bool = False) -> tuple[Parameter | None, list[Problem]]:
    """A :class:`Parameter` from a ``[parameters."<key>"]`` table, and the problems found. In a ``sampled`` design
    (not a grid) a range needs no ``points``: the design draws ``design.points`` values from ``from`` to ``to``
    (a range's points are then not used)."""
    from ...scenes.schema import key_paths

    where = f"parameters.{key}"
    v = key_validator(key)
    if v is None:
        from apexseal.suggest import did_you_mean

        given = ps.values if ps.values is not None else {k: v for k, v in (("from", ps.from_), ("to", ps.to),
                                                                          ("points", ps.points)) if v is not None}
        return None, [Problem(where, given, "not a scene key" + did_you_mean(key, key_paths())
                              + "; any key of docs/scenes.md, e.g. spring.ks, spring.delta_s, operation.rpm")]
    unit = getattr(v, "unit", None) or ("1" if type(v).__name__ == "Int" else "")
    problems: list[Problem] = []
    ranged = ps.from_ is not None or ps.to is not None or ps.points is not None
    if ps.values is not None and ranged:
        problems.append(Problem(where, "values and from/to/points", "give either values or from, to and points"))
    if ps.values is None and not ranged:
        problems.append(Problem(where, "{}", "give values = [...] or from, to and points"))
    if problems:
        return None, problems

    def number(x: Any, sub: str) -> float | None:
        """``x`` as the scene reads it (a quoted plain number "0.1" too); its range is the scene's to check, with
        the points that hold it. What is no number of the key's kind names what is allowed."""
        if hasattr(v, "convert"):  # a quantity (SI): the scene's own conversion
            try:
                return v.convert(x, ranged=False)
            except PydanticCustomError as exc:
                problems.append(Problem(f"{where}.{sub}", x, exc.context["message"]))
                return None
        if isinstance(x, bool) or not isinstance(x, int | float):
            expects = getattr(v, "expects", None)
            problems.append(Problem(f"{where}.{sub}", x, f"expected {expects() if expects else 'a number'}"))
            return None
        return x

    display = ""
    if ps.values is not None:
        if not ps.values:
            return None, [Problem(f"{where}.values", [], "give at least one value")]
        if unit == "":
            values = tuple(ps.values)  # words and flags: the scene checks them
        else:
            values = tuple(number(x, f"values[{i}]") for i, x in enumerate(ps.values))
            display = _unit_written(ps.values[0])
        if not problems:
            problems += _repeated(f"{where}.values", ps.values, values, unit)
        nums = [x for x in values if isinstance(x, int | float) and not isinstance(x, bool)]
        low, high = (min(nums), max(nums)) if nums and len(nums) == len(values) else (None, None)
        return (None if problems else Parameter(key, unit, values, low, high, ps.scale, display, listed=True)), problems

    if unit == "":
        return None, [Problem(where, ps.from_, "a key of words or flags takes values = [...], not from/to")]
    for sub, x in (("from", ps.from_), ("to", ps.to), ("points", ps.points)):
        if x is None and not (sampled and sub == "points"):
            problems.append(Problem(f"{where}.{sub}", "(missing)", "from, to and points go together" if not sampled
                                    else "from and to go together (a sampled design draws design.points values "
                                    "between them)"))
    if problems:
        return None, problems
    low, high = number(ps.from_, "from"), number(ps.to, "to")
    if problems:
        return None, problems
    if not low < high:
        si = f" ({low:g} {unit} is not below {high:g} {unit})" if unit not in ("", "1") else ""
        problems.append(Problem(where, f"from {ps.from_} to {ps.to}", f"from must be below to{si}"))
    if ps.scale == "log" and low <= 0:
        problems.append(Problem(f"{where}.from", ps.from_, "a log scale needs from > 0"))
    if problems:
        return None, problems
    if ps.points is None:  # a sampled design's range: no grid of its own
        return Parameter(key, unit, None, low, high, ps.scale, _unit_written(ps.from_)), problems
    if ps.scale == "log":
        grid = np.geomspace(low, high, ps.points)
    else:
        grid = np.linspace(low, high, ps.points)
    if unit == "1" and type(v).__name__ == "Int":
        grid = np.unique(np.round(grid).astype(int))
        values = tuple(int(x) for x in grid)
        if len(values) < ps.points:  # an integer key has fewer distinct values in the range than points asked
            return None, [Problem(f"{where}.points", ps.points, f"an integer key takes {len(values)} distinct "
                                  f"value(s) from {ps.from_} to {ps.to}; allowed: a range holding at least {ps.points} "
                                  "integers, or fewer points")]
    else:
        values = tuple(float(f"{x:.12g}") for x in grid)  # 12 digits, as scenes hash them
        if len(set(values)) < ps.points:  # a range too narrow for its points: the same point several times
            return None, [Problem(f"{where}.points", ps.points, f"{ps.points} points from {ps.from_} to {ps.to} give "
                                  f"{len(set(values))} distinct value(s) at 12 significant digits (as scenes keep "
                                  "them); allowed: a wider range, or fewer points")]
    return Parameter(key, unit, values, low, high, ps.scale, _unit_written(ps.from_)), problems


def _repeated(where: str, given: list, values: tuple, unit: str) -> list[Problem]:
    """A problem for each value listed more than once (compared in SI at the 12 significant digits scenes keep, so
    "1 mm" and "0.001 m" are one value): each repeat ran the same point again, and weighed double in a sampled
    design."""
    from ...scenes.errors import show_value

    at: dict[Any, list[int]] = {}
    for i, x in enumerate(values):
        same = float(f"{x:.12g}") if isinstance(x, int | float) and not isinstance(x, bool) else (type(x), x)
        at.setdefault(same, []).append(i)
    out = []
    for idx in at.values():
        if len(idx) > 1:
            x = values[idx[0]]
            shown = f"{x:g} {unit}" if unit not in ("", "1") else show_value(x)
            where_ = ", ".join(f"values[{i}]" for i in idx)
            out.append(Problem(where, given, f"{shown} repeated ({where_}); allowed: distinct values (each is one "
                               "point of the design)"))
    return out


def _scaled(u: np.ndarray, p) -> list[Any]:
    """Unit-cube samples ``u`` (in [0, 1)) mapped onto a parameter's box or values."""
    if p.listed:
        idx = np.minimum((u * len(p.values)).astype(int), len(p.values) - 1)
        return [p.values[i] for i in idx]
    if p.scale == "log":
        x = np.exp(np.log(p.low) + u * (np.log(p.high) - np.log(p.low)))
    else:
        x = p.low + u * (p.high - p.low)
    if p.unit == "1" and (isinstance(p.values[0], int) if p.values else type(key_validator(p.key)).__name__ == "Int"):
        return [int(round(v)) for v in x]
    return [float(f"{v:.12g}") for v in x]


def scene_values(study, point: dict[str, Any]) -> dict[str, Any]:
    """A point's values as :meth:`Scene.with_overrides` takes them: an angle or angular speed with its SI unit
    written out (a scene refuses a bare angle: deg or rad is ambiguous; a sweep of operation.start_angle was refused
    at every point), every other value as it is (a bare number is in the key's SI unit)."""
    units = {p.key: p.unit for p in study.parameters}
    return {k: f"{v!r} {units[k]}" if units.get(k) in ANGULAR and isinstance(v, float | int) else v
            for k, v in point.items()}


def design_points(study) -> list[dict[str, Any]]:
    """The points of a study, in order: each a dict of scene key -> value (SI)."""
    pars = study.parameters
    if study.design == "grid":
        return [dict(zip((p.key for p in pars), combo, strict=True))
                for combo in itertools.product(*(p.values for p in pars))]
    n, d = study.points, len(pars)
    if study.design == "random":
        u = np.random.default_rng(study.seed).random((n, d))
    else:
        from scipy.stats import qmc

        engine = {"sobol": qmc.Sobol, "halton": qmc.Halton, "lhs": qmc.LatinHypercube}[study.design]
        u = engine(d=d, scramble=True, seed=study.seed).random(n) if study.design != "lhs" else \
            engine(d=d, seed=study.seed).random(n)
    columns = [_scaled(u[:, j], p) for j, p in enumerate(pars)]
    return [{p.key: columns[j][i] for j, p in enumerate(pars)} for i in range(n)]


#: distinct problems (key, value, message) of refused points after which the check of a study's points stops
MAX_REFUSALS = 10
#: points named in full in a problem shared by more points
POINTS_SHOWN = 5


def checked_points(study) -> tuple[list[tuple[int, Any, dict[str, Any]]], list[Problem], str | None]:
    """(point, scene, overrides) of every point of ``study`` whose scene its values make, the problems of those
    they do not (each distinct problem once, with the points it refuses: a value that recurs across a grid is one
    line, not one per point; keyed ``parameters.<key>``), and a note when the check stopped early: past
    :data:`MAX_REFUSALS` distinct problems it says at which point."""
    from ...scenes.errors import SceneError, show_value

    designs = design_points(study)
    out: list[tuple[int, Any, dict[str, Any]]] = []
    refused: dict[tuple[str, str, str], tuple[Any, list[int]]] = {}
    note = None
    for i, overrides in enumerate(designs):
        try:
            out.append((i, study.scene.with_overrides(**scene_values(study, overrides)), overrides))
        except SceneError as err:
            for p in err.errors:
                refused.setdefault((p.key, show_value(p.value), p.message), (p, []))[1].append(i)
            if len(refused) >= MAX_REFUSALS and i + 1 < len(designs):
                note = f"checked points 0 to {i} of {len(designs)}; the others were not checked"
                break
    problems = [Problem(f"parameters.{p.key}", p.value, f"{p.message} ({_points(at)})") for p, at in refused.values()]
    return out, problems, note


def _points(at: list[int]) -> str:
    """The points a problem refuses, e.g. "point 1", "points 1, 4, 7", "20 points: 1, 4, 7, 10, 13, ..., 58"."""
    if len(at) == 1:
        return f"point {at[0]}"
    if len(at) <= POINTS_SHOWN + 1:
        return "points " + ", ".join(map(str, at))
    return f"{len(at)} points: {', '.join(map(str, at[:POINTS_SHOWN]))}, ..., {at[-1]}"
