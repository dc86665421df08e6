"""The units a user's or a package's submodel declares, as pint reads them, checked when the scene's tables are built
from the registry (:func:`.schema.sections`): the registry (derive/) checks the rest of a declaration at
registration and imports neither the runtime nor pint. A unit pint does not read, or reads as no SI unit ("Nm" is
pint's number_meter), or a unit of ``show=``/``bare=``/``plausible=`` that does not convert to it, is a
:class:`~apexseal.derive.submodels.registry.RegistryError` naming the submodel, before any scene is read. What pint
accepted is remembered (:mod:`.unit_memo`), so a warm process imports no pint; the built-in submodels are checked by
the tests.
"""

from __future__ import annotations

from ...derive.parameters import Parameter
from .units import declared_unit_problem


def unit_problems(p: Parameter) -> list[str]:
    """What pint finds wrong with parameter ``p``'s unit and the units it is shown in (each in words)."""
    name = f"parameter {p.name!r}"
    why = declared_unit_problem(p.unit)
    if why is not None:
        return [f"{name}: unit={p.unit!r} {why}"]
    shown = {"show": p.show, "bare": p.bare, "plausible": p.plausible[2] if p.plausible else None}
    out = []
    for field, unit in shown.items():
        why = declared_unit_problem(p.unit, unit) if unit is not None and unit != p.unit else None
        if why is not None:
            out.append(f"{name}: {field}={unit!r} {why}" if field != "plausible" else
                       f"{name}: the unit {unit!r} of plausible={p.plausible!r} {why}")
    return out


def check_declared_units(classes) -> None:
    """Raise the RegistryError of the first submodel of ``classes`` (not built in) whose units pint finds wrong."""
    from ...derive.submodels.registry import RegistryError, built_in, origin

    for cls in classes:
        if built_in(cls):
            continue
        problems = [why for p in cls.parameters for why in unit_problems(p)]
        if problems:
            raise RegistryError(f"submodel {cls.name!r} ({origin(cls)}): " + "; ".join(problems))
