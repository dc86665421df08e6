"""A light study for the sweep tests: 16 points of ks x delta_s, one coarse revolution each (~0.3 s a point)."""

from __future__ import annotations

LIGHT = """
[study]
name = "light"

[scene]
"operation.revolutions" = 1
"solver.samples_per_revolution" = 36
"solver.rtol" = 1e-4

[parameters."spring.ks"]
from = "3e3 N/m"
to = "2e4 N/m"
points = 4
scale = "log"

[parameters."spring.delta_s"]
values = ["1 mm", "2 mm", "3 mm", "4 mm"]

[collect]
quantities = ["friction_power.total", "friction_power.housing", "liftoff_fraction", "housing_force.max",
              "x.max_at", "gap.mean", "events.total", "revolutions"]

[run]
max_wall_time = "60 s"

[feasible]
liftoff_fraction = { max = 0 }
"friction_power.total" = { max = "35 W" }
"""

#: columns that differ between two runs of the same point (timing, which process)
VOLATILE = ["wall_time_s", "run_time_s", "worker"]


def light_study(**replace: str):
    """The light study, with lines replaced (``{"points = 4": "points = 2"}``)."""
    from apexseal.runtime.studies.sweep import study_from_toml

    text = LIGHT
    for old, new in replace.items():
        assert old in text, old
        text = text.replace(old, new)
    return study_from_toml(text, source="light.toml")


def stable(table):
    """A results table without its volatile columns (for comparing runs digit by digit)."""
    return table.drop(columns=VOLATILE).reset_index(drop=True)
