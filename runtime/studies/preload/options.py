"""The preload study's options as ``optimise_preload`` (study.py) and ``apexseal optimise-preload`` both take them:
one declaration of their defaults, in the study's units (N, m), and of the objectives; their ranges are checked by
one function, :func:`.study.check_option`, for both. Light (no CasADi), so that the command line declares its
options from it."""

from __future__ import annotations

import math

#: what the study minimises: the cycle-mean friction power, or the mean preload
OBJECTIVES = ("friction", "preload")
#: the defaults of the study's options (min_force in N, max_preload in m)
DEFAULTS = {"min_force": 5.0, "max_preload": 0.1, "max_iter": 100, "nodes": 4, "objective": "friction",
            "deficit_tol": 0.2**2 * math.radians(0.1)}
#: the unit of each quantity option, as its value is given without one
UNITS = {"min_force": "N", "max_groove_force": "N", "max_preload": "m"}


def default_text(name: str) -> str:
    """An option's default as the command line shows it, e.g. "5 N", "100 mm"."""
    value = DEFAULTS[name]
    if name == "max_preload":
        return f"{value * 1e3:g} mm"
    return f"{value:g} {UNITS[name]}" if name in UNITS else str(value)
