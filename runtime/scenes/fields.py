"""The validators of a scene file's fields: each converts one value and raises one clear message.

:class:`SI` (a quantity converted to SI and checked against a range), :class:`Int`, :class:`Choice`,
:class:`Flag`, :class:`Text` and :class:`PressureUnit` carry what is allowed (``allowed``, ``expects``), so that a
bad or missing key can say what to give; :func:`quantity` and :func:`validated` make annotated pydantic field types
of them (the sections of runtime/scenes/schema.py).
"""

import math
from typing import Annotated, Any

from pydantic import BeforeValidator, ValidationInfo
from pydantic_core import PydanticCustomError

from ...suggest import did_you_mean
from ..solving.settings import LIMITS, not_a_flag
from .units import QuantityError, Range, expected, parse_pressure_unit, parse_quantity, show_factor

#: the key of a validation context (``model_validate(..., context={UNRANGED: names})``) naming the fields whose
#: range :class:`SI` does not check
UNRANGED = "unranged"


def _fail(message: str) -> PydanticCustomError:
    return PydanticCustomError("scene", "{message}", {"message": message})


class SI:
    """A quantity converted to ``unit`` (pint syntax) and checked against a range.

    ``bare``: unit of bare numbers (default: ``unit``; angles refuse bare numbers).
    ``show``: unit in which the range is printed (default: ``unit``).
    A field named in the validation context's :data:`UNRANGED` (a value no law of the scene's model reads, its
    effect off: runtime/scenes/scene.py) is converted but not range-checked; a value that is no quantity of its
    kind (no number, an unknown unit, the wrong dimension) is refused all the same.
    """

    def __init__(
        self,
        unit: str,
        *,
        gt: float | None = None,
        ge: float | None = None,
        lt: float | None = None,
        le: float | None = None,
        bare: str | None = None,
        optional: bool = False,
        show: str | None = None,
    ) -> None:
        self.unit, self.bare, self.optional = unit, bare, optional
        self.range = Range(gt=gt, ge=ge, lt=lt, le=le)
        self.show = show or unit

    def __call__(self, value: Any, info: ValidationInfo) -> float | None:
        unranged = (info.context or {}).get(UNRANGED, ())
        return self.convert(value, ranged=info.field_name not in unranged)

    def convert(self, value: Any, *, ranged: bool = True) -> float | None:
        """``value`` in SI; a :class:`PydanticCustomError` (the message) if it is no quantity of this field's kind,
        or, ``ranged``, out of its range."""
        if value is None and self.optional:
            return None
        try:
            x = parse_quantity(value, self.unit, bare=self.bare)
        except QuantityError as exc:
            bounded = "" if self.range == Range() else f"; allowed: {self.allowed()}"
            raise _fail(exc.reason + bounded) from None
        if ranged and not self.range.holds(x):
            raise _fail(f"{self._shown(x)} is out of range; allowed: {self.allowed()}")
        return x

    def _factor(self) -> float:
        return show_factor(self.unit, self.show)

    def _shown(self, x: float) -> str:
        return _g(x) if self.show == "1" else f"{_g(x * self._factor())} {self.show}"

    def allowed(self) -> str:
        if self.show == self.unit:
            return self.range.describe(self.unit)
        f = self._factor()
        scaled = Range(
            *(
                None if b is None else round(b * f, 9)
                for b in (self.range.gt, self.range.ge, self.range.lt, self.range.le)
            )
        )
        return scaled.describe(self.show)

    def expects(self) -> str:
        return expected(self.unit) + ("" if self.range == Range() else f", {self.allowed()}")


class Each:
    """A TOML array of ``least``..``most`` values, each converted and checked by ``item`` (an :class:`SI`): the
    knots of a schedule (runtime/scenes/schedule.py). A bad value is named by its position in the array."""

    def __init__(self, item: SI, *, least: int = 2, most: int = 360, optional: bool = True) -> None:
        self.item, self.least, self.most, self.optional = item, least, most, optional
        self.unit, self.show = item.unit, item.show

    def __call__(self, value: Any, info: ValidationInfo) -> tuple[float, ...] | None:
        if value is None and self.optional:
            return None
        if not isinstance(value, list | tuple) or not self.least <= len(value) <= self.most:
            raise _fail(f"expected {self.expects()}")
        out = []
        for i, v in enumerate(value, 1):
            try:
                out.append(self.item.convert(v))
            except PydanticCustomError as exc:
                raise _fail(f"item {i} ({v!r}): {exc.message()}") from None
        return tuple(out)

    def allowed(self) -> str:
        return f"{self.least} to {self.most} values, each {self.item.expects()}"

    def expects(self) -> str:
        return f"an array of {self.allowed()}"


class Int:
    """An integer (TOML integer, not float or bool) in a range."""

    def __init__(self, *, ge: int | None = None, le: int | None = None) -> None:
        self.range = Range(ge=ge, le=le)

    def __call__(self, value: Any) -> int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise _fail(f"expected an integer, {self.allowed()}")
        if not self.range.holds(value):
            raise _fail(f"{value} is out of range; allowed: {self.allowed()}")
        return value

    def allowed(self) -> str:
        return self.range.describe(name="n")

    def expects(self) -> str:
        return f"an integer, {self.allowed()}"


class Choice:
    """One of a few strings; a near miss gets a "did you mean"."""

    def __init__(self, *allowed: str) -> None:
        self.values = allowed

    def __call__(self, value: Any) -> str:
        if isinstance(value, str) and value in self.values:
            return value
        raise _fail(f"not allowed{did_you_mean(value, self.values)}; allowed: {self.allowed()}")

    def allowed(self) -> str:
        return ", ".join(f'"{v}"' for v in self.values)

    def expects(self) -> str:
        return f"one of {self.allowed()}"


class Flag:
    """A TOML boolean (``true``/``false``; not 0/1 or "yes")."""

    def __init__(self, optional: bool = False) -> None:
        self.optional = optional

    def __call__(self, value: Any) -> bool | None:
        if value is None and self.optional:
            return None
        if not isinstance(value, bool):
            raise _fail(not_a_flag(value))
        return value

    def allowed(self) -> str:
        return "true or false"

    expects = allowed


class Text:
    """A non-empty string (a file name)."""

    def __init__(self, optional: bool = False) -> None:
        self.optional = optional

    def __call__(self, value: Any) -> str | None:
        if value is None and self.optional:
            return None
        if not isinstance(value, str) or not value.strip():
            raise _fail("expected a non-empty string")
        if "\0" in value:
            raise _fail(f"a file name cannot contain a NUL character; allowed: {self.allowed()}")
        return value

    def allowed(self) -> str:
        return "a non-empty string without NUL characters"

    expects = allowed


class PressureUnit:
    """A pressure unit name, e.g. "Pa", "kPa", "bar"."""

    def __call__(self, value: Any) -> str:
        try:
            parse_pressure_unit(value)
        except QuantityError as exc:
            raise _fail(exc.reason) from None
        return value

    def allowed(self) -> str:
        return 'a pressure unit such as "Pa", "kPa" or "bar"'

    expects = allowed


def _g(x: float) -> str:
    return f"{x:.6g}"


def quantity(unit: str, **kw: Any) -> Any:
    """Annotated float field of a quantity in ``unit``."""
    kind = float | None if kw.get("optional") else float
    return Annotated[kind, BeforeValidator(SI(unit, **kw))]


def validated(validator: Any, kind: Any) -> Any:
    """Annotated ``kind`` field checked by ``validator``."""
    return Annotated[kind, BeforeValidator(validator)]


TWO_PI = 2 * math.pi


def setting_bounds(name: str) -> dict[str, float]:
    """The bounds of run setting ``name`` (runtime/solving/settings.py: one table for scene, CLI and API)."""
    rng = LIMITS[name][1]
    return {k: getattr(rng, k) for k in ("gt", "ge", "lt", "le") if getattr(rng, k) is not None}


def setting_int(name: str) -> Int:
    """The integer field of run setting ``name``, with its bounds."""
    return Int(**setting_bounds(name))
