"""The checks of a submodel's own declarations when it is registered: its parameters, guards and switch.

Each check returns what is wrong, in words that name the parameter (or the switch), the value and what is allowed;
:func:`~.registry.register` refuses the submodel with them, naming it. A mistake that was accepted silently (a
default outside its own range, two parameters on one scene key) or failed far from its cause (a scene key without
a section: an IndexError on every command) is refused here, where the submodel is declared.

This module imports neither sympy nor the runtime, nor pint: what pint reads of a declared unit is checked when the
scene's tables are built from the registry (runtime/scenes/declared_units.py).
"""

from __future__ import annotations

import math

from ..parameters import Parameter

#: the scene sections whose keys are no parameter's: the option tables, and the sections of fixed keys (their
#: keys are the scene schema's own: runtime/scenes/schema.py; a parameter there would never be read)
RESERVED_SECTIONS = ("effects", "assumptions", "operation", "pressure", "solver")
#: the keys of a parameter section that are not a parameter's (runtime/scenes/schema.py, _EXTRA_FIELDS)
RESERVED_KEYS = ("machine.embodiment", "machine.ports")


def parameter_problems(cls) -> list[str]:
    """What is wrong with the parameters submodel ``cls`` declares (each in words); their units as pint reads them
    are checked by the scene layer (runtime/scenes/declared_units.py), which the derivation does not import."""
    out = [why for p in cls.parameters for why in _parameter_problems(p)]
    seen: dict[str, str] = {}
    for p in cls.parameters:
        if p.key is not None and p.key in seen:
            out.append(f"parameters {seen[p.key]!r} and {p.name!r} have the same scene key {p.key!r} (one key, one "
                       "parameter: give each its own)")
        elif p.key is not None:
            seen[p.key] = p.name
    return out


def _parameter_problems(p: Parameter) -> list[str]:
    name = f"parameter {p.name!r}"
    out = []
    if not isinstance(p.name, str) or not p.name.isidentifier():
        out.append(f"{name}: its name is not an identifier (letters, digits and underscores, not starting with a "
                   "digit: it names the symbol ctx.P[...] and the generated code's slot)")
    out += _key_problems(p, name)
    out += _range_problems(p, name)
    if not isinstance(p.unit, str) or not p.unit.strip():
        out.append(f"{name}: unit={p.unit!r} is empty (its SI unit in pint's syntax, e.g. \"N/m\"; \"1\" for a "
                   "plain number)")
    return out


def _key_problems(p: Parameter, name: str) -> list[str]:
    if p.key is None:
        return []
    section, dot, leaf = p.key.partition(".") if isinstance(p.key, str) else ("", "", "")
    if not dot or not section or not leaf or not all(part.isidentifier() for part in p.key.split(".")):
        return [f"{name}: key={p.key!r} is not a scene key \"section.name\" (e.g. \"contacts.{p.name}\": the "
                "table of the scene it is written in, a dot, its name there)"]
    if section in RESERVED_SECTIONS:
        return [f"{name}: key={p.key!r} is in the scene's [{section}] table, whose keys are not parameters "
                f"({', '.join(f'[{s}]' for s in RESERVED_SECTIONS)} are the scene's own; an effect is switched "
                "by an Option); use a section of parameters, e.g. \"contacts\""]
    if p.key in RESERVED_KEYS:
        return [f"{name}: key={p.key!r} is a scene key that is not a parameter's ({', '.join(RESERVED_KEYS)})"]
    return []


def _range_problems(p: Parameter, name: str) -> list[str]:
    out = []
    for bound, value in p.range_kwargs().items():
        if isinstance(value, bool) or not isinstance(value, int | float) or math.isnan(value):
            out.append(f"{name}: {bound}={value!r} is not a number")
    if out:
        return out
    lows = [(k, v) for k, v in (("gt", p.gt), ("ge", p.ge)) if v is not None]
    highs = [(k, v) for k, v in (("lt", p.lt), ("le", p.le)) if v is not None]
    empty = [(lo, hi) for lo in lows for hi in highs
             if not (lo[1] < hi[1] or (lo[1] == hi[1] and (lo[0], hi[0]) == ("ge", "le")))]
    if empty:
        (lk, lv), (hk, hv) = empty[0]
        out.append(f"{name}: its range {lk}={lv!r}, {hk}={hv!r} holds no value (the lower bound must be below the "
                   "upper one)")
    if p.default is not None and not out:
        d = p.default
        if isinstance(d, bool) or not isinstance(d, int | float) or not math.isfinite(d):
            out.append(f"{name}: default={d!r} is not a finite number")
        else:
            broken = [f"{k}={v!r}" for k, v in p.range_kwargs().items()
                      if not {"gt": d > v, "ge": d >= v, "lt": d < v, "le": d <= v}[k]]
            if broken:
                out.append(f"{name}: default={d!r} is outside its own range ({', '.join(broken)})")
    if p.plausible is not None:
        out += _plausible_problems(p, name)
    return out


def _plausible_problems(p: Parameter, name: str) -> list[str]:
    shape = isinstance(p.plausible, tuple) and len(p.plausible) == 3
    if not shape or not all(isinstance(x, int | float) and not isinstance(x, bool) for x in p.plausible[:2]) \
            or not isinstance(p.plausible[2], str):
        return [f"{name}: plausible={p.plausible!r} is not (SI low, SI high, unit shown), e.g. (1e3, 1e9, \"N/m\")"]
    low, high, _ = p.plausible
    if not low <= high:
        return [f"{name}: plausible={p.plausible!r} has its low end {low!r} above its high end {high!r} (SI low "
                "first, then SI high)"]
    return []


def guard_problems(cls, others) -> list[str]:
    """What is wrong with the guards submodel ``cls`` declares, given the guards ``others`` of the registered
    submodels: an output that is not a name, or another guard's; an activation that is not a name, or another
    guard's (the two contacts would open and close as one); a sign other than +1 or -1; a mode label another
    guard's labels or a groove case of Algorithm 3 (q1, ..., p2) take, or with an underscore (a mode's label joins
    the parts with underscores: the housing's open label h0 is how a run finds the tip off the housing)."""
    from ..groove_cases import CASES, GROOVE_GUARDS

    out: list[str] = []
    taken_outputs = {g.output: g.name for g in others}
    taken_activations = {g.activation: g.name for g in others}
    taken_labels = {lab: g.name for g in others if g.name not in GROOVE_GUARDS for lab in g.labels}
    taken_labels |= {case: "the groove's cases (Algorithm 3)" for case in CASES}
    for g in cls.guards:
        name = f"guard {g.name!r}"
        for field, value, taken in (("output", g.output, taken_outputs), ("activation", g.activation,
                                                                            taken_activations)):
            if not isinstance(value, str) or not value.isidentifier():
                out.append(f"{name}: {field}={value!r} is not a name (letters, digits and underscores: the "
                           + ("result's column of its gap or penetration)" if field == "output" else
                              "symbol that is 1 while the contact is closed, e.g. \"s_\" + the guard's name)"))
            elif value in taken:
                out.append(f"{name}: {field}={value!r} is already that of guard {taken[value]!r} (give each guard "
                           "its own)")
            else:
                taken[value] = g.name
        if isinstance(g.sign, bool) or g.sign not in (1, -1):
            out.append(f"{name}: sign={g.sign!r} is not 1 or -1 (+1: its output is the gap, the guard itself; -1: "
                       "a penetration or compression, minus the guard)")
        for label in dict.fromkeys(g.labels):
            if not isinstance(label, str) or "_" in label:
                out.append(f"{name}: the mode label {label!r} is not a word without underscores (closed_label, "
                           "open_label: a mode's label joins its parts with underscores)")
            elif label in taken_labels:
                owner = taken_labels[label]
                out.append(f"{name}: the mode label {label!r} is already one of "
                           + (owner if owner.startswith("the ") else f"guard {owner!r}") + " (its modes would read as "
                           "another contact's: give it a closed_label and an open_label of its own)")
            else:
                taken_labels[label] = g.name
    return out


def reference_problems(cls, known) -> list[str]:
    """The names in the ``oscillators``, ``dampers`` and ``damping_ratios`` of submodel ``cls`` that are none of
    the parameters ``known`` (the registered ones and its own): a misspelt one failed only when a scene was run,
    far from its cause."""
    from ...suggest import did_you_mean

    named = [("oscillators", n) for pair in cls.oscillators for n in pair]
    named += [("dampers", n) for n in cls.dampers] + [("damping_ratios", n) for pair in cls.damping_ratios for n in pair]
    return [f"{field} names {n!r}, which is no parameter{did_you_mean(n, known)} (a parameter it or a registered "
            "submodel declares, by name)" for field, n in named if n not in known]


def switch_problem(cls, slots: dict) -> str | None:
    """What is wrong with the ``switch`` of submodel ``cls`` given the option slots ``slots`` (name -> Option: the
    registered ones and its own), or None."""
    if cls.switch is None:
        return None
    from ...suggest import not_known

    effects = [n for n, o in slots.items() if o.table == "effects"]
    if cls.switch in effects:
        return None
    return (not_known(f"switch={cls.switch!r}", cls.switch, effects, "an effect (an Option of the table "
                      "\"effects\" that it or a registered submodel declares)", listing="effects")
            + " (declare options = (Option(name, (NONE, ON), meaning),) and switch = name)")


def contact_problem(cls, contact: str) -> str | None:
    """What is wrong with a contact named ``contact`` that submodel ``cls``'s laws return, or None."""
    own = tuple(cls.contact_names) or (cls.name,)
    if contact in own:
        return None
    return (f"returned ContactModel({contact!r}), a contact it does not declare (its contacts: {', '.join(own)}; "
            "declare contact_names = (...) and contact_meanings for each)")
