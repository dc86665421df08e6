"""Scenes: one TOML file holds everything a run needs, checked before anything is built.

A scene has the sections ``[machine]``, ``[operation]``, ``[seal]`` (required) and ``[spring]``,
``[contacts]``, ``[friction]``, ``[pressure]``, ``[effects]``, ``[assumptions]``, ``[solver]``
(optional; the keys an effect reads are required while it is on); ``docs/scenes.md`` lists every key.
Quantities carry units (``"3 mm"``, ``"1500 rpm"``, ``"6 bar"``); bare numbers are SI.

>>> scene = load_scene()                       # the embedded default (the paper's case study)
>>> scene.parameter_vector()                   # the vector of its model (its effects), SI
>>> fast = scene.with_overrides(**{"operation.rpm": 6000, "contacts.kw": "2e9 N/m"})

Every problem of a scene (unknown keys, wrong units or types, out-of-range and
physically inconsistent values, a bad pressure table) is reported at once in one
:class:`~.scene_errors.SceneError`.
"""

from __future__ import annotations

import copy
import hashlib
import importlib.resources
import json
import numbers
import re
import tomllib
import warnings
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from apexseal.derive.assumptions import Assumptions
from apexseal.derive.effects import Effects
from apexseal.files import path_argument
from apexseal.stacklevel import user_stacklevel

from .checks import (
    check_consistency,
    check_damping,
    check_needed,
    check_plausible,
    check_set_by,
    check_superseded,
    check_unread_tables,
    check_wall_deflection,
    ignored_values,
    resolve_assumptions,
    resolve_effects,
    unread_keys,
)
from .errors import IgnoredValueWarning, Problem, SceneError
from .pressure import PressureSource, make_source
from .schema import MISSING, OperationSection, Section, SolverSection, raw_at, validate_sections
from .units import PlausibilityWarning, quantity_text

__all__ = ["Scene", "SceneError", "load_scene", "scene_file", "default_scene_text", "derive_parameters",
           "embedded_scene_path"]

DEFAULT_SCENE = "default.toml"
#: bump when the meaning of a scene's content changes (it enters the content hash)
SCENE_FORMAT = 1


def _scenes_folder() -> Any:
    """The folder of embedded scenes (an importlib resource; a Path in ordinary installs)."""
    return importlib.resources.files("apexseal.runtime.scenes")


def _files_from_here(dotted: dict[str, Any]) -> dict[str, Any]:
    """Overrides of an embedded scene with its relative file names (``FILE_KEYS``: ``pressure.file``) taken from the
    current folder where a file of that name is there, as the command line's ``--set`` takes them: the user's file
    is meant (``apexseal scene --default > my.toml`` writes expander-pressure.csv there), not the package's table
    of that name beside the embedded scene, which a path relative to the scene's folder found silently. A name the
    current folder does not hold is still the embedded scenes' (their tables: ``expander-pressure.csv``). A scene
    file of the user's keeps its rule: relative to its own folder."""
    from .schema import FILE_KEYS

    def here(value):
        if isinstance(value, str) and value and not Path(value).is_absolute() and (Path.cwd() / value).is_file():
            return str(Path.cwd() / value)
        return value

    out = dict(dotted)
    for key in FILE_KEYS:
        table, _, leaf = key.rpartition(".")
        if key in out:
            out[key] = here(out[key])
        if isinstance(out.get(table), dict) and leaf in out[table]:  # a whole table given inline
            out[table] = out[table] | {leaf: here(out[table][leaf])}
    return out


def _embedded_hint(path: Path) -> str:
    """For a scene named like one of apexseal's own (``"soft-contacts"``, ``"hard/speed-6000"``): how to load that."""
    stem = Path(path).with_suffix(".toml") if Path(path).suffix != ".toml" else Path(path)
    try:
        found = Path(str(_scenes_folder().joinpath(stem.as_posix()))).is_file()
    except (OSError, ValueError):
        found = False
    if found:
        return (f"; apexseal's own scene of that name loads with "
                f"load_scene(apexseal.embedded_scene_path({stem.as_posix()!r}))")
    from apexseal.suggest import did_you_mean

    # a misspelt name of the default or of an embedded scene ("defualt"), and where a relative name was looked for
    own = list(dict.fromkeys([DEFAULT_NAME, *sorted(Path(n).with_suffix("").as_posix() for n in _embedded_names())]))
    given = Path(path).with_suffix("") if Path(path).suffix == ".toml" else Path(path)
    # a relative name as given, or the end of a path made absolute (a study file's scene, from the study's folder)
    near = did_you_mean(given.as_posix(), own) or did_you_mean(given.name, own)
    where = "" if Path(path).is_absolute() else f" (looked for {Path(path).resolve()})"
    if near and near != f" (did you mean {DEFAULT_NAME!r}?)":
        near += "; apexseal's own scenes load with load_scene(apexseal.embedded_scene_path(\"<name>.toml\"))"
    return where + near


def _embedded_names() -> list[str]:
    """apexseal's own scene files, as :func:`embedded_scene_path` takes them ("hard/speed-6000.toml"), sorted."""
    folder = Path(str(_scenes_folder()))
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*.toml"))


def embedded_scene_path(name: str) -> Path:
    """The path of an embedded scene file, e.g. ``"soft-contacts.toml"`` or ``"hard/speed-6000.toml"``."""
    path = Path(str(_scenes_folder().joinpath(name)))
    if not path.is_file():
        raise SceneError([("scene", name, f"no such embedded scene; embedded: {', '.join(_embedded_names())}")],
                         source=name)
    return path


def default_scene_text() -> str:
    """The TOML text of the embedded default scene (a starting point for new scenes)."""
    return _scenes_folder().joinpath(DEFAULT_SCENE).read_text(encoding="utf-8")


#: the name that stands for the embedded default scene, in a study file (``scene = "default"``) and to load_scene
DEFAULT_NAME = "default"


def scene_file(name: str | Path | None, base_dir: Path | None = None) -> Path | None:
    """Where a scene named by a user is: None for the embedded default (None or the string ``"default"``, as a
    study file names it), else the file, relative to ``base_dir`` when given (a study file's folder)."""
    if name is None or isinstance(name, str) and name == DEFAULT_NAME:
        return None
    p = path_argument("path", name, f"the path of a scene file (str or Path), or None or {DEFAULT_NAME!r} for the "
                      "embedded default")
    return p if base_dir is None else base_dir / p


def load_scene(path: str | Path | None = None, overrides: dict[str, Any] | None = None) -> Scene:
    """Load and check a scene file; ``None`` or ``"default"`` (the name a study file gives it) loads the embedded
    default (the paper's case study). ``overrides`` (dotted keys, as :meth:`Scene.with_overrides` takes them)
    replace the file's keys before anything is checked, so they can repair a file that would not load alone."""
    path = scene_file(path)
    if path is None:
        folder = _scenes_folder()
        source = Path(str(folder.joinpath(DEFAULT_SCENE))) if isinstance(folder, Path) else None
        return Scene.from_toml_string(default_scene_text(), folder, name="default", source_path=source,
                                      overrides=None if overrides is None else _files_from_here(overrides))
    p = path
    try:
        text = p.read_text(encoding="utf-8-sig")  # a byte-order mark (an editor's) is no TOML: dropped
    except FileNotFoundError:
        raise SceneError([("scene", str(path), "file not found" + _embedded_hint(path))], source=str(path)) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError([("scene", str(path), f"cannot read: {exc}")], source=str(path)) from None
    return Scene.from_toml_string(text, p.parent, name=p.name, source_path=p, overrides=overrides)


def _parse_toml(text: str, name: str) -> dict[str, Any]:
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        msg = str(exc)
        lines = text.splitlines() or [""]
        m = re.search(r"\(at line (\d+), column (\d+)\)", msg)
        line, col = (int(m[1]), int(m[2])) if m else (len(lines), len(lines[-1]) + 1)
        reason = re.sub(r"\s*\(at [^)]*\)\s*$", "", msg)
        shown = lines[line - 1].strip() if 0 < line <= len(lines) else ""
        if re.search(r"=\s*[-+.\d][\w.+-]*\s+[A-Za-z%]", shown):
            reason += ' (a quantity with a unit must be a quoted string, e.g. r = "3 mm")'
        elif reason.startswith("Cannot overwrite a value") or reason.startswith("Cannot declare"):
            reason += " (a key or a table given twice?)"
        raise SceneError(
            [("toml", shown, f"malformed TOML at line {line}, column {col}: {reason}")], source=name
        ) from None


@contextmanager
def _naming_overrides(overrides: dict[str, Any]):
    """A SceneError raised while keys are replaced says which were (a problem of a replaced key is not the file's:
    the command line's --set, a sweep's point, an API call's overrides)."""
    try:
        yield
    except SceneError as err:
        source = f"{err.source + ' ' if err.source else ''}with {', '.join(overrides)} replaced"
        raise SceneError(err.errors, source=source) from None


def derive_parameters(sections: dict[str, Section], effects: Effects,
                      assumptions: Assumptions | None = None) -> dict[str, float]:
    """Every parameter of the model's vector, in SI, from validated sections: the parameters its effects read
    (an effect that is off has no slot, :func:`~apexseal.derive.submodels.registry.parameters`).

    The keys each submodel declares are read from their sections; then each submodel
    computes its derived parameters from them with plain numeric functions (the seal
    body: omega from rpm, the mass and inertia, beta_o of Eq. 24, zeta0 of Eqs. 6-8,
    delta_w of Eq. 9 and Li of Eq. 12; see derive/submodels/seal.py).
    """
    from apexseal.derive.choices import options_of
    from apexseal.derive.submodels.registry import parameters

    options = options_of(effects, assumptions or Assumptions())
    values = parameter_values(sections, options)
    names = parameters(opts=options)
    missing = [p.name for p in names if values.get(p.name) is None]
    if missing:  # pragma: no cover - a submodel declares a parameter that nothing computes
        raise RuntimeError(f"the scene gives no value for parameters {missing}: a submodel's derived() must")
    return {p.name: float(values[p.name]) for p in names}


def parameter_values(sections: dict[str, Section], options, **changes) -> dict[str, Any]:
    """Every declared value (scene inputs and parameters) by name: the sections' keys, ``changes`` (numbers or
    CasADi symbols) in their place, then each submodel's derived parameters computed from them."""
    from apexseal.derive.submodels.registry import omissible_while_off, parameters, submodels

    from .schedule import value_at_start

    values: dict[str, Any] = {}
    for p in parameters(all_inputs=True):
        if p.key is not None:
            given = getattr(sections[p.section], p.leaf)
            values[p.name] = given if given is not None else value_at_start(sections, p)  # a schedule's at the start
    values.update(changes)
    for cls in submodels():
        left_out = any(values.get(p.name) is None and omissible_while_off(p) for p in cls.parameters)
        if cls.active(options) or not left_out:  # one that is off with inputs left out: its derived values unset
            values.update(cls.derived(values, sections, options))
    return values


def _overridden(raw: dict[str, Any], dotted: dict[str, Any], name: str) -> dict[str, Any]:
    """A copy of the raw TOML content with the dotted keys replaced (``None`` removes one); see
    :meth:`Scene.with_overrides`."""
    from apexseal.derive.submodels.registry import alternatives

    raw = copy.deepcopy(raw)
    dotted = {key: _plain(value) for key, value in dotted.items()}
    _children_follow(raw, dotted)
    _source_follows(raw, dotted)
    for pair in alternatives():
        for mine, other in (pair, pair[::-1]):
            if dotted.get(mine) is not None and other not in dotted:
                section, leaf = other.split(".", 1)
                if isinstance(raw.get(section), dict):
                    raw[section].pop(leaf, None)
    problems = []
    for key, value in dotted.items():
        parts = key.split(".")
        if not all(parts):
            problems.append(Problem(key, value, "not a key path such as 'seal.Ws'"))
            continue
        node = raw
        for i, part in enumerate(parts[:-1]):
            nxt = node.get(part)
            if nxt is None:
                nxt = node[part] = {}
            elif not isinstance(nxt, dict):
                problems.append(Problem(key, value, f"{'.'.join(parts[: i + 1])} is a value, not a table"))
                break
            node = nxt
        else:
            if value is None:
                node.pop(parts[-1], None)
            else:
                node[parts[-1]] = _plain(value)
    if problems:
        raise SceneError(problems, source=f"{name} overrides")
    return raw


def _children_follow(raw: dict[str, Any], dotted: dict[str, Any]) -> None:
    """An override that switches an effect off switches off with it the effects under it that the scene switched
    on and the overrides leave as they were (:func:`~apexseal.derive.effects.off_with_parents`)."""
    from apexseal.derive.effects import off_with_parents

    effects = raw.get("effects")
    if not isinstance(effects, dict):
        return
    named = {k.split(".", 1)[1] for k in dotted if k.startswith("effects.")}
    off = {name for name in named if dotted[f"effects.{name}"] is False}
    effects.update({k: v for k, v in off_with_parents(effects, off, named).items() if k in effects})


def _source_follows(raw: dict[str, Any], dotted: dict[str, Any]) -> None:
    """An override of ``pressure.source`` drops the [pressure] keys the scene gave that the new source does not use
    and the overrides do not give (``--set pressure.source=chamber`` on a table scene was refused for its
    ``pressure.file``, which --set cannot remove)."""
    from .schema import PRESSURE_SOURCES

    source, pressure = dotted.get("pressure.source"), raw.get("pressure")
    if not isinstance(source, str) or source not in PRESSURE_SOURCES or not isinstance(pressure, dict):
        return
    used = {"source", *PRESSURE_SOURCES[source], *(("unit",) if source == "table" else ())}
    for key in [k for k in pressure if k not in used and f"pressure.{k}" not in dotted]:
        del pressure[key]


def _unranged(raw: dict[str, Any], sections: dict[str, Section], problems: list[Problem], effects: Effects,
              assumptions: Assumptions | None) -> tuple[dict[str, Section], list[Problem], list[Problem]]:
    """The sections validated again without the range checks of the values no law of the model of ``effects``
    and ``assumptions`` reads (:func:`.checks.unread_keys`), when one of them is out of range: (sections, their
    problems, the range problems so ignored). A value that is no quantity of its kind stays an error, read or
    not."""
    unread = unread_keys(effects, assumptions)
    if not unread & {p.key for p in problems}:
        return sections, problems, []
    sections, lenient = validate_sections(raw, unranged=unread)
    return sections, lenient, [p for p in problems if p not in lenient]


def _pressure_read(sections: dict[str, Section], effects: Effects | None) -> bool:
    """Whether a law reads the chamber pressures: the chamber_pressure effect, or where the effects do not resolve,
    unless the scene switches it off."""
    if effects is not None:
        return effects.chamber_pressure
    return getattr(sections.get("effects"), "chamber_pressure", None) is not False


def _assumptions(sections: dict[str, Section]) -> Assumptions | None:
    """The modelling choices of valid sections ([assumptions], with pressure.source where [pressure] is valid), or
    None when [assumptions] is not valid."""
    if "assumptions" not in sections:
        return None
    return resolve_assumptions(sections["assumptions"], sections["pressure"].source if "pressure" in sections else None)


def _section_of(content: dict[str, Any], key: str) -> tuple[dict[str, Any] | None, str]:
    """The table of ``content`` (nested dicts) that holds the dotted ``key``, and its last part."""
    *path, leaf = key.split(".")
    section: Any = content
    for part in path:
        section = section.get(part) if isinstance(section, dict) else None
    return (section if isinstance(section, dict) else None), leaf


def _pop(content: dict[str, Any], key: str) -> None:
    section, leaf = _section_of(content, key)
    if section is not None:
        section.pop(leaf, None)


def _recording(scene: Scene, overrides: dict[str, Any]) -> Scene:
    """``scene`` holding the ``overrides`` it was built with (:attr:`Scene.overrides`)."""
    object.__setattr__(scene, "overrides", dict(overrides))
    return scene


def _build(raw: dict[str, Any], base_dir: Any, source_path: Path | None, name: str) -> Scene:
    sections, problems = validate_sections(raw)
    effects: Effects | None = None
    effect_problems: list[Problem] = []
    # the effects hold no range, and a [pressure] refused only for a constant pressure out of range (read while the
    # chamber pressure is on) has no source to switch it off: the effects resolved here are those of the sections
    # _unranged returns
    if "effects" in sections:
        src = sections["pressure"].source if "pressure" in sections else None
        effects, effect_problems = resolve_effects(sections["effects"], src, raw)
    assumptions = _assumptions(sections)
    ignored: list[Problem] = []
    if effects is not None:
        sections, problems, ignored = _unranged(raw, sections, problems, effects, assumptions)
        # pressure_model follows pressure.source, which a [pressure] refused only for a value no law reads hid from
        # the choices above (no choice that decides what is read depends on it): resolved again from the sections
        # _unranged returns
        assumptions = _assumptions(sections)
    consistency = check_consistency(sections, raw)
    if effects is not None:  # a cross-key bound on a value no law reads is ignored as its own range is
        unread = unread_keys(effects, assumptions)
        ignored += [p for p in consistency if p.key in unread]
        consistency = [p for p in consistency if p.key not in unread]
    problems += consistency
    pressure: PressureSource | None = None
    if "pressure" in sections and not any(p.key.startswith("pressure.") for p in problems):
        try:
            pressure = make_source(sections["pressure"], base_dir, read=_pressure_read(sections, effects))
        except SceneError as exc:
            problems += exc.errors
    problems += effect_problems
    if effects is not None:
        problems += check_needed(sections, effects, assumptions)
    doubtful = check_plausible(sections, raw, pressure, effects, assumptions)
    if problems:  # an implausible value (a unit slip) is the likely cause of the rest: report it first, and on
        # a key refused as well, with the refusal ("did you mean "0.6 mm"?" after the range a bare 0.6 m leaves)
        doubts = {p.key: p.message for p in doubtful}
        problems = [Problem(q.key, q.value, f"{q.message}; {doubts[q.key]}") if q.key in doubts else q for q in problems]
        raise SceneError([p for p in doubtful if p.key not in {q.key for q in problems}] + problems, source=name)
    for p in doubtful:
        warnings.warn(f"scene {name}: {p}", PlausibilityWarning, stacklevel=user_stacklevel())
    if ignored:
        warnings.warn(f"scene {name}: {ignored_values(ignored, effects, assumptions)}", IgnoredValueWarning,
                      stacklevel=user_stacklevel())
    for p in [*check_superseded(raw), *check_set_by(raw, assumptions),
              *(check_unread_tables(raw, sections, effects, assumptions, {p.key for p in ignored}) if effects else [])]:
        warnings.warn(f"scene {name}: {p}", IgnoredValueWarning, stacklevel=user_stacklevel())
    assert pressure is not None and effects is not None and assumptions is not None
    values = derive_parameters(sections, effects, assumptions)
    deflection = check_wall_deflection(values, raw)  # of derived values: checked once they are computed
    if deflection:
        raise SceneError(deflection, source=name)
    for p in check_damping(values, raw):
        warnings.warn(f"scene {name}: {p}", PlausibilityWarning, stacklevel=user_stacklevel())
    return Scene(
        machine=sections["machine"],
        operation=sections["operation"],
        seal=sections["seal"],
        spring=sections["spring"],
        contacts=sections["contacts"],
        friction=sections["friction"],
        pressure=pressure,
        effects=effects,
        assumptions=assumptions,
        solver=sections["solver"],
        source_path=source_path,
        name=name,
        _raw=copy.deepcopy(raw),
        _base_dir=base_dir,
        _values=tuple(values.values()),
        _names=tuple(values),
        _sections=sections,
    )


def _plain(value: Any) -> Any:
    """An override as the TOML would hold it: numpy scalars and 0-d arrays as the Python numbers and bools they
    hold (``np.bool_(False)`` switched an effect off without its children, which follow a ``False``), paths as
    strings, pint quantities as their magnitude and unit written out ("3.2 millimeter"), tables and arrays likewise."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple) or (isinstance(value, np.ndarray) and value.ndim == 1):  # a schedule's knots
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value.item()
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        return float(value)
    if isinstance(value, Path):
        return str(value)
    text = quantity_text(value)
    return value if text is None else text


def _dump(section: Section) -> dict[str, Any]:
    """A section's content; a ``schedule`` sub-table only where one is given (a scene without one hashes as it did
    before parameters could be scheduled)."""
    return section.model_dump(exclude={"schedule"} if getattr(section, "schedule", True) is None else None)


def _normalise(obj: Any) -> Any:
    """Floats to 12 significant digits, so "3.06 mm" and 0.00306 hash alike."""
    if isinstance(obj, dict):
        return {k: _normalise(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_normalise(v) for v in obj]
    if isinstance(obj, float):
        return float(f"{obj:.12g}")
    return obj


@dataclass(frozen=True, eq=False, repr=False)
class Scene:
    """A checked scene: the validated sections, the pressure source, effects, assumptions, solver settings.

    Quantities in the sections are SI (``operation.rpm`` in rev/min, angles in rad).
    Build with :func:`load_scene`, :meth:`from_toml_string` or :meth:`with_overrides`.
    """

    machine: Section
    operation: OperationSection
    seal: Section
    spring: Section
    contacts: Section
    friction: Section
    pressure: PressureSource
    effects: Effects
    assumptions: Assumptions
    solver: SolverSection
    source_path: Path | None
    name: str
    _raw: dict[str, Any] = field(repr=False)
    _base_dir: Any = field(repr=False)
    _values: tuple[float, ...] = field(repr=False)
    _names: tuple[str, ...] = field(repr=False, default=())
    _sections: dict[str, Section] = field(repr=False, default_factory=dict)
    #: the dotted keys replaced when this scene was built (load_scene's ``overrides``, with_overrides), as given:
    #: what a report records of them (a study's preload.json)
    overrides: dict[str, Any] = field(repr=False, compare=False, default_factory=dict)

    @classmethod
    def from_toml_string(
        cls,
        text: str,
        base_dir: str | Path | None = None,
        *,
        name: str = "<string>",
        source_path: Path | None = None,
        overrides: dict[str, Any] | None = None,
    ) -> Scene:
        """Parse and check TOML ``text``; a pressure table's path is taken relative to ``base_dir``
        (default: the current directory); ``overrides`` as :func:`load_scene` takes them."""
        raw = _parse_toml(text, name)
        folder = Path.cwd() if base_dir is None else Path(base_dir) if isinstance(base_dir, str) else base_dir
        if not overrides:
            return _build(raw, folder, source_path, name)
        with _naming_overrides(overrides):
            return _recording(_build(_overridden(raw, dict(overrides), name), folder, source_path, name), overrides)

    @property
    def reference(self) -> str:
        """How a result names this scene: "default" for the embedded default, else the file as it was given.

        Never the absolute path of the installed package, so a saved result reads the same on every machine.
        """
        if self.source_path is None or self.source_path.name == DEFAULT_SCENE and self.name == "default":
            return self.name
        return self.source_path.as_posix()

    # -- parameters ---------------------------------------------------------

    @property
    def parameters(self) -> dict[str, float]:
        """Every parameter of the scene's model, by name, in SI (see :func:`derive_parameters`): those its effects
        read (an effect that is off has none here; its keys are in the scene's sections)."""
        return dict(zip(self._names, self._values, strict=True))

    def parameter_vector(self, names=None) -> np.ndarray:
        """The parameters as a float array, in the order of ``names`` (default: the vector of the scene's model, the
        generated Functions' order for its effects; pass ``functions.parameter_names`` to match another model)."""
        values = self.parameters
        if names is None:
            names = self._names
        try:
            return np.array([values[n] for n in names], dtype=float)
        except KeyError as exc:
            raise KeyError(f"the scene has no parameter {exc.args[0]!r}: the effect that reads it is off in this scene "
                           "(a model of other effects), or its submodel was registered after the scene was loaded "
                           "(load the scene again)") from None

    def parameter_function(self, *names: str):
        """The parameter vector as a CasADi Function of the named parameters (the others at the scene's values).

        Derived parameters follow through the submodels' own formulas: ``parameter_function("delta_s")`` moves
        delta_w (Eq. 9) and Li (Eq. 12) with the preload, so a study can differentiate ``p(delta_s)``. A name is a
        parameter's (``scene.parameters``: ``"delta_s"``) or its scene key (``"spring.delta_s"``); the Function's
        inputs are named by the parameters. Any other name is a KeyError with the closest known name and the list.
        """
        import casadi as ca

        from apexseal.derive.choices import options_of
        from apexseal.derive.submodels.registry import parameters
        from apexseal.suggest import not_known

        by_key = {q.key: q.name for q in parameters(all_inputs=True) if q.key is not None and q.name in self.parameters}
        names = tuple(by_key.get(n, n) for n in names)
        for n in names:
            if n not in self.parameters:
                raise KeyError(not_known(f"parameter_function: {n!r}", n, [*self.parameters, *by_key],
                                         "a parameter of the scene's model nor its scene key", listing="known"))
        sym = {n: ca.SX.sym(n) for n in names}
        options = options_of(self.effects, self.assumptions)
        values = parameter_values(self._sections, options, **sym)
        p = ca.vertcat(*[values[q.name] for q in parameters(opts=options)])
        return ca.Function("parameters_of_" + "_".join(names), list(sym.values()), [p], list(names), ["p"])

    @property
    def omega(self) -> float:
        """Rotor speed in rad/s."""
        return self.operation.omega

    @property
    def schedule(self):
        """The parameters the scene gives along the revolution (a :class:`~.schedule.Schedule`: ``[spring.schedule]``
        for the preload), or None: every parameter is one value (runtime/scenes/schedule.py). A schedule of a
        parameter the model does not have (its effect off: ``effects.spring = false``) is not read."""
        from .schedule import Schedule, scheduled

        given = scheduled(self._sections)
        if given is None:
            return None
        read = {n: v for n, v in given.values.items() if n in self.parameters}  # an effect that is off reads none
        return Schedule(given.angles, read) if read else None

    def parameter_path(self, names=None):
        """None for a scene without a schedule; else a :class:`~.schedule.ParameterPath`, ``path(theta) -> (n_par,
        m)``: the parameter vector (in the order of ``names``, default ``self.parameters``) at the crank angles
        ``theta`` (rad, absolute, m of them), each scheduled parameter at its schedule's value and the parameters
        derived from it following through the submodels' formulas (:meth:`parameter_function`)."""
        from .schedule import ParameterPath

        schedule = self.schedule
        if schedule is None:
            return None
        return ParameterPath(schedule, self.parameter_function(*schedule.names), self.parameters,
                             tuple(names) if names is not None else tuple(self.parameters))

    # -- variants -----------------------------------------------------------

    def with_overrides(self, **dotted: Any) -> Scene:
        """A new, checked scene with keys replaced, e.g. ``**{"contacts.kw": 2e9, "operation.rpm": 6000}``.

        Values are written as in the TOML (numbers in SI, or strings with units; numpy numbers, 0-d arrays and pint
        quantities are read as what they hold);
        ``None`` removes a key, restoring its default (a key without one is then missing: refused, named). Setting
        one key of a pair that states one thing two ways (``contacts.cw`` or the damping ratio ``contacts.zeta_w``,
        ...) removes the other, unless both are given.
        """
        dotted = _files_from_here(dotted) if self.embedded else dotted
        with _naming_overrides(dotted):
            return _recording(_build(_overridden(self._raw, dotted, self.name), self._base_dir, self.source_path,
                                     self.name), self.overrides | dotted)

    @property
    def embedded(self) -> bool:
        """Whether the scene is one of apexseal's own (the default, runtime/scenes/*.toml), not a user's file."""
        try:
            return Path(str(self._base_dir)).resolve().is_relative_to(Path(str(_scenes_folder())).resolve())
        except (OSError, ValueError):
            return False

    # -- content ------------------------------------------------------------

    def to_dict(self) -> dict[str, Any]:
        """Normalised content in SI: every section, the pressure source, effects, assumptions, parameters."""
        content = {
            "format": SCENE_FORMAT,
            "machine": _dump(self.machine),
            "operation": self.operation.model_dump(),
            "seal": _dump(self.seal),
            "spring": _dump(self.spring),
            "contacts": _dump(self.contacts),
            "friction": _dump(self.friction),
            "pressure": self.pressure.to_dict(),
            "effects": self.effects.as_dict(),
            "assumptions": self.assumptions.as_dict(),
            "solver": self.solver.model_dump(),
            "parameters": self.parameters,
        }
        from apexseal.derive.submodels.registry import superseding

        for key in self.left_out_keys():  # a submodel that is off and enters no model (a user's or a package's)
            _pop(content, key)
        for key, unread in superseding():  # seal.density beside seal.ms: not read, and not in the resolved file
            section, leaf = _section_of(content, unread)
            if section is not None and section.get(leaf) is not None \
                    and raw_at(content, key.split(".")) not in (None, MISSING):
                section[leaf] = None  # as a scene that does not give it
        return content

    def left_out_keys(self) -> frozenset[str]:
        """The dotted keys of the submodels that enter no model of this scene (a user's or a package's that is
        off with its options at their defaults, :func:`~apexseal.derive.submodels.registry.entering`): their
        parameters, switches and choices. Neither the scene's content (:meth:`to_dict`,
        :meth:`content_hash`) nor its resolved file holds them, so installing a package changes neither, and a
        result that never ran it still loads where the package is not installed."""
        from apexseal.derive.choices import options_of
        from apexseal.derive.submodels.registry import entering, submodels

        entered = set(entering(options_of(self.effects, self.assumptions)))
        return frozenset(key for cls in submodels() if cls not in entered
                         for key in [*(p.key for p in cls.parameters if p.key is not None),
                                     *(f"{o.table}.{o.name}" for o in cls.options)])

    def content_hash(self) -> str:
        """sha256 of the normalised content (including the pressure table's numbers).

        Independent of where the scene lives, of the table's file name and of how
        units are spelled (``"3 mm"`` and ``0.003`` hash alike; a table in bar and the same numbers in Pa too,
        as the result's scene.toml writes it).
        """
        content = self.to_dict()
        content["pressure"].pop("file", None)
        content["pressure"].pop("unit", None)  # its numbers are hashed in Pa
        text = json.dumps(_normalise(content), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode("utf-8")).hexdigest()

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Scene) and self.content_hash() == other.content_hash()

    def __hash__(self) -> int:
        return hash(self.content_hash())

    def __repr__(self) -> str:
        where = f", {self.source_path.name}" if self.source_path else ""
        return f"Scene({self.name!r}{where}, {self.content_hash()[:12]})"
