"""Chamber pressures Pa(theta), Pb(theta) for the seal model (Eq. 75).

Chamber a is on the seal's +Ys side, chamber b on its -Ys side. A source gives
both as vectorised, 2π-periodic functions of the crank angle theta (rad), in Pa.
The runtime feeds them to the CasADi integrators as inputs held constant over
each output interval, so every source also gives :meth:`PressureSource.interval_means`.

Sources (``[pressure] source``):

* ``"none"``: zero pressure; the scene then switches the chamber_pressure effect off;
* ``"constant"``: ``Pa``, ``Pb`` fixed;
* ``"chamber"``, ``"chamber+leakage"``: the chamber gas model (derive/submodels/gas.py) computes them from
  its own states; nothing is fed in;
* ``"table"``: a CSV file ``theta_deg,Pa,Pb`` (one revolution, angles strictly
  increasing within [0, 360) or [-180, 180); pressures absolute, in ``unit``),
  interpolated linearly and periodically. Lines starting with ``#`` are comments.
  While the chamber_pressure effect is off the file is not read (:class:`UnreadTable`).
"""

from __future__ import annotations

import functools
import hashlib
import math
import os
import stat
from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from .errors import Problem, SceneError
from .units import parse_pressure_unit

TWO_PI = 2 * math.pi
HEADER = ("theta_deg", "Pa", "Pb")
#: a table whose angles span no more than this (deg) was most likely written in radians (a revolution is 2 pi =
#: 6.283 rad; 1 % above it for a last row rounded up)
RADIANS_SPAN = 1.01 * 2 * math.pi
#: how many row problems a table error lists before summarising the rest
MAX_ROW_PROBLEMS = 20
#: the largest pressure table read (one revolution; 10 MB is ~300 000 rows)
MAX_TABLE_BYTES = 10 * 2**20
#: the most characters of a line of the file quoted in a message
EXCERPT = 60


def excerpt(text: str, limit: int = EXCERPT) -> str:
    """``text`` quoted for a message: at most ``limit`` characters, invisible characters escaped."""
    shown = repr(text[:limit])[1:-1]
    return shown + (f"... ({len(text) - limit} more characters)" if len(text) > limit else "")


def _edges(theta_edges: Any) -> np.ndarray:
    e = np.asarray(theta_edges, dtype=float)
    if e.ndim != 1 or e.size < 2:
        raise ValueError("theta_edges must be a 1-D array of at least 2 crank angles")
    if not np.all(np.isfinite(e)) or not np.all(np.diff(e) > 0):
        raise ValueError("theta_edges must be finite and strictly increasing")
    return e


class PressureSource(ABC):
    """A source of the two chamber pressures, in Pa, as 2π-periodic functions of theta (rad)."""

    kind: ClassVar[str]

    @abstractmethod
    def Pa(self, theta: Any) -> np.ndarray:
        """Pressure of chamber a at crank angles ``theta``."""

    @abstractmethod
    def Pb(self, theta: Any) -> np.ndarray:
        """Pressure of chamber b at crank angles ``theta``."""

    @abstractmethod
    def interval_means(self, theta_edges: Any) -> tuple[np.ndarray, np.ndarray]:
        """Means of Pa and Pb over each interval ``[theta_edges[k], theta_edges[k+1]]``."""

    @abstractmethod
    def to_dict(self) -> dict[str, Any]:
        """Normalised content (for ``Scene.to_dict`` and the content hash)."""

    def __call__(self, theta: Any) -> tuple[np.ndarray, np.ndarray]:
        return self.Pa(theta), self.Pb(theta)

    def rows_per_revolution(self) -> int:
        """How many corners the pressures have in a revolution (a table's rows; 0: none, they are smooth). A run
        integrates at least this many intervals a revolution, so that it sees every row (runtime/solving/run.py)."""
        return 0


@dataclass(frozen=True)
class ConstantPressure(PressureSource):
    """Both chambers at fixed pressures."""

    pa: float
    pb: float
    kind: ClassVar[str] = "constant"

    def Pa(self, theta: Any) -> np.ndarray:
        return np.full(np.shape(theta), self.pa, dtype=float)

    def Pb(self, theta: Any) -> np.ndarray:
        return np.full(np.shape(theta), self.pb, dtype=float)

    def interval_means(self, theta_edges: Any) -> tuple[np.ndarray, np.ndarray]:
        n = _edges(theta_edges).size - 1
        return np.full(n, self.pa), np.full(n, self.pb)

    def to_dict(self) -> dict[str, Any]:
        return {"source": self.kind, "Pa": self.pa, "Pb": self.pb}


@dataclass(frozen=True)
class NoPressure(ConstantPressure):
    """No gas load: both pressures zero (the chamber_pressure effect is off)."""

    pa: float = 0.0
    pb: float = 0.0
    kind: ClassVar[str] = "none"

    def to_dict(self) -> dict[str, Any]:
        return {"source": self.kind}


@dataclass(frozen=True)
class GasModelPressure(NoPressure):
    """The chamber gas model's pressures: states of the model, so nothing is fed in (u = 0)."""

    source: str = "chamber"
    kind: ClassVar[str] = "chamber"

    def to_dict(self) -> dict[str, Any]:
        return {"source": self.source}


@dataclass(frozen=True)
class UnreadTable(NoPressure):
    """A table source while the chamber_pressure effect is off: no law reads the pressures, so the file is neither
    needed nor read (its name and unit are kept, as the scene gives them, with the folder it is relative to; the
    pressures are zero)."""

    file: str = ""
    unit: str = "Pa"
    base_dir: Any = field(default=None, compare=False, repr=False)
    kind: ClassVar[str] = "table"

    def load(self) -> TablePressure | None:
        """The table, read now, if its file is there and valid; None otherwise (it was not needed: nothing read it)."""
        if self.base_dir is None:
            return None
        try:
            return load_table(self.file, self.base_dir, self.unit)
        except (SceneError, OSError, ValueError):
            return None

    def to_dict(self) -> dict[str, Any]:
        return {"source": self.kind, "file": self.file, "unit": self.unit}


class PeriodicLinear:
    """A 2π-periodic piecewise-linear function through knots ``(x, y)`` (any order, distinct mod 2π)."""

    def __init__(self, x: np.ndarray, y: np.ndarray) -> None:
        x = np.mod(np.asarray(x, dtype=float), TWO_PI)
        order = np.argsort(x)
        self.x, self.y = x[order], np.asarray(y, dtype=float)[order]
        # one period of knots, closed: x0 .. x0 + 2π
        self._xs = np.append(self.x, self.x[0] + TWO_PI)
        self._ys = np.append(self.y, self.y[0])
        seg = 0.5 * (self._ys[1:] + self._ys[:-1]) * np.diff(self._xs)
        self._cum = np.concatenate(([0.0], np.cumsum(seg)))
        self.period_integral = float(self._cum[-1])

    def __call__(self, theta: Any) -> np.ndarray:
        return np.interp(theta, self.x, self.y, period=TWO_PI)

    def integral(self, theta: Any) -> np.ndarray:
        """Exact antiderivative F(theta) = integral from x[0] to theta (any real theta)."""
        t = np.asarray(theta, dtype=float)
        x0 = self._xs[0]
        turns = np.floor((t - x0) / TWO_PI)
        u = t - turns * TWO_PI
        k = np.clip(np.searchsorted(self._xs, u, side="right") - 1, 0, self._xs.size - 2)
        dx = u - self._xs[k]
        slope = (self._ys[k + 1] - self._ys[k]) / (self._xs[k + 1] - self._xs[k])
        return turns * self.period_integral + self._cum[k] + self._ys[k] * dx + 0.5 * slope * dx**2

    def interval_means(self, theta_edges: Any) -> np.ndarray:
        e = _edges(theta_edges)
        return np.diff(self.integral(e)) / np.diff(e)


@dataclass(frozen=True, eq=False)
class TablePressure(PressureSource):
    """Pressures from a table of one revolution, interpolated linearly and periodically.

    ``theta_deg`` as in the file; ``pa``, ``pb`` already converted to Pa.
    """

    theta_deg: np.ndarray
    pa: np.ndarray
    pb: np.ndarray
    file: str = ""
    unit: str = "Pa"
    kind: ClassVar[str] = "table"
    _a: PeriodicLinear = field(init=False, repr=False)
    _b: PeriodicLinear = field(init=False, repr=False)

    def __post_init__(self) -> None:
        theta = np.radians(np.asarray(self.theta_deg, dtype=float))
        object.__setattr__(self, "_a", PeriodicLinear(theta, self.pa))
        object.__setattr__(self, "_b", PeriodicLinear(theta, self.pb))

    def Pa(self, theta: Any) -> np.ndarray:
        return self._a(theta)

    def Pb(self, theta: Any) -> np.ndarray:
        return self._b(theta)

    def interval_means(self, theta_edges: Any) -> tuple[np.ndarray, np.ndarray]:
        """Exact means of the piecewise-linear table over each interval."""
        return self._a.interval_means(theta_edges), self._b.interval_means(theta_edges)

    def rows_per_revolution(self) -> int:
        """The table's rows (one revolution)."""
        return int(self._a.x.size)

    def angles_in_radians(self) -> str | None:
        """Why the table's angles look written in radians (spanning no more than 2 pi = 6.283, read as degrees:
        the whole cycle squeezed into the first 6.3 deg of the revolution, a linear ramp back over the rest), or
        None. A table of one revolution spans most of it; none of engineering practice holds only 6 degrees."""
        theta = np.asarray(self.theta_deg, dtype=float)
        if theta.size < 2 or theta.max() - theta.min() > RADIANS_SPAN:
            return None
        return (f"the table's angles span {theta.min():.4g}..{theta.max():.4g} deg, no more than 2 pi = 6.283 of "
                f"them: {HEADER[0]} is in degrees, and a table of one revolution spans most of its 360 deg; were they "
                "written in radians (multiply them by 180/pi)?")

    def data_sha256(self) -> str:
        """Hash of the numbers (angles in deg, pressures in Pa), independent of the file's spelling."""
        h = hashlib.sha256()
        for arr in (self.theta_deg, self.pa, self.pb):
            h.update(np.ascontiguousarray(arr, dtype="<f8").tobytes())
        return h.hexdigest()

    def to_dict(self) -> dict[str, Any]:
        return {
            "source": self.kind,
            "file": self.file,
            "unit": self.unit,
            "rows": int(self.theta_deg.size),
            "data_sha256": self.data_sha256(),
        }


# ---------------------------------------------------------------------------
# reading tables


def parse_table(text: str, *, file: str, factor: float = 1.0, unit: str = "Pa") -> TablePressure:
    """Read a pressure table from CSV text; every problem becomes a :class:`SceneError` line.

    ``factor`` converts the file's pressures (in ``unit``) to Pa. Checks: the
    header ``theta_deg,Pa,Pb``; three numbers a row; finite values; no negative
    absolute pressure; angles strictly increasing (no duplicates) within one
    revolution, [0, 360) or [-180, 180); at least 2 rows.
    """
    key = "pressure.file"
    problems: list[Problem] = []

    def bad(message: str) -> None:
        problems.append(Problem(key, file, message))

    rows: list[tuple[int, float, float, float]] = []
    header_seen = False
    for lineno, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        cells = [c.strip() for c in stripped.split(",")]
        if not header_seen:
            header_seen = True
            if tuple(cells) != HEADER:
                bad(f"{file} line {lineno}: expected the header 'theta_deg,Pa,Pb', got '{excerpt(stripped)}'")
                break
            continue
        if len(cells) != 3:
            n = len(cells)
            bad(f"{file} line {lineno}: expected 3 comma-separated numbers (theta_deg,Pa,Pb), got {n}")
            continue
        try:
            t, a, b = (float(c) for c in cells)
        except ValueError:
            bad(f"{file} line {lineno}: '{excerpt(stripped)}' is not three numbers")
            continue
        ok = True
        for name, v in zip(HEADER, (t, a, b), strict=True):
            if not math.isfinite(v):
                bad(f"{file} line {lineno}: {name} = {v} is not a finite number")
                ok = False
            elif name != "theta_deg" and v < 0:
                what = f"{name} = {v:g} {unit} is a negative absolute pressure"
                bad(f"{file} line {lineno}: {what}; allowed: >= 0")
                ok = False
        if ok:
            if rows and not t > rows[-1][1]:
                prev_line, prev_t = rows[-1][0], rows[-1][1]
                what = "repeats" if t == prev_t else "is below"
                bad(
                    f"{file} line {lineno}: theta_deg = {t:g} {what} the previous angle {prev_t:g} (line "
                    f"{prev_line}); allowed: strictly increasing angles"
                )
            rows.append((lineno, t, a, b))
    if not header_seen and not problems:
        bad(f"{file}: empty; expected the header 'theta_deg,Pa,Pb' and at least 2 rows")
    elif header_seen and len(rows) < 2 and not problems:
        bad(f"{file}: {len(rows)} data row{'s' if len(rows) != 1 else ''}; allowed: at least 2 rows")
    if rows and not problems:
        lo, hi = rows[0][1], rows[-1][1]
        if not ((0 <= lo and hi < 360) or (-180 <= lo and hi < 180)):
            bad(
                f"{file}: angles span [{lo:g}, {hi:g}] deg (lines {rows[0][0]}-{rows[-1][0]}); allowed: one "
                "revolution, all angles in [0, 360) or all in [-180, 180)"
            )
    if problems:
        if len(problems) > MAX_ROW_PROBLEMS:
            extra = len(problems) - MAX_ROW_PROBLEMS
            problems = problems[:MAX_ROW_PROBLEMS] + [Problem(key, file, f"... and {extra} more problems")]
        raise SceneError(problems, source=file)
    data = np.array([r[1:] for r in rows], dtype=float)
    return TablePressure(data[:, 0], data[:, 1] * factor, data[:, 2] * factor, file=file, unit=unit)


def load_table(file: str, base_dir: Any, unit: str = "Pa") -> TablePressure:
    """Read the table ``file`` (relative to ``base_dir``, a path or an importlib resource folder).

    Only a regular file of at most :data:`MAX_TABLE_BYTES` is read (a device or a pipe could be endless, a file
    of the proc file system reports size 0 and holds what the process knows); UTF-8 with or without a byte-order
    mark, LF or CRLF line ends.
    """
    factor = parse_pressure_unit(unit)
    target = Path(file) if Path(file).is_absolute() else base_dir.joinpath(file)

    def refuse(message: str) -> SceneError:
        return SceneError([("pressure.file", file, message)], source=file)

    try:
        if isinstance(target, Path):
            info = os.stat(target)
            if not stat.S_ISREG(info.st_mode):
                raise refuse(f"cannot read {target}: not a regular file (a folder, device or pipe); allowed: a CSV file")
            if info.st_size > MAX_TABLE_BYTES:
                raise refuse(f"{target} is {info.st_size / 2**20:.1f} MB; allowed: at most "
                             f"{MAX_TABLE_BYTES // 2**20} MB (a table of one revolution)")
            with open(target, "rb") as fh:
                data = fh.read(MAX_TABLE_BYTES + 1)
            if info.st_size == 0 and data:
                raise refuse(f"{target} reports size 0 but has content (a file of a virtual file system); "
                             "allowed: a CSV file on disk")
        else:
            data = target.read_bytes()
    except FileNotFoundError:
        relative = "" if Path(file).is_absolute() else " (a relative path is taken from the scene file's folder)"
        raise refuse(f"file not found: {target}{relative}") from None
    except OSError as exc:
        raise refuse(f"cannot read {target}: {exc.strerror or exc}") from None
    if len(data) > MAX_TABLE_BYTES:
        raise refuse(f"{target} is larger than {MAX_TABLE_BYTES // 2**20} MB; allowed: a table of one revolution")
    if b"\0" in data:
        raise refuse(f"{target} is a binary file (it contains NUL bytes); allowed: a CSV text file")
    try:
        text = data.decode("utf-8-sig")  # a byte-order mark (spreadsheet exports) is accepted
    except UnicodeDecodeError as exc:
        raise refuse(f"cannot read {target}: not UTF-8 text (byte {exc.start}: {data[exc.start:exc.start + 1]!r})") \
            from None
    return _parsed(text, file, factor, unit)


@functools.lru_cache(maxsize=8)
def _parsed(text: str, file: str, factor: float, unit: str) -> TablePressure:
    """:func:`parse_table`, once per process for the same text: every point of a sweep reads its scene's table
    again (4.5 ms for the default scene's 720 rows). The table is shared, so its arrays are made read-only."""
    table = parse_table(text, file=file, factor=factor, unit=unit)
    for values in (table.theta_deg, table.pa, table.pb):
        values.flags.writeable = False
    return table


def make_source(section: Any, base_dir: Any, *, read: bool = True) -> PressureSource:
    """The pressure source of a validated ``[pressure]`` section (see :mod:`.schema`); ``read``: whether a law reads
    the pressures (the chamber_pressure effect is on). A table that no law reads is not loaded (:class:`UnreadTable`):
    its file need not exist."""
    from .schema import GAS_SOURCES

    if section.source == "constant":
        return ConstantPressure(section.Pa, section.Pb)
    if section.source == "table" and not read:
        return UnreadTable(file=section.file, unit=section.unit, base_dir=base_dir)
    if section.source == "table":
        return load_table(section.file, base_dir, section.unit)
    if section.source in GAS_SOURCES:
        return GasModelPressure(source=section.source)
    return NoPressure()
