"""The one table of what every column of a result means: unit, long name, and the unit shown to a reader.

Every writer of results takes units and meanings from here: the CSV header (``x [m]``), the attributes of
:meth:`SimulationResult.to_xarray`, the columns of :meth:`SimulationResult.to_pandas` and ``docs/outputs.md``
(:func:`markdown_table`, checked by the tests). Quantities are stored in SI; ``display`` is the unit the
summary and the figures use (the seal moves by micrometres and milliradians).
"""

from __future__ import annotations

import re
from dataclasses import dataclass


def guard_outputs() -> dict[str, tuple[str, str]]:
    """Output column of each contact's guard -> (guard name, meaning), as the submodels declare them."""
    from ...derive.submodels.registry import guards

    out = {}
    for g in guards():
        meaning = g.meaning.removeprefix("minus ").removeprefix("the ")
        text = f"{meaning}; positive: in contact" if g.sign < 0 else f"{meaning}; negative: in contact"
        out[g.output] = (g.name, text)
    return out


@dataclass(frozen=True)
class Column:
    """One quantity of a result: its name, SI unit, meaning, and the unit figures and summaries show it in."""

    name: str
    unit: str
    meaning: str
    display: str = ""
    scale: float = 1.0  # display value = scale * SI value

    @property
    def header(self) -> str:
        """The CSV header cell, e.g. ``x [m]``; a plain number or a label has no bracket."""
        return f"{self.name} [{self.unit}]" if self.unit not in ("", "1") else self.name

    @property
    def label(self) -> str:
        """An axis label in the display unit, e.g. ``x (µm)``."""
        unit = self.display or self.unit
        return f"{self.name} ({unit})" if unit not in ("", "1") else self.name


#: fixed columns, in the order of the CSV
FIXED: dict[str, Column] = {c.name: c for c in (
    Column("theta_deg", "deg", "crank angle since the scene's start angle (θ, Section 2, Fig. 1)"),
    Column("time_s", "s", "time since the start of the run"),
    Column("x", "m", "seal displacement along the groove axis X (groove frame, Eq. 10)", "µm", 1e6),
    Column("y", "m", "seal displacement across the groove, along Y (groove frame, Eq. 10)", "µm", 1e6),
    Column("phi", "rad", "seal tilt angle in the groove (Eq. 11)", "mrad", 1e3),
    Column("xd", "m/s", "time derivative of x", "mm/s", 1e3),
    Column("yd", "m/s", "time derivative of y", "mm/s", 1e3),
    Column("phid", "rad/s", "time derivative of phi"),
    Column("mode", "", "contact mode: case of Algorithm 3, then h (housing) and s (spring) when closed"),
)}

_PATTERNS: tuple[tuple[str, str, str, str, float], ...] = (
    # regex, unit, meaning template ({c}: contact meaning, {g}: guard meaning), display unit, scale
    (r"F_(\w+)_X", "N", "X force on the seal (groove frame) from the {c}", "N", 1.0),
    (r"F_(\w+)_Y", "N", "Y force on the seal (groove frame) from the {c}", "N", 1.0),
    (r"M_(\w+)", "N*m", "moment about the seal's centre of gravity from the {c}", "N*mm", 1e3),
    (r"Pf_total", "W", "friction power of all contacts", "W", 1.0),
    (r"Pf_(\w+)", "W", "friction power dissipated at the {c}", "W", 1.0),
    (r"v_(\w+)", "m/s", "sliding velocity of the seal on the wall (signed, also while open; the wear numbers of "
                         "summary.json read it) at the {c}", "m/s", 1.0),
    (r"closed_(\w+)", "", "1 if contact {n} is closed at this sample, else 0 (Algorithm 3)", "", 1.0),
    (r"b_gap", "m", "leakage gap past the seal (Algorithm 4)", "µm", 1e6),
    (r"Pa", "Pa", "pressure of chamber a, +Ys side of the seal (Eq. 75)", "bar", 1e-5),
    (r"Pb", "Pa", "pressure of chamber b, -Ys side of the seal (Eq. 75)", "bar", 1e-5),
)


def describe(name: str) -> Column:
    """The :class:`Column` of a result column name (states, outputs, ``closed_<guard>``)."""
    if name in FIXED:
        return FIXED[name]
    guard_cols = guard_outputs()
    if name in guard_cols:
        display, scale = ("mm", 1e3) if name == "spring_compression" else ("µm", 1e6)
        return Column(name, "m", guard_cols[name][1], display, scale)
    from ...derive.submodels.registry import contacts, extended, parameters, submodels

    for pattern, unit, meaning, display, scale in _PATTERNS:
        m = re.fullmatch(pattern, name)
        if m:
            part = m.group(1) if m.groups() else ""
            text = meaning.format(c=contacts().get(part, part), n=part)
            return Column(name, unit, text, display, scale)

    for cls in submodels():  # a submodel's own states (the seal's are FIXED) and named outputs
        for st in cls.states:
            if st.name == name and name not in FIXED:
                return Column(name, st.unit, f"{st.meaning} ({cls.name} model state)", st.display, st.display_scale)
        for column, unit, meaning, *shown in cls.output_columns:
            if column == name:
                return Column(name, unit, meaning, *shown)
    for p in parameters(all_inputs=True):  # a parameter a scene schedules along the revolution (delta_s)
        if p.schedulable and p.name == name:
            from ..scenes.units import show_factor

            shown = p.show or (p.plausible[2] if p.plausible else p.unit)
            return Column(name, p.unit, f"{p.meaning} along the revolution, where the scene schedules it "
                                        f"([{p.section}.schedule])", shown, show_factor(p.unit, shown))
    if extended():  # a user's submodel may output what it does not declare: the run's files still hold it
        return Column(name, "", "an output of a user's submodel that declares no unit for it (Submodel.output_columns)")
    raise KeyError(f"no description of the result column {name!r}; add it to runtime/results/outputs.py")


def header(names: list[str] | tuple[str, ...]) -> list[str]:
    """CSV header cells with units, e.g. ``["theta_deg [deg]", "x [m]", ..., "mode"]``."""
    return [describe(n).header for n in names]


def documented_names() -> list[str]:
    """Every column of a result of the full model (the default scene), in CSV order: the states, the mode, the
    closed flag of each guard, the outputs of the committed generated model (generated/default/manifest.json),
    the guards' gap columns and the chamber pressures."""
    import json

    from ...derive.submodels.registry import guards
    from ...generated.load import DEFAULT_DIR

    names = json.loads((DEFAULT_DIR / "manifest.json").read_text())["names"]
    gs = {g.name: g for g in guards()}
    return [*FIXED, *(f"closed_{g}" for g in names["guards"]), *names["outputs"],
            *(gs[g].output for g in names["guards"]), "Pa", "Pb"]


def markdown_table() -> str:
    """The table of docs/outputs.md: column, unit, shown in, meaning."""
    rows = ["| column | unit (stored, SI) | shown in | meaning |", "|---|---|---|---|"]
    for n in documented_names():
        c = describe(n)
        rows.append(f"| `{c.header}` | {c.unit or '-'} | {c.display or c.unit or '-'} | {c.meaning} |")
    return "\n".join(rows) + "\n"
