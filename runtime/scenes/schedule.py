"""Parameters that follow the crank angle: a scene's ``[<section>.schedule]`` tables.

A parameter its submodel declares ``schedulable`` (the spring's preload delta_s, Eq. 39) may be given as a
schedule instead of one value::

    [spring.schedule]
    angles = ["0 deg", "90 deg", "180 deg", "270 deg"]   # crank angle theta of each knot, increasing
    delta_s = ["1.5 mm", "2.6 mm", "2.0 mm", "1.2 mm"]   # its value at each knot

The schedule is periodic in theta (one revolution) and linear between knots, after the last knot back to the
first one: the active preload the preload study designs (runtime/studies/preload/schedule.py). The parameters
derived from it move with it (delta_w of Eq. 9 and Li of Eq. 12 follow delta_s through the submodels' own
formulas, ``Scene.parameter_function``). The run evaluates the whole parameter vector at the edges of its output
intervals and the event-locating engines integrate it linear between them (generated/hybrid.py), which is the
schedule exactly wherever its knots lie on output edges. ``scene.parameters`` holds the values at the start angle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .errors import MISSING, Problem
from .schema import raw_at

TWO_PI = 2 * math.pi


def periodic_line(angles, values, theta, period: float = TWO_PI) -> np.ndarray:
    """The periodic, piecewise-linear function through ``values`` at ``angles`` (increasing, spanning less than
    one ``period``: rad by default, 360 for degrees), at ``theta``: after the last knot it runs back to the first
    one a period later. One knot: that value everywhere."""
    values = np.asarray(values, float)
    if values.size == 1:
        return np.full(np.shape(theta), values[0])
    a = np.r_[angles, angles[0] + period]
    x = (np.asarray(theta, float) - angles[0]) % period + angles[0]
    return np.interp(x, a, np.r_[values, values[0]])


@dataclass(frozen=True)
class Schedule:
    """The knots (rad, increasing) and each scheduled parameter's values there (by parameter name, SI)."""

    angles: tuple[float, ...]
    values: dict[str, tuple[float, ...]]

    def __call__(self, name: str, theta) -> np.ndarray:
        """Parameter ``name`` at crank angles ``theta`` (rad, absolute)."""
        return periodic_line(np.asarray(self.angles), np.asarray(self.values[name]), theta)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.values)


class ParameterPath:
    """The parameter vector along a schedule: ``path(theta) -> (n_par, m)`` at crank angles ``theta`` (rad,
    absolute), in the order of ``order`` (the model's parameter names), each scheduled parameter at its schedule's
    value and those derived from it following through ``function`` (``Scene.parameter_function`` of the scheduled
    names). ``names``: the scheduled parameters."""

    def __init__(self, schedule: Schedule, function, all_names, order):
        import casadi as ca

        self.schedule, self.names = schedule, schedule.names
        rows = [tuple(all_names).index(n) for n in order]
        # only the parameters that depend on the scheduled ones are evaluated along it (delta_s, delta_w, Li: a small
        # Function, where the whole vector's, the seal's geometry included, cost 15 ms at 3600 crank angles)
        x = [ca.SX.sym(n) for n in self.names]
        p = function(*x)
        moved = [i for i, r in enumerate(rows) if ca.depends_on(p[r], ca.vertcat(*x))]
        self.moved = np.array(moved, dtype=int)
        self.fixed = np.array(function(*(schedule(n, schedule.angles[0]) for n in self.names))).ravel()[rows]
        self.function = ca.Function("scheduled_parameters", x, [ca.vertcat(*(p[rows[i]] for i in moved))])
        self._maps: dict[int, object] = {}  # the function mapped over m crank angles, by m (a few sizes a run)

    def __call__(self, theta) -> np.ndarray:
        theta = np.atleast_1d(np.asarray(theta, float))
        m = theta.size
        if m not in self._maps:
            if len(self._maps) > 16:
                self._maps.clear()
            self._maps[m] = self.function.map(m)
        out = np.repeat(self.fixed[:, None], m, axis=1)
        out[self.moved] = np.array(self._maps[m](*(self.schedule(n, theta)[None, :] for n in self.names)))
        return out


def scheduled(sections: dict[str, Any]) -> Schedule | None:
    """The schedule of every ``[<section>.schedule]`` table of validated ``sections`` (None: none given)."""
    from apexseal.derive.submodels.registry import parameters

    angles, values = None, {}
    for p in parameters(all_inputs=True):
        table = _table(sections, p)
        if table is not None and getattr(table, p.leaf) is not None:
            angles = table.angles
            values[p.name] = getattr(table, p.leaf)
    return None if angles is None else Schedule(tuple(angles), values)


def value_at_start(sections: dict[str, Any], p) -> float | None:
    """A scheduled parameter's value at the scene's start angle (None: ``p`` is not scheduled)."""
    table = _table(sections, p)
    if table is None or getattr(table, p.leaf) is None or "operation" not in sections:
        return None
    values = getattr(table, p.leaf)
    if len(values) != len(table.angles):  # refused by schedule_problems; its first value stands in meanwhile
        return float(values[0])
    return float(periodic_line(table.angles, values, sections["operation"].start_angle))


def _table(sections: dict[str, Any], p):
    if not p.schedulable or p.section not in sections:
        return None
    return getattr(sections[p.section], "schedule", None)


def schedule_problems(sections: dict[str, Any], raw: dict[str, Any]) -> list[Problem]:
    """What is wrong with the schedules of valid ``sections``: knots not increasing or spanning a revolution or
    more, a parameter's values not one per knot, a table that schedules nothing, a parameter given both as one value
    and as a schedule."""
    from apexseal.derive.submodels.registry import parameters

    out: list[Problem] = []
    by_section: dict[str, list] = {}
    for p in parameters(all_inputs=True):
        if p.schedulable and p.key is not None:
            by_section.setdefault(p.section, []).append(p)
    for section, params in by_section.items():
        table = getattr(sections.get(section), "schedule", None)
        if table is None:
            continue
        key = f"{section}.schedule"
        a = np.asarray(table.angles)
        shown = raw_at(raw, [section, "schedule", "angles"])
        if np.any(np.diff(a) <= 0):
            out.append(Problem(f"{key}.angles", shown, "the knots' crank angles must increase strictly"))
        elif a[-1] - a[0] >= TWO_PI:
            out.append(Problem(f"{key}.angles", shown, f"the knots span {math.degrees(a[-1] - a[0]):.6g} deg: a "
                                                       "schedule is periodic, its knots lie within less than one "
                                                       "revolution (360 deg)"))
        given = [p for p in params if getattr(table, p.leaf) is not None]
        if not given:
            out.append(Problem(key, MISSING, f"schedules nothing; give the values at its knots of "
                                             f"{' or '.join(f'{key}.{p.leaf}' for p in params)}"))
        for p in given:
            n = len(getattr(table, p.leaf))
            if n != a.size:
                out.append(Problem(f"{key}.{p.leaf}", raw_at(raw, [section, "schedule", p.leaf]),
                                   f"{n} values for {a.size} knots ({key}.angles): give one value per knot"))
            alone = raw_at(raw, p.key.split("."))
            if alone is not MISSING:
                out.append(Problem(p.key, alone, f"given together with {key}.{p.leaf}, which states the "
                                                 f"{p.meaning} along the revolution; allowed: one of {p.key} or "
                                                 f"{key}.{p.leaf}"))
    return out
