"""The one error a scene raises: every problem found, one per line.

A scene is checked completely before anything is built (units, types, ranges,
unknown keys, physical consistency, the pressure table), and all problems are
reported together, each naming the key path, the value given and what is
allowed, so a user can fix a scene file in one pass.
"""

from __future__ import annotations

import json
import math
from typing import Any

#: placeholder shown as the value of a key that was not given
MISSING = "(missing)"


class Problem(tuple):
    """One problem: ``(key, value, message)``; ``key`` is a dotted path such as ``seal.Wg``."""

    __slots__ = ()

    def __new__(cls, key: str, value: Any, message: str) -> Problem:
        return super().__new__(cls, (key, value, message))

    @property
    def key(self) -> str:
        return self[0]

    @property
    def value(self) -> Any:
        return self[1]

    @property
    def message(self) -> str:
        return self[2]

    def __str__(self) -> str:
        return f"{self.key} = {show_value(self.value)}: {self.message}"


def show_value(value: Any) -> str:
    """The value as the user wrote it: strings quoted, a missing key as ``(missing)``."""
    if value is MISSING:
        return MISSING
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str) and any(ord(c) < 32 or ord(c) == 127 for c in value):
        return json.dumps(value, ensure_ascii=False)  # escaped as TOML writes them (a NUL shown, not printed)
    if isinstance(value, str):
        return f"'{value}'" if '"' in value and "'" not in value else f'"{value}"'
    if isinstance(value, dict):  # an inline table, as TOML writes it
        return "{" + ", ".join(f"{k} = {show_value(v)}" for k, v in value.items()) + "}"
    return show_repr(value)


def show_repr(value: Any) -> str:
    """Python's repr, but a float from 1e6 up in exponent form, as short as it reads back exactly (``1e+09``, not
    ``1000000000.0``), as a user writes a stiffness or a bound; Python and TOML read both forms."""
    if not isinstance(value, float) or not math.isfinite(value) or abs(value) < 1e6:
        return repr(value)
    digits = 0
    while float(f"{value:.{digits}e}") != value:
        digits += 1
    return f"{value:.{digits}e}"


class SceneError(ValueError):
    """A scene that cannot be used; ``errors`` lists every ``(key, value, message)``."""

    def __init__(self, errors: list[tuple[str, Any, str]], source: str | None = None) -> None:
        self.errors: list[Problem] = [Problem(*e) for e in errors]
        self.source = source
        where = f"scene {source}" if source else "scene"
        count = len(self.errors)
        head = f"{where}: {count} problem{'s' if count != 1 else ''}"
        super().__init__("\n".join([head, *(f"  {p}" for p in self.errors)]))

    def keys(self) -> list[str]:
        """The key paths of all problems, in order."""
        return [p.key for p in self.errors]


class IgnoredValueWarning(UserWarning):
    """A scene value out of its range that no law of the scene's model reads (its effect off): the scene loads,
    the value is ignored, and the warning names it (runtime/scenes/checks.py, ``ignored_values``)."""
