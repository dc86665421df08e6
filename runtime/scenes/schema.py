"""The sections of a scene file, as pydantic models (unknown keys are errors).

Keys are the paper's symbols in ASCII. Every quantity is stored in SI (rpm stays
rpm; angles in rad); see ``docs/scenes.md`` for the reference of every key.
Each field's validator is one of the small classes of :mod:`.fields` (:class:`~.fields.SI`,
:class:`~.fields.Int`, :class:`~.fields.Choice`, :class:`~.fields.Flag`, :class:`~.fields.Text`): they raise one
clear message each, and carry what is allowed, so that a missing key can say
what to give. :func:`validate_sections` turns pydantic's errors into
:class:`~.errors.Problem` lines ``key = value: message``.

Checks that involve more than one key (aspect ratio, groove and seal sizes,
pressure source) are in :mod:`.checks`.
"""

import functools
import math
from typing import Annotated, Any

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, ValidationError, create_model

from ...derive.chambers import EMBODIMENTS
from ...derive.submodels.seal import SealBody
from ...suggest import did_you_mean
from ..solving.methods import METHODS
from ..solving.settings import DEFAULT_PRESSURE, FLAGS, PRESSURE_PROFILES
from .errors import MISSING, Problem
from .fields import SI, TWO_PI, UNRANGED, Choice, Each, Flag, PressureUnit, Text
from .fields import quantity as _q
from .fields import setting_bounds as _bounds
from .fields import setting_int as _int
from .fields import validated as _v

#: one revolution in rad as a scene value reads it (rounded to 15 digits), so that "360 deg" is inside
FULL_TURN = round(TWO_PI, 14)

# ---------------------------------------------------------------------------
# sections


class Section(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Port(Section):
    """A port of Table 1: its angular position, angular width and axial length."""

    angle: _q("rad", show="deg") = Field(description="angular position of the port centre")
    # narrower than a chamber's arc (pi, from one apex to the next): a wider port would join both chambers to the
    # supply or the exhaust at once, and the open-area law (derive/ports.py) takes a port narrower than pi
    width: _q("rad", gt=0, lt=math.pi, show="deg") = Field(description="angular width of the port (< 180 deg, a "
                                                                       "chamber's arc)")
    length: _q("m", gt=0) = Field(description="length of the port along the machine axis")

    @property
    def angle_deg(self) -> float:
        return math.degrees(self.angle)

    @property
    def width_deg(self) -> float:
        return math.degrees(self.width)


class Ports(Section):
    """The inlet and outlet ports; ``items()`` gives ``(name, Port)`` pairs."""

    inlet: Port
    outlet: Port
    datum: _q("rad", show="deg") = Field(
        0.0, description="housing angle (from the Xo axis, counter-clockwise) from which the ports' angles are "
        "measured; Table 1 does not say")

    def items(self) -> tuple[tuple[str, Port], ...]:
        return (("inlet", self.inlet), ("outlet", self.outlet))


def _initial_field(state) -> tuple[Any, float]:
    """The scene field of a seal state's initial value (Eqs. 10-11), as the state declares it
    (derive/submodels/seal.py): its unit, the unit messages show it in, +-its ``initial_limit``; 0 if omitted."""
    limit = state.initial_limit
    return _q(state.unit, ge=-limit, le=limit, show=state.show), 0.0


InitialState = create_model("InitialState", __base__=Section,
                            **{s.name: _initial_field(s) for s in SealBody.states})
InitialState.__doc__ = (
    """Initial seal state in the groove frame (Eqs. 10-11), one key per state of the seal body. The bounds refuse only
    the absurd (a unit slip, an overflow): a seal displaced by a metre, tilted beyond the model's geometry (45 deg),
    or moving faster than 1 km/s in its groove; whether the start is inside a wall is the run's start check
    (runtime/solving/preflight.py).""")


class OperationSection(Section):
    """[operation]: speed and run length."""

    rpm: _q("rpm", gt=0, bare="rpm") = Field(description="constant rotor speed; bare numbers are rev/min")
    revolutions: _v(_int("revolutions"), int) = Field(
        1, description="revolutions to run (the most, with until_periodic)"
    )
    start_angle: _q("rad", ge=-FULL_TURN, le=FULL_TURN, show="deg") = Field(
        0.0, description="crank angle theta at the start (within one revolution either way)")
    initial_state: InitialState = Field(default_factory=InitialState)
    until_periodic: _v(Flag(), bool) = Field(
        False, description="stop once a revolution repeats the previous one"
    )
    # below 1: a relative change of the state over a revolution of 100 % or more says nothing about periodicity
    periodic_tol: _q("1", gt=0, lt=1) = Field(
        3e-2, description="largest change from one revolution to the next that counts as periodic: the position at "
                          "every output sample, the whole state at the revolution's end (relative above 1 µm or 1 "
                          "mrad; runtime/solving/periodicity.py); it must lie above what the integrator resolves")

    @property
    def omega(self) -> float:
        """Rotor speed in rad/s."""
        return omega_of_rpm(self.rpm)


def omega_of_rpm(rpm: float) -> float:
    """A rotor speed in rev/min (the scene's operation.rpm) in rad/s (the model's omega)."""
    return rpm * TWO_PI / 60.0


def rpm_of_omega(omega: float) -> float:
    """A rotor speed in rad/s (the model's omega) in rev/min (the scene's operation.rpm)."""
    return omega * 60.0 / TWO_PI


#: the scene keys that name a file: relative to the scene file's folder in a scene, to the current folder when given
#: on the command line (--set), as a shell user types paths
FILE_KEYS = ("pressure.file",)

#: pressure.source -> the [pressure] keys it needs
PRESSURE_SOURCES = {"none": (), "constant": ("Pa", "Pb"), "table": ("file",), "chamber": (), "chamber+leakage": ()}
#: the sources that integrate the chamber gas model (derive/submodels/gas.py), whose pressure is (gamma - 1) U / V:
#: each is also the name of the gas model's ``pressure_model`` choice it sets (the others set "input")
GAS_SOURCES = ("chamber", "chamber+leakage")


class PressureSection(Section):
    """[pressure]: where the chamber pressures Pa(theta), Pb(theta) come from (Eq. 75)."""

    source: _v(Choice(*PRESSURE_SOURCES), str) = Field(
        "none", description="none, constant, table, or the chamber gas model (with the leakage past the seal)")
    Pa: _q("Pa", ge=0, optional=True) = Field(None, description="chamber a (+Ys side), source = constant")
    Pb: _q("Pa", ge=0, optional=True) = Field(None, description="chamber b (-Ys side), source = constant")
    file: _v(Text(optional=True), str | None) = Field(
        None, description="CSV table, relative to the scene file"
    )
    unit: _v(PressureUnit(), str) = Field("Pa", description="unit of the table's pressure columns")


#: integration methods, as runtime/solving/methods.py defines them
SOLVER_METHODS: tuple[str, ...] = tuple(METHODS)


class SolverSection(Section):
    """[solver]: integration settings."""

    method: _v(Choice(*SOLVER_METHODS), str) = "erk"
    rtol: _q("1", **_bounds("rtol")) = 1e-6
    atol: _q("1", optional=True, **_bounds("atol")) = None
    samples_per_revolution: _v(_int("samples_per_revolution"), int) = 720
    event_tol: _q("rad", **_bounds("event_tol")) = 1e-10
    max_events_per_revolution: _v(_int("max_events_per_revolution"), int) = 10000
    euler_steps_per_revolution: _v(_int("steps_per_revolution"), int) = 200000
    chatter_window: _q("rad", **_bounds("chatter_window")) = 1e-3
    chatter_events: _v(_int("chatter_events"), int) = 50
    compile: _v(Choice(*FLAGS), str) = "optimised"
    interpreted: _v(Flag(), bool) = False
    pressure: _v(Choice(*PRESSURE_PROFILES), str) = DEFAULT_PRESSURE
    calls_per_revolution: _v(_int("calls_per_revolution"), int | None) = None


# ---------------------------------------------------------------------------
# sections built from the submodels' declarations (derive/submodels/)

#: keys of parameter sections that are not model parameters: (before the parameters, after them)
_EXTRA_FIELDS: dict[str, tuple[dict[str, Any], dict[str, Any]]] = {
    "machine": (
        {"embodiment": (_v(Choice(*EMBODIMENTS), str),
                        Field(description="machine embodiment (Section 2)"))},
        {"ports": (Ports | None, Field(None, description="inlet and outlet ports (Table 1)"))},
    ),
}
#: within a section, keys are listed stiffnesses first, then damping, coefficients, the rest (stable otherwise)
_KIND_ORDER = {"N/m": 0, "N*s/m": 1, "1": 2}
#: the built-in sections, in the order scenes and docs list them: the model's parameters, then the rest
SECTION_ORDER = ("machine", "operation", "seal", "spring", "contacts", "friction", "pressure", "gas", "effects",
                 "assumptions", "solver")
_DOCS = {"machine": "[machine]: the limaçon machine (Eqs. 1-8).", "seal": "[seal]: the apex seal (Eqs. 16-31, 76, 80).",
         "spring": "[spring]: the groove-bottom spring (Eqs. 37-39).",
         "contacts": "[contacts]: contact stiffness and damping (Eqs. 34, 55, 62, 67, 73, Algorithm 1).",
         "friction": "[friction]: Coulomb coefficients, regularised as mu tanh(v / v_eps)."}


def _parameter_field(p) -> tuple[Any, Any]:
    """The pydantic field of a declared parameter: its unit, range, default and meaning. A parameter without a
    default that an effect switches (``registry.needing``) may be left out here: it is required only while that
    effect is on (:func:`.checks.check_needed`, once the effects are known)."""
    from apexseal.derive.submodels.registry import omissible_while_off

    # a schedulable one may be given as a schedule instead (the [<section>.schedule] table; checks.check_needed)
    omissible = p.optional or omissible_while_off(p) is not None or p.schedulable
    validator = SI(p.unit, bare=p.bare, optional=omissible, show=p.show, **p.range_kwargs())
    kind = float | None if omissible else float
    default = None if omissible else (p.default if p.default is not None else ...)
    return Annotated[kind, BeforeValidator(validator)], Field(default, description=p.meaning)


def _schedule_field(section: str, params: list) -> tuple[Any, Any]:
    """The ``schedule`` sub-table of a section with schedulable parameters (runtime/scenes/schedule.py): the knots'
    crank angles and each parameter's values there, checked as its own key is."""
    angles = Each(SI("rad", ge=-FULL_TURN, le=FULL_TURN, show="deg"), optional=False)
    fields = {"angles": (Annotated[tuple[float, ...], BeforeValidator(angles)],
                         Field(description="crank angle theta of each knot, increasing, within less than one "
                                           "revolution"))}
    for p in params:
        item = Each(SI(p.unit, bare=p.bare, show=p.show, **p.range_kwargs()))
        fields[p.leaf] = (Annotated[tuple[float, ...] | None, BeforeValidator(item)],
                          Field(None, description=f"{p.meaning}: its value at each knot, periodic and linear "
                                                  f"between knots (instead of {p.key})"))
    model = create_model(f"{section.title()}Schedule", __base__=Section, **fields)
    model.__doc__ = (f"[{section}.schedule]: parameters of [{section}] along the revolution, periodic and "
                     "piecewise linear in crank angle (runtime/scenes/schedule.py).")
    return model | None, Field(None, description="parameters along the revolution (runtime/scenes/schedule.py)")


def _option_fields(table: str) -> dict[str, Any]:
    from apexseal.derive.submodels.registry import options

    out = {}
    for name, opt in options().items():
        if opt.table != table:
            continue
        if table == "effects":  # true/false (or a choice); unset ones are resolved by Effects.from_mapping
            out[name] = (_v(Flag(optional=True), bool | None), Field(None, description=opt.meaning))
        else:
            out[name] = (_v(Choice(*opt.choices), str), Field(opt.default, description=opt.meaning))
    return out


@functools.lru_cache(maxsize=8)
def _sections(classes: tuple[type, ...]) -> dict[str, tuple[type[Section], bool]]:
    """The sections for the registered submodels ``classes`` (the key: the classes themselves, which the cache
    keeps alive, so that a class defined again never meets the sections of one whose id it took over)."""
    from apexseal.derive.submodels.registry import parameters

    from .declared_units import check_declared_units

    check_declared_units(classes)  # a user's submodel's units, as pint reads them
    by_section: dict[str, list] = {}
    for p in parameters(all_inputs=True):
        if p.key is not None:
            by_section.setdefault(p.section, []).append(p)
    built: dict[str, tuple[type[Section], bool]] = {}
    for section, params in by_section.items():
        params = sorted(params, key=lambda p: _KIND_ORDER.get(p.unit, 3))
        head, tail = _EXTRA_FIELDS.get(section, ({}, {}))
        schedulable = [p for p in params if p.schedulable]
        if schedulable:
            tail = {**tail, "schedule": _schedule_field(section, schedulable)}
        fields = {**head, **{p.leaf: _parameter_field(p) for p in params}, **tail}
        model = create_model(f"{section.title()}Section", __base__=Section, **fields)
        model.__doc__ = _DOCS.get(section, f"[{section}]: parameters of a submodel.")
        required = any(f.is_required() for f in model.model_fields.values())
        built[section] = (model, required)
    built["operation"] = (OperationSection, True)
    built["pressure"] = (PressureSection, False)
    built["effects"] = (create_model("EffectsSection", __base__=Section, **_option_fields("effects")), False)
    built["assumptions"] = (create_model("AssumptionsSection", __base__=Section, **_option_fields("assumptions")),
                            False)
    built["solver"] = (SolverSection, False)
    order = [n for n in SECTION_ORDER if n in built] + [n for n in built if n not in SECTION_ORDER]
    return {n: built[n] for n in order}


def sections() -> dict[str, tuple[type[Section], bool]]:
    """Section name -> (model, required), for the submodels registered now."""
    from apexseal.derive.submodels.registry import submodels

    return _sections(submodels())


def __getattr__(name: str):
    """``SECTIONS`` and the section classes by their names (``ContactsSection``, ...), as registered now."""
    if name == "SECTIONS":
        return sections()
    for model, _ in sections().values():
        if model.__name__ == name:
            return model
    raise AttributeError(name)


# ---------------------------------------------------------------------------
# schema walking (for messages and docs)


def _sub_model(annotation: Any) -> type[Section] | None:
    if isinstance(annotation, type) and issubclass(annotation, Section):
        return annotation
    for arg in getattr(annotation, "__args__", ()):
        if isinstance(arg, type) and issubclass(arg, Section):
            return arg
    return None


def model_at(model: type[Section], path: list[str]) -> type[Section] | None:
    """The nested model reached by ``path`` from ``model`` (None if the path leaves the schema)."""
    for part in path:
        field = model.model_fields.get(part)
        sub = _sub_model(field.annotation) if field is not None else None
        if sub is None:
            return None
        model = sub
    return model


def validator_of(model: type[Section], name: str) -> Any:
    """The scene validator (:class:`SI`, :class:`Int`, ...) of field ``name``, if any."""
    for meta in model.model_fields[name].metadata:
        if isinstance(meta, BeforeValidator):
            return meta.func
    return None


def key_paths(prefix: str = "") -> list[str]:
    """Every key path of the schema, e.g. ``machine.ports.inlet.angle`` (for docs and tests)."""
    out: list[str] = []

    def walk(model: type[Section], base: str) -> None:
        for name, field in model.model_fields.items():
            sub = _sub_model(field.annotation)
            if sub is not None:
                walk(sub, f"{base}.{name}")
            else:
                out.append(f"{base}.{name}")

    for section, (model, _) in sections().items():
        walk(model, section)
    return [p for p in out if p.startswith(prefix)]


# ---------------------------------------------------------------------------
# validation


def raw_at(raw: Any, path: list[str]) -> Any:
    """The raw value at ``path`` in the parsed TOML, or :data:`MISSING`."""
    for part in path:
        if not isinstance(raw, dict) or part not in raw:
            return MISSING
        raw = raw[part]
    return raw


#: what an unknown section, effect or modelling choice may be: a submodel's, whose package is not installed here
NOT_INSTALLED = "; if it is a submodel's, its package is not installed here (apexseal scene lists those that are)"


def _unknown(key: str, known: list[str], what: str = "key", package_hint: bool = False) -> str:
    hint = NOT_INSTALLED if package_hint else ""
    return f"unknown {what}{did_you_mean(key, known, cutoff=0.5)}{hint}; known: {', '.join(known)}"


def _problems(exc: ValidationError, section: str, model: type[Section], raw: Any) -> list[Problem]:
    out = []
    for err in exc.errors():
        loc = [str(p) for p in err["loc"]]
        key = ".".join([section, *loc])
        kind = err["type"]
        if kind == "scene":
            out.append(Problem(key, err["input"], err["msg"]))
        elif kind == "missing":
            parent = model_at(model, loc[:-1])
            spec = validator_of(parent, loc[-1]) if parent is not None else None
            sub = model_at(model, loc)
            what = (
                spec.expects()
                if spec is not None
                else (f"a table with keys {', '.join(sub.model_fields)}" if sub is not None else "a table")
            )
            out.append(Problem(key, MISSING, f"required; give {what}"))
        elif kind == "extra_forbidden":
            parent = model_at(model, loc[:-1])
            known = list(parent.model_fields) if parent is not None else []
            out.append(Problem(key, err["input"], _unknown(loc[-1], known,
                                                          package_hint=section in ("effects", "assumptions"))))
        elif kind in ("model_type", "model_attributes_type", "dict_type"):
            out.append(Problem(key, raw_at(raw, loc), "expected a table of keys"))
        else:  # pragma: no cover - every field has a scene validator
            out.append(Problem(key, err.get("input"), err["msg"]))
    return out


def validate_sections(raw: dict[str, Any], unranged: frozenset[str] = frozenset()) -> tuple[dict[str, Section],
                                                                                          list[Problem]]:
    """Validate every section of a parsed scene on its own.

    Returns the sections that are valid and the problems of the others, so that
    cross-key checks can still run on the valid ones. The dotted keys ``unranged`` (values no law of the scene's
    model reads, :func:`.checks.unread_keys`) are converted to SI but not range-checked (:class:`~.fields.SI`).
    """
    problems: list[Problem] = []
    valid: dict[str, Section] = {}
    known = sections()
    for key, value in raw.items():
        if key not in known:
            what = "section" if isinstance(value, dict) else "top-level key (keys belong in sections)"
            problems.append(Problem(key, value, _unknown(key, list(known), what, package_hint=isinstance(value, dict))))
    for name, (model, required) in known.items():
        if name not in raw:
            if required:
                problems.append(Problem(name, MISSING, f"required section [{name}] is missing"))
            else:
                valid[name] = model()
            continue
        if not isinstance(raw[name], dict):
            problems.append(Problem(name, raw[name], f"expected a table: [{name}]"))
            continue
        leaves = frozenset(k.split(".", 1)[1] for k in unranged if k.split(".", 1)[0] == name)
        try:
            valid[name] = model.model_validate(raw[name], context={UNRANGED: leaves} if leaves else None)
        except ValidationError as exc:
            problems.extend(_problems(exc, name, model, raw[name]))
    return valid, problems
