"""Quantities with units in scene files, read with pint.

A value is either a TOML number, taken in the SI unit of its key (``ks = 5000``
is 5000 N/m), or a string with a unit (``"5e3 N/m"``, ``"3 mm"``, ``"6 bar"``).
A quoted number without a unit (``delta_s = "2.0"``) is an error where the key has a
dimension: the quotes say a unit was meant. Three exceptions remove the usual ambiguities:

* angles and angular speeds need a unit (``"30 deg"``, ``"0.5 rad"``,
  ``"0 rad/s"``); a bare number is an error, never silently radians;
* a rotational speed must carry an angle (``rpm``, ``rev/s``, ``rad/s``); ``Hz``
  or ``1/s`` is refused, because pint would read ``25 Hz`` as 25 rad/s.

The one key whose name is its unit, ``operation.rpm``, reads bare numbers as rev/min.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING, Any

from ...derive.parameters import ABSOLUTE_PRESSURE
from . import unit_memo

if TYPE_CHECKING:
    import pint


class QuantityError(ValueError):
    """A value that is not a quantity of the expected kind; ``reason`` says why."""

    def __init__(self, key: str, value: Any, reason: str) -> None:
        self.key, self.value, self.reason = key, value, reason
        where = f"{key} = {value!r}: " if key else f"{value!r}: "
        super().__init__(where + reason)


@lru_cache(maxsize=1)
def registry() -> pint.UnitRegistry:
    """The shared unit registry, built once per process.

    pint parses its definition files on every start (~0.5 s); with a cache folder (in the project's cache,
    ``$APEXSEAL_CACHE/pint``) it loads them parsed (~0.08 s). pint's cache library writes its pickles in place, so
    the folder is used under a lock (two processes on an empty cache, such as a sweep's first points, would
    otherwise read each other's half-written files), and a folder whose files cannot be read (a process killed
    while writing one) is emptied and written again. An unwritable cache falls back to parsing.
    """
    import shutil

    import pint

    from apexseal.derive.cache import cache_dir
    from apexseal.files import file_lock

    folder = cache_dir() / "pint"
    try:
        with file_lock(folder.with_name("pint.lock")):
            try:
                ureg = pint.UnitRegistry(cache_folder=folder)
            except OSError:
                raise
            except Exception:  # noqa: BLE001 - a cut or foreign file in the cache: rebuilt once, then pint's error
                shutil.rmtree(folder, ignore_errors=True)
                ureg = pint.UnitRegistry(cache_folder=folder)
    except OSError:
        ureg = pint.UnitRegistry()
    ureg.define("rev = revolution")
    return ureg


#: SI unit (pint syntax) -> the word used in messages
KINDS: dict[str, str] = {
    "m": "length",
    "m/s": "speed",
    "rad": "angle",
    "rad/s": "angular speed",
    "rpm": "rotational speed",
    "kg": "mass",
    "kg*m^2": "moment of inertia",
    "kg/m^3": "density",
    "N/m": "stiffness",
    "N*s/m": "damping coefficient",
    "Pa": "pressure",
    "N": "force",
    "W": "power",
    "K": "temperature",
    "J/(kg*K)": "specific gas constant",
    "s": "time",
    "1": "plain number",
}

#: example spelling for messages
EXAMPLES: dict[str, str] = {
    "m": '"3 mm"',
    "m/s": '"1 mm/s"',
    "rad": '"30 deg"',
    "rad/s": '"0 rad/s"',
    "rpm": '"1500 rpm"',
    "kg": '"17 g"',
    "kg*m^2": '"1.05e-7 kg*m^2"',
    "kg/m^3": '"7200 kg/m^3"',
    "N/m": '"5e3 N/m"',
    "N*s/m": '"27 N*s/m"',
    "Pa": '"6 bar"',
    "N": '"5 N"',
    "W": '"60 W"',
    "K": '"300 K"',
    "J/(kg*K)": '"287 J/(kg*K)"',
    "s": '"600 s"',
    "1": "0.1",
}

#: a quantity string starts with a number: "3 mm", "-25 deg", ".5 bar", "5e3 N/m"
NUMBER_FIRST = re.compile(r"^[+-]?\.?\d")
#: the one number a quantity string starts with; the rest is its unit, which holds no number of its own
LEADING_NUMBER = re.compile(r"^[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
#: words that spell a number that is not finite
NOT_FINITE = re.compile(r"^[+-]?(?:inf|infinity|nan)\b", re.IGNORECASE)

#: units that contain an angle, so bare numbers are ambiguous and an angle must be spelled out
ANGULAR = ("rad", "rad/s", "rpm")


def show_factor(unit: str, show: str) -> float:
    """Multiplies a value in ``unit`` into ``show`` (pint, loaded only when the units differ)."""
    return 1.0 if show == unit else float(registry().Quantity(1.0, unit).to(show).magnitude)


def declared_unit_problem(unit: str, to: str | None = None) -> str | None:
    """Why a submodel's declared SI unit ``unit`` is not one (pint does not read it, or reads it as a unit that is
    not SI: "Nm" is pint's number_meter, not a newton metre), or with ``to``, why ``to`` (the unit its messages or
    its plausible range are shown in) does not convert to it; None when it is fine. What pint accepted is
    remembered (:mod:`.unit_memo`), so a warm process that registers the submodel again imports no pint."""
    memo = unit_memo.key_of(unit, to, "declared unit")
    if unit_memo.lookup(memo) is not None:
        return None
    ureg = registry()
    try:
        q = ureg.Quantity(1.0, unit)
        reading = str(q.units)
        if to is not None:
            q.to(to)
        else:
            base = q.to_base_units()
            if not math.isclose(base.magnitude, 1.0, rel_tol=1e-12):
                return (f"is not an SI unit: pint reads it as {reading}, 1 {unit} = {base.magnitude:g} {base.units} "
                        "(declare the SI unit in pint's syntax, e.g. \"N*m\", \"N/m\", \"Pa\"; show= and plausible= "
                        "give the unit values are shown in)")
    except Exception as exc:  # noqa: BLE001 - pint's own errors (undefined unit, syntax, dimensionality), in words
        if to is not None and type(exc).__name__ == "DimensionalityError":
            return f"does not convert to {unit!r}: {exc}"
        return f"is not a unit pint reads: {exc}"
    unit_memo.remember(memo, 1.0)
    return None


def expected(unit: str) -> str:
    """Words for the expected kind, e.g. ``a length in m (e.g. "3 mm")``; a unit of neither table (a user's
    submodel's) is ``a quantity in N*m (e.g. "1 N*m")``."""
    kind = KINDS.get(unit, "quantity")
    article = "an" if kind[0] in "aeiou" else "a"
    if unit == "1":
        return "a plain number"
    return f"{article} {kind} in {unit} (e.g. {example(unit)})"


def example(unit: str) -> str:
    """How a value in ``unit`` is written, for messages: ``"3 mm"`` for m, ``"1 N*m"`` for a unit without one."""
    return EXAMPLES.get(unit, f'"1 {unit}"')


def _has_angle(q: pint.Quantity) -> bool:
    return dict(q.to_root_units().unit_items()).get("radian", 0) == 1


def quantity_text(value: Any) -> str | None:
    """A pint quantity with a number as magnitude as the text a scene writes ("3.2 millimeter"), or None for any
    other value (the scene, the command line and the API take pint's quantities as they take this text)."""
    if type(value).__module__.split(".")[0] != "pint" or not hasattr(value, "magnitude") or not hasattr(value, "units"):
        return None
    magnitude = value.magnitude
    if type(magnitude).__module__ == "numpy" and getattr(magnitude, "ndim", None) == 0:
        magnitude = magnitude.item()
    return f"{magnitude!r} {value.units}" if isinstance(magnitude, int | float) and not isinstance(magnitude, bool) \
        else None


def parse_quantity(value: Any, unit: str, *, key: str = "", bare: str | None = None) -> float:
    """The magnitude of ``value`` in ``unit`` (pint syntax, e.g. ``"m"``, ``"N/m"``, ``"rad"``).

    ``value`` is an int or float (taken in ``bare`` if given, else in ``unit``) or a
    string with a unit. Angles and angular speeds refuse bare numbers unless
    ``bare`` is given. Raises :class:`QuantityError` naming ``key``, the value and
    the expected unit. The result is rounded to 15 significant digits, so that
    ``"3.06 mm"`` gives exactly ``0.00306``. A conversion pint made before (in any process) is
    remembered (:mod:`.unit_memo`): pint is imported only for text never read before.
    """
    plain = isinstance(value, int | float) and not isinstance(value, bool) and (bare is None or bare == unit)
    if plain or not isinstance(value, int | float | str):
        return _parse_quantity(value, unit, key, bare)
    memo = unit_memo.key_of(value, unit, bare)
    x = unit_memo.lookup(memo)
    if x is None:
        x = _parse_quantity(value, unit, key, bare)
        unit_memo.remember(memo, x)
    return x


def _parse_quantity(value: Any, unit: str, key: str, bare: str | None) -> float:
    angular = unit in ANGULAR
    if isinstance(value, bool) or not isinstance(value, int | float | str):
        raise QuantityError(key, value, f"expected {expected(unit)}, got {type(value).__name__}")
    number = value
    if isinstance(value, str):
        text = value.strip()
        if "," in text:
            raise QuantityError(key, value, f"use a decimal point, not a comma; expected {expected(unit)}")
        if NOT_FINITE.match(text):
            raise QuantityError(key, value, f"must be finite; expected {expected(unit)}")
        if not NUMBER_FIRST.match(text):
            what = "is not a number" if unit == "1" else "needs a number first, then the unit"
            raise QuantityError(key, value, f"{what}; expected {expected(unit)}")
        q = _number_and_unit(text, unit, key, value)
        if tuple(q.unit_items()):  # written with a unit (pint's `unitless` is also true for "%")
            return _convert(q, unit, key, value, angular)
        if unit != "1" and (not angular or bare is not None):  # "2.0" for a length: the quotes promise a unit
            raise QuantityError(
                key, value, f"a quoted value needs a unit (write it with one, e.g. {example(unit)}, "
                f"or as a bare TOML number in {unit}); expected {expected(unit)}"
            )
        number = float(q.magnitude)  # "0.1" for a plain number: the same as the TOML number
    if angular and bare is None:
        raise QuantityError(
            key,
            value,
            f"give a unit: deg or rad (an angle without a unit is ambiguous), e.g. {EXAMPLES[unit]}",
        )
    number = float(number)
    if bare is not None and bare != unit:
        return _convert(registry().Quantity(number, bare), unit, key, value, angular)
    return _round(_finite(number, key, value, unit))


def _number_and_unit(text: str, unit: str, key: str, raw: Any) -> pint.Quantity:
    """``text`` as one number followed by a unit that holds no number: ``"3 mm"``, ``"5e3 N/m"``, ``"1 kg*m^2"``.

    pint would evaluate an expression (``"3 mm 4"`` as 12 mm, ``"6 mm / 2"`` as 3 mm): a typo would pass as another
    value, so a second number is refused.
    """
    import pint

    ureg = registry()
    number = LEADING_NUMBER.match(text)
    if number is None:
        raise QuantityError(key, raw, f"cannot read this as a quantity; expected {expected(unit)}")
    rest = text[number.end():].strip()
    if not rest:
        return ureg.Quantity(float(number.group()), "dimensionless")
    try:
        units = ureg.parse_units(rest)
    except pint.UndefinedUnitError as exc:
        raise QuantityError(key, raw, f"unknown unit {exc.args[0]!r}; expected {expected(unit)}") from None
    except Exception as exc:  # pint's parser raises several kinds for malformed text
        if "scaling factor" in str(exc):  # a number in what follows the first
            reason = f"write one number, then its unit: {rest!r} after {number.group()} holds a number"
        else:
            reason = f"cannot read this as a quantity ({rest!r} is not a unit)"
        raise QuantityError(key, raw, f"{reason}; expected {expected(unit)}") from None
    return ureg.Quantity(float(number.group()), units)


def _convert(q: pint.Quantity, unit: str, key: str, raw: Any, angular: bool) -> float:
    import pint

    ureg = registry()
    try:
        out = float(q.to(ureg.Quantity(1, unit).units).magnitude)
    except pint.DimensionalityError:
        got = f"{q.units:~}" + ("" if q.dimensionless else f" ({q.dimensionality})")
        raise QuantityError(key, raw, f"wrong unit: expected {expected(unit)}, got {got}") from None
    if angular and not _has_angle(q):
        if unit == "rad":
            raise QuantityError(key, raw, f"give a unit: deg or rad; expected {expected(unit)}")
        raise QuantityError(
            key,
            raw,
            f"{q.units:~} carries no angle, so the speed is ambiguous: use rpm, rev/s, "
            f"rad/s or deg/s (not Hz or 1/s); expected {expected(unit)}",
        )
    return _round(_finite(out, key, raw, unit))


def _finite(x: float, key: str, raw: Any, unit: str) -> float:
    if not math.isfinite(x):
        raise QuantityError(key, raw, f"must be finite; expected {expected(unit)}")
    return x


def _round(x: float) -> float:
    return float(f"{x:.15g}")


def parse_pressure_unit(text: Any, *, key: str = "pressure.unit") -> float:
    """The factor from ``text`` (a pressure unit such as ``"Pa"``, ``"bar"``, ``"kPa"``) to Pa (remembered like
    :func:`parse_quantity`'s conversions)."""
    if not isinstance(text, str):
        raise QuantityError(key, text, 'expected a pressure unit such as "Pa", "kPa" or "bar"')
    memo = unit_memo.key_of(text, "pressure unit")
    x = unit_memo.lookup(memo)
    if x is None:
        x = _pressure_factor(text, key)
        unit_memo.remember(memo, x)
    return x


def _pressure_factor(text: str, key: str) -> float:
    import pint

    ureg = registry()
    try:
        units = ureg.parse_units(text.strip())
    except Exception:
        raise QuantityError(
            key, text, 'unknown unit; expected a pressure unit such as "Pa", "kPa" or "bar"'
        ) from None
    try:
        return _round(float(ureg.Quantity(1.0, units).to("Pa").magnitude))
    except pint.DimensionalityError:
        raise QuantityError(
            key, text, 'wrong unit: expected a pressure unit such as "Pa", "kPa" or "bar"'
        ) from None


@dataclass(frozen=True)
class Range:
    """Bounds of a value in its SI unit; ``None`` means unbounded."""

    gt: float | None = None
    ge: float | None = None
    lt: float | None = None
    le: float | None = None

    def holds(self, x: float) -> bool:
        return not (
            (self.gt is not None and not x > self.gt)
            or (self.ge is not None and not x >= self.ge)
            or (self.lt is not None and not x < self.lt)
            or (self.le is not None and not x <= self.le)
        )

    def describe(self, unit: str = "", name: str = "value") -> str:
        """E.g. ``0 <= value < 1`` or ``> 0 m``."""
        u = "" if unit in ("", "1") else f" {unit}"
        low = (
            f"{_g(self.gt)} < "
            if self.gt is not None
            else f"{_g(self.ge)} <= "
            if self.ge is not None
            else ""
        )
        high = (
            f" < {_g(self.lt)}"
            if self.lt is not None
            else f" <= {_g(self.le)}"
            if self.le is not None
            else ""
        )
        if low and high:
            return f"{low}{name}{high}{u}"
        if low:
            return (
                f"{'>' if self.gt is not None else '>='} {_g(self.gt if self.gt is not None else self.ge)}{u}"
            )
        if high:
            return f"{high.strip()}{u}"
        return "any finite value"


def _g(x: float) -> str:
    return f"{x:.6g}"


# ---------------------------------------------------------------------------
# plausibility: magnitudes far outside engineering practice for this machine


class PlausibilityWarning(UserWarning):
    """A scene value that is valid but far outside engineering practice (probably a unit slip)."""


@dataclass(frozen=True)
class Plausible:
    """The range of engineering practice of a key, in SI, and the unit to show it in."""

    lo: float
    hi: float
    show: str
    #: the unit ``lo`` and ``hi`` (and the values checked) are in: the key's SI unit
    si: str

    @property
    def factor(self) -> float:
        """Multiplies a value in :attr:`si` into :attr:`show` (pint)."""
        return show_factor(self.si, self.show)

    def shown(self, x: float) -> str:
        """``x`` (in :attr:`si`) in :attr:`show`, with the unit unless it is the dimensionless "1"."""
        return _g(x * self.factor) + ("" if self.show == "1" else f" {self.show}")

    def describe(self) -> str:
        return f"{_g(self.lo * self.factor)} to {self.shown(self.hi)}"


#: the scene's own settings (not parameters of a submodel) -> their range of engineering practice; the
#: parameters declare theirs (``Parameter.plausible``)
SETTINGS_PLAUSIBLE: dict[str, Plausible] = {
    "operation.rpm": Plausible(1.0, 50000.0, "rpm", "rpm"),
    "pressure.Pa": Plausible(*ABSOLUTE_PRESSURE, si="Pa"),
    "pressure.Pb": Plausible(*ABSOLUTE_PRESSURE, si="Pa"),
}

#: absolute chamber pressures of a table outside this span are implausible (a table in bar declared in Pa, or in
#: Pa declared in bar): the span of a constant pressure's keys
TABLE_PRESSURES = SETTINGS_PLAUSIBLE["pressure.Pa"]
#: a table whose absolute pressures all lie below this (Pa) is warned of too: well below atmospheric in both
#: chambers over the whole revolution is no expander's (a table in bar declared unit = "kPa": 1.2-8 kPa)
SUBATMOSPHERIC_MAX = 20e3
#: atmospheric pressure (Pa): the unit suggested for a table below :data:`SUBATMOSPHERIC_MAX` lifts it above this
ATMOSPHERIC = 101325.0
#: the units a pressure table may be suggested in, smallest first
TABLE_UNITS = ("Pa", "kPa", "bar", "MPa")


def table_pressures_implausible(pa, pb, unit: str = "Pa") -> str | None:
    """Why a pressure table's absolute pressures (Pa, both chambers; its numbers were declared in ``unit``) lie
    outside :data:`TABLE_PRESSURES` (a table in bar or kPa read in Pa, or the other way round), or all below
    :data:`SUBATMOSPHERIC_MAX` (a table in bar read in kPa), or None when they do not."""
    import numpy as np

    if not np.size(pa):
        return None
    low, high = float(min(np.min(pa), np.min(pb))), float(max(np.max(pa), np.max(pb)))
    lo, hi = TABLE_PRESSURES.lo, TABLE_PRESSURES.hi
    if lo <= low and high <= hi:
        return _subatmospheric(low, high, unit)
    why = (f"below {lo:g} Pa (a vacuum far beyond engineering practice)" if low < lo else
           f"above {hi:g} Pa (far beyond engineering practice)")
    return f"the table's absolute pressures span {low:.4g}..{high:.4g} Pa, {why}{_unit_hint(low, high, unit)}"


def _subatmospheric(low: float, high: float, unit: str) -> str | None:
    """Why a table of absolute pressures ``low``..``high`` Pa, declared in ``unit``, all below
    :data:`SUBATMOSPHERIC_MAX` is implausible, and the unit that would lift its numbers above atmospheric; None above
    it."""
    if high >= SUBATMOSPHERIC_MAX:
        return None
    return (f"the table's absolute pressures span {low:.4g}..{high:.4g} Pa (unit = \"{unit}\"), all below "
            f"{SUBATMOSPHERIC_MAX:g} Pa, well below atmospheric ({ATMOSPHERIC:g} Pa) in both chambers over the whole "
            f"revolution: no machine's chambers{_unit_hint(low, high, unit)}")


def _unit_hint(low: float, high: float, unit: str) -> str:
    """``; read in bar, its numbers would span 1..4 bar: is the table in bar (unit = "bar")?`` for a table of
    absolute pressures ``low``..``high`` Pa declared in ``unit``: the first of :data:`TABLE_UNITS` (another than
    ``unit``) in which its highest number is at least atmospheric and within :data:`TABLE_PRESSURES`; else (or when
    its lowest is too low but its highest atmospheric already: a few rows too low are no unit slip) a question
    naming the units a table may be in."""
    factor = parse_pressure_unit(unit)
    lifted = [u for u in TABLE_UNITS if parse_pressure_unit(u) != factor
              and ATMOSPHERIC <= high / factor * parse_pressure_unit(u) <= TABLE_PRESSURES.hi]
    if not lifted or low < TABLE_PRESSURES.lo <= ATMOSPHERIC <= high:  # a few rows too low, the rest lifted: no slip
        units = ", ".join(f'"{u}"' for u in TABLE_UNITS)
        return f": is the table in another unit (unit = {units})?"
    return (f"; read in {lifted[0]}, its numbers would span {low / factor:.4g}..{high / factor:.4g} {lifted[0]}: "
            f"is the table in {lifted[0]} (unit = \"{lifted[0]}\")?")


def plausible_ranges() -> dict[str, Plausible]:
    """Scene key -> range of engineering practice for limaçon machines of rotary-engine size (docs/scenes.md,
    "Plausible ranges"): the registered submodels' parameters' (``Parameter.plausible``), then the scene's own
    settings. Outside it a scene still loads, with a :class:`PlausibilityWarning`; when the scene also has errors,
    the implausible keys are reported first, as the likely cause."""
    from ...derive.submodels.registry import parameters

    declared = {p.key: Plausible(*p.plausible, si=p.unit) for p in parameters(all_inputs=True)
                if p.plausible and p.key}
    return declared | SETTINGS_PLAUSIBLE


def implausible(values: dict[str, tuple[float, Any]]) -> list[tuple[str, float, str]]:
    """``(key, SI value, message)`` for each entry of ``values`` (key -> (SI value, value as written)) outside
    :func:`plausible_ranges`; a bare number of a length that would be plausible in mm gets a "did you mean"."""
    out = []
    ranges = plausible_ranges()
    for key, (x, written) in values.items():
        rule = ranges.get(key)
        if rule is None or x is None or rule.lo <= x <= rule.hi:
            continue
        out.append((key, x, f"{rule.shown(x)} is far outside engineering practice for this key "
                            f"({rule.describe()}){bare_hint(rule, x, written)}"))
    return out


def bare_hint(rule: Plausible, x: float, written: Any) -> str:
    """``; a bare number is in m: did you mean "3 mm"?`` for a bare number ``written`` (read in SI, ``x``) of a length
    or a mass that would be plausible in the unit ``rule`` shows the key in (mm, g), else ``""``: a pressure, shown
    in kPa, is more likely meant in bar, and no hint is better than a wrong one."""
    bare = isinstance(written, int | float) and not isinstance(written, bool)
    if not bare or rule.si not in ("m", "kg") or rule.show == rule.si or not rule.lo <= x / rule.factor <= rule.hi:
        return ""
    return f"; a bare number is in {rule.si}: did you mean \"{_g(x)} {rule.show}\"?"
