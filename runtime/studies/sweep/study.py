"""The study file of a sweep: a base scene, the parameters to vary, the design, what to collect, the constraints.

A study is a TOML file (``docs/sweeps.md`` lists every key)::

    [study]
    name = "preload-map"
    scene = "default"                      # the embedded default scene, or a scene file relative to this file

    [scene]                                # overrides of the base scene (its dotted keys, as in with_overrides)
    "operation.revolutions" = 1

    [parameters."spring.delta_s"]          # a scene key to vary: from/to/points (scale linear or log) or values
    from = "0.5 mm"
    to = "4 mm"
    points = 8

    [design]
    kind = "grid"                          # grid, random, sobol, halton or lhs
    points = 64                            # random and low-discrepancy designs only
    seed = 0

    [collect]
    quantities = ["friction_power.total", "liftoff_fraction"]

    [run]
    max_wall_time = "120 s"                # wall-time budget of each point

    [feasible]                             # the constraints whose region the figures show
    liftoff_fraction = { max = 0 }
    "friction_power.total" = { max = "35 W" }

Every problem of a study file is reported at once in one :class:`StudyError`, each naming the key,
the value given and what is allowed; values of the scene keys are also checked by the scene itself
(:meth:`Scene.with_overrides`), so the scene's ranges apply.
"""

from __future__ import annotations

import hashlib
import json
import math
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from apexseal.suggest import did_you_mean

from ...results.quantities import quantity_help, quantity_unit
from ...scenes.errors import Problem, show_value
from .design import Parameter, checked_points, parameter_of

#: the designs of experiments (design.py)
DESIGNS = ("grid", "random", "sobol", "halton", "lhs")
#: the most points a study may ask for (a typo guard: 1e6 points is days on any cluster)
MAX_POINTS = 1_000_000


class StudyError(ValueError):
    """A study file that cannot be used; ``errors`` lists every ``(key, value, message)``; ``note`` says what the
    list leaves out."""

    def __init__(self, errors: list[tuple[str, Any, str]], source: str | None = None, note: str | None = None) -> None:
        self.errors = [Problem(*e) for e in errors]
        self.source = source
        head = f"study {source}: " if source else "study: "
        head += f"{len(self.errors)} problem{'s' if len(self.errors) != 1 else ''}"
        head += f" ({note})" if note else ""
        super().__init__("\n".join([head, *(f"  {p}" for p in self.errors)]))

    def keys(self) -> list[str]:
        return [p.key for p in self.errors]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", populate_by_name=True)


#: a study's name names its default output folder (apexseal-out/<name>): one plain folder name
NAME_PATTERN = r"^[A-Za-z0-9][A-Za-z0-9._-]{0,99}$"


class StudySection(_Model):
    name: str = Field("sweep", pattern=NAME_PATTERN)
    scene: str = "default"
    description: str = ""


class ParameterSection(_Model):
    values: list[Any] | None = None
    from_: Any = Field(None, alias="from")
    to: Any = None
    points: int | None = Field(None, ge=2, le=100_000, strict=True)
    scale: Literal["linear", "log"] = "linear"


class DesignSection(_Model):
    kind: Literal["grid", "random", "sobol", "halton", "lhs"] = "grid"
    points: int | None = Field(None, ge=1, le=MAX_POINTS, strict=True)
    seed: int = Field(0, ge=0, strict=True)


class CollectSection(_Model):
    quantities: list[str] = Field(default_factory=lambda: ["friction_power.total", "liftoff_fraction"])


class RunSection(_Model):
    max_wall_time: Any = "600 s"


class Bound(_Model):
    min: Any = None
    max: Any = None


class StudyFile(_Model):
    study: StudySection = Field(default_factory=StudySection)
    scene: dict[str, Any] = Field(default_factory=dict)
    parameters: dict[str, ParameterSection]
    design: DesignSection = Field(default_factory=DesignSection)
    collect: CollectSection = Field(default_factory=CollectSection)
    run: RunSection = Field(default_factory=RunSection)
    feasible: dict[str, Bound] = Field(default_factory=dict)

    @field_validator("parameters", mode="before")
    @classmethod
    def _values_shorthand(cls, value: Any) -> Any:
        """``"spring.ks" = [1e3, 3e3]`` is short for ``[parameters."spring.ks"] values = [1e3, 3e3]``."""
        if isinstance(value, dict):
            return {k: {"values": v} if isinstance(v, list) else v for k, v in value.items()}
        return value


@dataclass(frozen=True)
class Constraint:
    """``min <= column <= max`` (either bound may be absent), in the column's unit."""

    column: str
    unit: str
    min: float | None
    max: float | None

    def holds(self, values):
        """Elementwise: the values (array or Series) that meet the bounds (NaN never does)."""
        import numpy as np

        v = np.asarray(values, float)
        ok = np.isfinite(v)
        if self.min is not None:
            ok &= v >= self.min
        if self.max is not None:
            ok &= v <= self.max
        return ok

    def describe(self) -> str:
        u = "" if self.unit in ("", "1") else f" {self.unit}"
        if self.min is not None and self.max is not None:
            return f"{self.min:g}{u} <= {self.column} <= {self.max:g}{u}"
        if self.min is not None:
            return f"{self.column} >= {self.min:g}{u}"
        return f"{self.column} <= {self.max:g}{u}"


@dataclass(frozen=True)
class Study:
    """A checked study: base scene (with the [scene] overrides applied), parameters, design and settings."""

    name: str
    description: str
    scene: Any  # apexseal Scene
    parameters: tuple[Parameter, ...]
    design: str
    points: int | None
    seed: int
    quantities: tuple[str, ...]
    max_wall_time: float
    constraints: tuple[Constraint, ...]
    source: str = "<string>"
    raw: dict = field(default_factory=dict, repr=False)
    #: (content hash of the study they are of, ((point, scene, overrides) of every point, each scene checked)) as
    #: :func:`study_from_dict` found them; None: not checked yet (a sweep checks them first: .execute.scenes_of, which
    #: checks them again for a study changed since, dataclasses.replace)
    points_checked: tuple | None = field(default=None, repr=False, compare=False)

    def content_hash(self) -> str:
        """sha256 of what decides the points and their results (not of where the file lives)."""
        content = {"scene": self.scene.content_hash(), "parameters": [vars(p) for p in self.parameters],
                   "design": self.design, "points": self.points, "seed": self.seed,
                   "quantities": list(self.quantities), "max_wall_time": self.max_wall_time}
        text = json.dumps(content, sort_keys=True, default=str, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()

    def feasible(self, table):
        """Per row of a results table: completed and every constraint met (all completed rows if none)."""
        ok = (table["status"] == "completed").to_numpy()
        for c in self.constraints:
            ok = ok & c.holds(table[c.column])
        return ok

    def units(self) -> dict[str, str]:
        """Column -> unit of every parameter and quantity column."""
        out = {p.key: p.unit for p in self.parameters}
        out.update({q: quantity_unit(q) or "" for q in self.quantities})
        return out


def load_study(path: str | Path) -> Study:
    """Read and check a study file (TOML); raises :class:`StudyError` listing every problem."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8-sig")  # without a byte-order mark (an editor's), as a scene file
    except (OSError, UnicodeDecodeError) as exc:
        raise StudyError([("study", str(path), f"cannot read: {getattr(exc, 'strerror', None) or exc}")],
                         source=str(path)) from None
    return study_from_toml(text, base_dir=p.parent, source=str(path))


def study_from_toml(text: str, *, base_dir: str | Path | None = None, source: str = "<string>") -> Study:
    """Check a study given as TOML text; scene paths are relative to ``base_dir`` (default: current folder)."""
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise StudyError([("toml", "", f"malformed TOML: {exc}")], source=source) from None
    return study_from_dict(raw, base_dir=Path(base_dir) if base_dir is not None else Path.cwd(), source=source)


#: pydantic's range errors: their bound in the error's context, and its sign
BOUNDS = {"greater_than": ("gt", ">"), "greater_than_equal": ("ge", ">="), "less_than": ("lt", "<"),
          "less_than_equal": ("le", "<=")}


def _pydantic_problems(exc: ValidationError, raw: dict) -> list[Problem]:
    out = []
    for err in exc.errors():
        loc = [str(x) for x in err["loc"]]
        key = ".".join(loc) or "study"
        value: Any = raw
        for part in err["loc"]:
            value = value.get(part, "(missing)") if isinstance(value, dict) else "(missing)"
        msg = err["msg"]
        if err["type"] == "extra_forbidden" and loc[0] == "parameters" and len(loc) == 3 and isinstance(value, dict):
            # [parameters.operation.rpm] is TOML for a parameter "operation" with a table "rpm"
            value = show_value(value)
            msg = (f'a table in a parameter\'s table; to vary the scene key {loc[1]}.{loc[2]}, quote its dotted name: '
                   f'[parameters."{loc[1]}.{loc[2]}"]')
        elif (err["type"] == "extra_forbidden" and loc[0] == "parameters" and len(loc) == 3
              and loc[2] not in _known_keys(loc[:2])):
            # spring.ks = [...] in [parameters] is TOML for a parameter "spring" with a key "ks"
            written = json.dumps(value, default=str)  # the TOML of a list of strings and numbers
            msg = (f"unknown key of a parameter's table; to vary the scene key {loc[1]}.{loc[2]}, quote its dotted "
                   f'name: "{loc[1]}.{loc[2]}" = {written}')
        elif err["type"] == "extra_forbidden":
            parent = _known_keys(loc[:-1])
            msg = "unknown key" + did_you_mean(loc[-1], parent, cutoff=0.5) + (
                f"; known: {', '.join(parent)}" if parent else "")
        elif err["type"] == "literal_error":
            msg = "not allowed; allowed: " + err["ctx"]["expected"]
        elif err["type"] == "string_pattern_mismatch" and key == "study.name":
            msg = ("not a plain folder name (it names the output folder apexseal-out/<name>); allowed: up to 100 "
                   "letters, digits, '.', '_' and '-', starting with a letter or digit")
        elif err["type"] in BOUNDS:
            bound, sign = BOUNDS[err["type"]]
            msg = f"{value} is out of range; allowed: n {sign} {err['ctx'][bound]}"
        elif err["type"] == "int_type":
            msg = "expected an integer (a TOML integer, not a string or a float)"
        elif err["type"] == "model_type" and loc[0] == "parameters" and len(loc) == 2:
            msg = ("give the values to try as a list, e.g. [1e3, \"3e3 N/m\"], or a table with values or "
                   "from, to and points")
        out.append(Problem(key, value, msg))
    return out


def _known_keys(loc: list[str]) -> list[str]:
    model: Any = StudyFile
    sections = {"study": StudySection, "design": DesignSection, "collect": CollectSection, "run": RunSection}
    if not loc:
        return [f.alias or n for n, f in model.model_fields.items()]
    if loc[0] in sections and len(loc) == 1:
        return list(sections[loc[0]].model_fields)
    if loc[0] == "parameters" and len(loc) == 2:
        return ["values", "from", "to", "points", "scale"]
    if loc[0] == "feasible" and len(loc) == 2:
        return ["min", "max"]
    return []


def _dotted(table: dict, prefix: str = "") -> dict:
    """The [scene] table as dotted keys: ``solver.rtol = 5`` (which TOML reads as a table ``solver``) sets that key,
    as ``"solver.rtol" = 5`` does, instead of replacing the base scene's whole [solver]."""
    out = {}
    for key, value in table.items():
        name = f"{prefix}{key}"
        out.update(_dotted(value, name + ".") if isinstance(value, dict) else {name: value})
    return out


def _structure(raw: dict, source: str) -> tuple[StudyFile, list[Problem], set[str]]:
    """The study's tables checked for their keys and types, with the problems found and the tables that had them.

    A table with a problem is left at its defaults but for its keys that are well formed ([study]'s scene stays the
    study's scene), and a parameter with one is left out (its name is in the set returned, as
    ``parameters.<name>``), so the checks of the others still run and every problem is reported at once, not the
    structural ones first."""
    try:
        return StudyFile.model_validate(raw), [], set()
    except ValidationError as exc:
        problems, errors = _pydantic_problems(exc, raw), exc.errors()
    malformed = {str(e["loc"][0]) for e in errors if e["loc"]}

    def bad(table: str) -> set[str]:  # the keys of ``table`` with a problem of their own
        return {str(e["loc"][1]) for e in errors if len(e["loc"]) > 1 and e["loc"][0] == table}

    params, bad_params = raw.get("parameters"), bad("parameters")
    lenient = {k: v for k, v in raw.items() if k not in malformed}
    for table in ("study", "design", "collect", "run"):  # a table's keys that are well formed stay
        bad_keys = bad(table)
        whole = any(tuple(e["loc"]) == (table,) for e in errors)  # the table itself is wrong (not a table)
        if table in malformed and isinstance(raw.get(table), dict) and not whole:
            lenient[table] = {k: v for k, v in raw[table].items() if k not in bad_keys}
    malformed |= {f"parameters.{name}" for name in bad_params}
    # the parameters that are well formed (none: their problems say why)
    lenient["parameters"] = {k: v for k, v in params.items() if k not in bad_params} if isinstance(params, dict) else {}
    try:
        return StudyFile.model_validate(lenient), problems, malformed
    except ValidationError:  # pragma: no cover - every table left is at its defaults or was valid
        raise StudyError(problems, source=source) from None


def _unread(parameters, scene, given: dict) -> list[Problem]:
    """A varied scene key that no law of the study's model reads (its effect off, or the modelling choice that reads
    it not made, in the scene and not varied: :func:`apexseal.runtime.scenes.checks.unread_keys`, which also holds
    the inputs that only one effect reads, the constant chamber pressures): every point would be the same run."""
    from ....derive.effects import declared as effects_declared
    from ....derive.options import needed_effects
    from ....derive.submodels.registry import choice_key, unmet
    from ...scenes.checks import key_needing, unread_keys

    slots = effects_declared()

    def lineage(name: str) -> list[str]:  # the effect and its parents (varying a parent varies its children)
        return [name, *lineage(slots[name].parent)] if name in slots and slots[name].parent else [name]

    def keys(entry: str) -> list[str]:  # the scene keys that decide whether an entry of a needs holds
        slot, _, choice = entry.partition("=")
        return [f"assumptions.{slot}", choice_key(slot)] if choice else [f"effects.{e}" for e in lineage(entry)]

    varied = {p.key for p in parameters}
    unread = unread_keys(scene.effects, scene.assumptions)
    out = []
    for p in parameters:
        need = key_needing(p.key, scene.effects, scene.assumptions)
        if need is None or any(k in varied for n in needed_effects(need) for k in keys(n)):
            continue
        if p.key in unread:
            remedy = ("make that choice in [scene]" if any("=" in n for n in needed_effects(need)) else
                      "switch it on in [scene] (with the effects it needs)")
            out.append(Problem(f"parameters.{p.key}", show_value(given.get(p.key, "(varied)")),
                               f"read by no law while {unmet(need)} in the study's scene: every point would be the "
                               f"same run; {remedy}, or vary it too"))
    return out


def study_from_dict(raw: dict, *, base_dir: Path, source: str = "<string>") -> Study:
    """Check a parsed study (see the module docstring for the keys)."""
    import apexseal
    from apexseal.runtime.scenes.errors import SceneError
    from apexseal.runtime.scenes.scene import scene_file

    spec, problems, malformed = _structure(raw, source)

    # base scene and its fixed overrides
    scene = None
    path = scene_file(spec.study.scene, base_dir)  # load_scene's own resolver: "default" is the embedded scene
    overrides = _dotted(spec.scene)  # solver.rtol = 5 sets that key (a table would replace the whole section)
    try:
        base = apexseal.load_scene(path)
    except SceneError as exc:
        base, broken = None, exc
    try:
        if base is not None:
            scene = base.with_overrides(**overrides) if overrides else base
        else:  # the [scene] keys may repair the base file (they replace its keys before it is checked, as --set)
            scene = apexseal.load_scene(path, overrides=overrides) if overrides and path.is_file() else None
            if scene is None:
                raise broken
    except SceneError as exc:  # a key it writes, or any while the base loads alone, is [scene]'s; else the base's
        problems += [Problem(f"scene.{p.key}", p.value, p.message)
                     if base is not None or any(p.key == k or p.key.startswith(k + ".") for k in overrides) else
                     Problem("study.scene", spec.study.scene, p.message if p.key == "scene" else
                             f"{p.key} = {p.value!r}: {p.message}") for p in exc.errors]

    parameters = []
    for key, ps in spec.parameters.items():
        par, more = parameter_of(key, ps, sampled="design" not in malformed and spec.design.kind != "grid")
        problems += more
        if par is not None:
            parameters.append(par)
    if not spec.parameters and "parameters" not in malformed:
        problems.append(Problem("parameters", "(none)", "vary at least one scene key, e.g. [parameters.\"spring.ks\"]"))
    if scene is not None:
        problems += _unread(parameters, scene, raw.get("parameters", {}))

    d = spec.design
    if "design" in malformed:
        pass  # its problems are reported; a design left at its defaults says nothing more
    elif d.kind == "grid":
        if d.points is not None:
            problems.append(Problem("design.points", d.points, "a grid has the product of the parameters' points; "
                                    "remove design.points or choose kind = \"sobol\", \"lhs\", \"halton\" or \"random\""))
        n = math.prod(len(p.values or ()) for p in parameters) if parameters else 0
        if n > MAX_POINTS:
            problems.append(Problem("parameters", n, f"the grid has {n} points; allowed: at most {MAX_POINTS}"))
    else:
        if d.points is None:
            problems.append(Problem("design.points", "(missing)", f"a {d.kind} design needs the number of points, "
                                    f"an integer >= 1 and <= {MAX_POINTS}"))
        for p in parameters:
            if p.low is None and not p.values:
                problems.append(Problem(f"parameters.{p.key}", "", "give from/to (or values) to sample"))
        if d.kind == "sobol" and d.points is not None and d.points & (d.points - 1):
            problems.append(Problem("design.points", d.points, "a Sobol design needs a power of 2 (balance "
                                    "properties); allowed: 1, 2, 4, ..., e.g. 64 or 128"))

    known = quantity_help()
    for q in spec.collect.quantities if "collect" not in malformed else ():
        if q not in known:
            problems.append(Problem("collect.quantities", q, "unknown quantity" + did_you_mean(
                q, known, cutoff=0.5) + f"; known: {', '.join(known)}"))
    if not spec.collect.quantities and "collect" not in malformed:
        problems.append(Problem("collect.quantities", [], "collect at least one quantity"))

    from ...scenes.units import QuantityError, parse_quantity

    try:
        budget = parse_quantity(spec.run.max_wall_time, "s", key="run.max_wall_time")
        if not 0 < budget <= 7 * 86400:
            problems.append(Problem("run.max_wall_time", spec.run.max_wall_time,
                                    f"{budget:g} s is out of range; allowed: > 0 s and <= 604800 s (a week)"))
    except QuantityError as exc:
        problems.append(Problem("run.max_wall_time", spec.run.max_wall_time, exc.reason))
        budget = math.nan

    columns = {q: quantity_unit(q) for q in spec.collect.quantities if quantity_unit(q) is not None}
    columns.update({p.key: p.unit for p in parameters if p.numeric})
    constraints = []
    for col, b in spec.feasible.items() if "collect" not in malformed else ():  # its columns: the collected ones
        if f"parameters.{col}" in malformed or (col in spec.parameters and col not in {p.key for p in parameters}):
            continue  # a varied parameter left out for a problem of its own, reported as such
        if col not in columns:
            nested = isinstance(b.min, dict) or isinstance(b.max, dict)
            hint = f' (quote a dotted name: "{col}.{next(iter(b.max or b.min))}" = {{ max = ... }})' if nested else ""
            problems.append(Problem(f"feasible.{col}", show_value(raw["feasible"][col]), "not a collected quantity "
                                    f"or a numeric varied parameter{hint}; allowed: {', '.join(columns) or '(none)'}"))
            continue
        if b.min is None and b.max is None:
            problems.append(Problem(f"feasible.{col}", "{}", "give min, max or both"))
            continue
        bounds = {}
        for side in ("min", "max"):
            v = getattr(b, side)
            if v is None:
                bounds[side] = None
                continue
            try:
                bounds[side] = parse_quantity(v, columns[col] or "1", key=f"feasible.{col}.{side}")
            except QuantityError as exc:
                problems.append(Problem(f"feasible.{col}.{side}", v, exc.reason))
                bounds[side] = None
        if bounds["min"] is not None and bounds["max"] is not None and bounds["min"] > bounds["max"]:
            problems.append(Problem(f"feasible.{col}", f"min {bounds['min']:g} > max {bounds['max']:g}",
                                    "min must not exceed max"))
        constraints.append(Constraint(col, columns[col] or "1", bounds["min"], bounds["max"]))

    study = Study(name=spec.study.name, description=spec.study.description, scene=scene,
                  parameters=tuple(parameters), design=d.kind, points=d.points, seed=d.seed,
                  quantities=tuple(spec.collect.quantities), max_wall_time=budget, constraints=tuple(constraints),
                  source=source, raw=raw)
    note = None
    if scene is not None and parameters and not any(p.key.startswith(("parameters", "design")) for p in problems):
        # every point's scene, checked here with the file's other problems (all at once), and kept for the sweep
        points, refused, note = checked_points(study)
        problems += refused
        study = replace(study, points_checked=(study.content_hash(), tuple(points)))
    if problems:
        raise StudyError(problems, source=source, note=note)
    return study
