"""The settings of one run (one validated model for scene, CLI and API), and how a revolution is cut into calls.

:class:`RunSettings` is the only place where the ranges of the run's settings live: the scene's ``[solver]``
and ``[operation]`` tables (runtime/scenes/schema.py) take their bounds from :data:`LIMITS`, the command line
passes its options through ``settings_of`` (runtime/api.py), and so does ``apexseal.simulate(scene, rtol=...)``. A bad
value raises :class:`SettingsError`, one line per field: ``rtol = nan: nan is out of range; allowed: 1e-12 <=
value <= 0.01``.
"""

from __future__ import annotations

import math
import numbers
import time
from typing import Annotated, Any

from pydantic import BaseModel, BeforeValidator, ConfigDict, ValidationError
from pydantic_core import PydanticCustomError

from ...derive.submodels.seal import MAX_TILT  # noqa: F401 - the run's tilt limit, as the seal declares it
from ...generated.compiler import FLAG_SETS
from ...generated.layout import PARAMETER_PROFILES, PRESSURE_PROFILES
from ..scenes.errors import Problem
from ..scenes.units import Range

#: the most revolutions one run may ask for (results are streamed to disk, but a run must end)
MAX_REVOLUTIONS = 100_000

#: field -> (kind, range): the one table of the run settings' bounds ("int" or "float"; None: optional)
LIMITS: dict[str, tuple[str, Range]] = {
    "rtol": ("float", Range(ge=1e-12, le=1e-2)),
    "atol": ("float?", Range(gt=0, le=1.0)),
    "samples_per_revolution": ("int", Range(ge=36, le=100_000)),
    "steps_per_revolution": ("int", Range(ge=1, le=10**9)),
    "event_tol": ("float", Range(gt=0, le=1e-6)),  # rad of crank angle: far below a contact's ringing period (~0.03 rad)
    "max_events_per_revolution": ("int", Range(ge=1, le=10**8)),
    "chatter_window": ("float", Range(gt=0, le=2 * math.pi)),  # rad
    "chatter_events": ("int", Range(ge=2, le=10**8)),
    "max_steps_per_interval": ("int", Range(ge=1, le=10**9)),
    "max_wall_time": ("float?", Range(gt=0, le=1e7)),  # s
    "calls_per_revolution": ("int?", Range(ge=1, le=100_000)),
    "revolutions": ("int", Range(ge=1, le=MAX_REVOLUTIONS)),
}
#: the SI unit of a setting that has one, shown with its value and range ("0 < value <= 1e+07 s")
UNITS: dict[str, str] = {"event_tol": "rad", "chatter_window": "rad", "max_wall_time": "s"}
FLAGS = tuple(FLAG_SETS)  # the compiler's flag sets, by name


class SettingsError(ValueError):
    """Run settings that cannot be used; ``errors`` lists every ``(field, value, message)``."""

    def __init__(self, errors: list[tuple[str, Any, str]]) -> None:
        self.errors = [Problem(*e) for e in errors]
        count = len(self.errors)
        super().__init__("\n".join([f"run settings: {count} problem{'s' if count != 1 else ''}",
                                    *(f"  {p}" for p in self.errors)]))

    def keys(self) -> list[str]:
        return [p.key for p in self.errors]


def _fail(message: str) -> PydanticCustomError:
    return PydanticCustomError("settings", "{message}", {"message": message})


def allowed(name: str) -> str:
    """The allowed range of a numeric setting as the scene's validators print it, e.g. ``1e-12 <= value <= 0.01``
    (``36 <= n <= 100000`` for integers, ``0 < value <= 1e+07 s`` with a unit)."""
    kind, rng = LIMITS[name]
    return rng.describe(name="n") if kind.startswith("int") else rng.describe(UNITS.get(name, ""), name="value")


def check_value(name: str, value: Any) -> Any:
    """``value`` as the setting ``name`` (int or float in its range), or a message naming the range."""
    kind, rng = LIMITS[name]
    if value is None and kind.endswith("?"):
        return None
    if kind.startswith("int"):
        if isinstance(value, bool) or not isinstance(value, numbers.Integral):
            raise _fail(f"expected an integer, {allowed(name)}")
        value = int(value)
    else:
        if isinstance(value, str) and name in UNITS:  # "10 s", "1e-8 rad": as the scene's [solver] and --set take it
            from ..scenes.units import QuantityError, parse_quantity

            try:
                value = parse_quantity(value, UNITS[name])
            except QuantityError as err:
                raise _fail(f"{err.reason}; allowed: {allowed(name)}") from None
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise _fail(f"expected a number{f' in {UNITS[name]}, or a quantity with its unit' if name in UNITS else ''}"
                        f", {allowed(name)}")
        value = float(value)
    if not rng.holds(value):  # NaN fails every bound
        shown = value if kind.startswith("int") else format(value, ".6g") + (f" {UNITS[name]}" if name in UNITS else "")
        raise _fail(f"{shown} is out of range; allowed: {allowed(name)}")
    return value


def _ranged(name: str, kind: Any) -> Any:
    return Annotated[kind, BeforeValidator(lambda v: check_value(name, v))]


def _method(value: Any) -> Any:
    from .methods import METHODS, Engine

    if isinstance(value, type) and issubclass(value, Engine):
        return value
    if isinstance(value, str) and value in METHODS:
        return value
    import difflib

    near = difflib.get_close_matches(str(value), METHODS, n=1) if isinstance(value, str) else []
    hint = f" (did you mean '{near[0]}'?)" if near else ""
    raise _fail(f"not a method{hint}; allowed: {', '.join(METHODS)}, or a subclass of apexseal's Engine")


def _flags(value: Any) -> str:
    if value in FLAGS:
        return value
    raise _fail(f"not allowed; allowed: {', '.join(FLAGS)}")


#: the default pressure profile of PRESSURE_PROFILES (the hybrid DAE's controls, generated/layout.py;
#: docs/bench/levers.md: the pressure steps make the metal contacts ring)
DEFAULT_PRESSURE = "linear"


def _one_of(allowed: tuple[str, ...]):
    """The validator of a setting that takes one of ``allowed`` (a profile: of the pressures, of the parameters)."""

    def check(value: Any) -> str:
        if value in allowed:
            return value
        raise _fail(f"not allowed; allowed: {', '.join(allowed)}")

    return check


def not_a_flag(value: Any) -> str:
    """What is wrong with a value given for a switch (a TOML boolean: true or false, not 0/1 or "yes"); a string
    "true" or "false" (from Python, where quotes come naturally beside "2e4 N/m") is told how to write it."""
    word = value.strip().lower() if isinstance(value, str) else None
    if word in ("true", "false"):
        return (f"expected true or false, a boolean, not the string {value!r} (in a scene file and with --set: "
                f"{word} without quotes; from Python: {word.capitalize()})")
    return "expected true or false"


def _flag(value: Any) -> bool:
    if isinstance(value, bool):
        return value
    raise _fail(not_a_flag(value))


#: the scene's ``[solver]`` name of a setting whose field here is named otherwise -> that field: the API takes
#: either (``apexseal.simulate(scene, interpreted=True)`` is ``compile_c=False``)
SCENE_NAMES = {"compile": "flags", "interpreted": "compile_c", "euler_steps_per_revolution": "steps_per_revolution"}


def merged(base: dict[str, Any], changes: dict[str, Any]) -> dict[str, Any]:
    """``base`` with the ``changes`` that are not None; a change under a scene's name (:data:`SCENE_NAMES`)
    replaces the base's value of its field."""
    changes = {k: v for k, v in changes.items() if v is not None}
    return {k: v for k, v in base.items() if k not in {SCENE_NAMES.get(c) for c in changes}} | changes


def _field_names(values: dict[str, Any]) -> tuple[dict[str, Any], list[tuple[str, Any, str]]]:
    """``values`` with the scene's names of :data:`SCENE_NAMES` turned into the fields' (``interpreted`` into
    ``compile_c``, negated), and the problems of those names: one given under both names, a non-boolean
    ``interpreted`` (the others are checked with every field)."""
    out, problems = dict(values), []
    for scene_name, field in SCENE_NAMES.items():
        if scene_name not in out:
            continue
        value = out.pop(scene_name)
        if field in out:
            problems.append((scene_name, value, f"the scene's name of the setting {field}, also given "
                             f"({field} = {out[field]!r}): give one of the two"))
        elif scene_name == "interpreted" and not isinstance(value, bool):
            problems.append((scene_name, value, not_a_flag(value)))
        else:
            out[field] = (not value) if scene_name == "interpreted" else value
    return out, problems


class RunSettings(BaseModel):
    """Settings of one run: method, tolerances, samples, budgets and revolutions, each checked against its range
    (the module docstring). ``apexseal.simulate(scene, **settings)`` takes them by these names (or by the scene's
    [solver] key names, e.g. ``interpreted``), over the scene's [solver] table: ``method`` one of
    ``apexseal.runtime.solving.methods.METHODS`` (or an engine class), ``flags`` one of "quick", "optimised",
    ``pressure`` "linear" or "steps", ``compile_c`` true or false, and the numbers in the ranges listed below.
    """

    model_config = ConfigDict(frozen=True, extra="forbid", arbitrary_types_allowed=True)

    method: Annotated[Any, BeforeValidator(_method)] = "erk"
    rtol: _ranged("rtol", float) = 1e-6
    atol: _ranged("atol", float | None) = None
    samples_per_revolution: _ranged("samples_per_revolution", int) = 720
    steps_per_revolution: _ranged("steps_per_revolution", int) = 200000  # fixed-step methods (euler, rk, collocation)
    event_tol: _ranged("event_tol", float) = 1e-10  # crank angle, rad: event location of every method
    max_events_per_revolution: _ranged("max_events_per_revolution", int) = 10000
    chatter_window: _ranged("chatter_window", float) = 1e-3  # rad
    chatter_events: _ranged("chatter_events", int) = 50
    compile_c: Annotated[bool, BeforeValidator(_flag)] = True
    flags: Annotated[str, BeforeValidator(_flags)] = "optimised"
    #: adaptive methods: integrator steps allowed in one output interval
    max_steps_per_interval: _ranged("max_steps_per_interval", int) = 200000
    #: s, checked between integrator calls (and between intervals near the deadline, runtime/solving/pace.py); None:
    #: no budget
    max_wall_time: _ranged("max_wall_time", float | None) = None
    calls_per_revolution: _ranged("calls_per_revolution", int | None) = None  # None: 1, or 36 with a wall-time budget
    revolutions: _ranged("revolutions", int) = 1
    pressure: Annotated[str, BeforeValidator(_one_of(PRESSURE_PROFILES))] = DEFAULT_PRESSURE
    #: "linear" for a scene that schedules a parameter along the revolution (runtime/scenes/schedule.py; set from the
    #: scene, not a [solver] key): the engine then takes the parameters' values at its interval edges
    parameters: Annotated[str, BeforeValidator(_one_of(PARAMETER_PROFILES))] = "constant"

    def __init__(self, **values: Any) -> None:
        given = {SCENE_NAMES[k]: k for k in values if k in SCENE_NAMES}  # errors name what the caller wrote
        values, problems = _field_names(values)
        try:
            super().__init__(**values)
        except ValidationError as exc:  # every problem at once, the scene names' with the others
            raise SettingsError(problems + [tuple(p) for p in settings_error(exc, given).errors]) from None
        if problems:
            raise SettingsError(problems)
        if self.pressure != "steps" and self.pressure not in _profiles_of(self.method):  # imports the engine
            allowed = ", ".join(_profiles_of(self.method))
            raise SettingsError([("pressure", self.pressure, f"method {self.method!r} integrates the pressure "
                                  f"profiles {allowed} (its engine's pressure_profiles): set solver.pressure = "
                                  f"\"steps\" (pressure=\"steps\")")])

        if not self.compile_c and method_class(self.method).needs_library:
            name = given.get("compile_c", "compile_c")
            raise SettingsError([(name, True if name == "interpreted" else False,
                                  f"method {self.method!r} runs only in the compiled model library (its C); allowed "
                                  f"with {name} = {'false' if name == 'interpreted' else 'true'}, or a method of "
                                  "CasADi's, e.g. 'erk'")])
        if self.parameters != "constant" and self.parameters not in _profiles_of(self.method, "parameter"):
            can = [name for name in _methods() if self.parameters in _profiles_of(name, "parameter")]
            raise SettingsError([("method", self.method if isinstance(self.method, str) else self.method.__name__,
                                  "cannot integrate parameters that follow the crank angle (a scene's schedule, "
                                  f"[spring.schedule]; its engine's parameter_profiles); methods that can: "
                                  f"{', '.join(can)}")])

    def replace(self, **changes: Any) -> RunSettings:
        """A copy with ``changes`` (validated like the original; ``None`` values are ignored)."""
        return RunSettings(**merged(dict(self), changes))


#: the units of the run settings that have one (the others count steps, samples, events or revolutions)
SETTING_UNITS = {"event_tol": "rad", "chatter_window": "rad", "max_wall_time": "s"}
if RunSettings.__doc__ is not None:  # help(apexseal.RunSettings) lists the ranges (none under python -OO)
    RunSettings.__doc__ += "\n    Ranges (:data:`LIMITS`; rad of crank angle):\n\n" + "\n".join(
        f"    * ``{name}``: {kind.rstrip('?')}, {rng.describe(SETTING_UNITS.get(name, ''))}"
        + (" or None" if kind.endswith("?") else "") for name, (kind, rng) in LIMITS.items()) + "\n"


def settings_error(exc: ValidationError, given: dict[str, str] | None = None) -> SettingsError:
    """The :class:`SettingsError` of pydantic's errors: ``field = value: message`` (a field given under the
    scene's name, ``given``: field -> that name, is named so)."""
    out = []
    for err in exc.errors():
        name = ".".join(str(p) for p in err["loc"]) or "settings"
        name = (given or {}).get(name, name)
        if err["type"] == "extra_forbidden":
            import difflib

            known = [*RunSettings.model_fields, *SCENE_NAMES]
            near = difflib.get_close_matches(name, known, n=1)
            hint = f" (did you mean '{near[0]}'?)" if near else ""
            out.append((name, err["input"], f"unknown setting{hint}; known: {', '.join(known)}"))
        else:
            out.append((name, err.get("input"), err["msg"]))
    return SettingsError(out)


def method_class(method: Any):
    """The engine class of ``method`` (a name, or a subclass of Engine)."""
    from .methods import method_of

    return method_of(method).engine_class()


def _profiles_of(method: Any, kind: str = "pressure") -> tuple[str, ...]:
    """The pressure (or, ``kind = "parameter"``, parameter) profiles the engine of ``method`` integrates
    (``Engine.pressure_profiles``, ``Engine.parameter_profiles``)."""
    return getattr(method_class(method), f"{kind}_profiles")


def _methods() -> tuple[str, ...]:
    from .methods import METHODS

    return tuple(METHODS)


def samples_per_call(settings: RunSettings) -> int:
    """Output intervals per integrator call: the revolution cut into ``calls_per_revolution`` equal calls.

    The number of calls is rounded up to a divisor of ``samples_per_revolution`` (every call the same engine).
    """
    n = settings.samples_per_revolution
    calls = settings.calls_per_revolution or (36 if settings.max_wall_time else 1)
    calls = next(d for d in range(max(1, min(calls, n)), n + 1) if n % d == 0)
    return n // calls


def out_of_time(settings: RunSettings, t_wall: float, doing: str = "") -> str:
    """The stop reason of a run whose wall-time budget ran out (``t_wall``: when the run started)."""
    return (f"wall-time budget used up: max_wall_time = {settings.max_wall_time:g} s (after "
            f"{time.perf_counter() - t_wall:.1f} s{doing})")
