"""The ordered registry of submodels, and everything built from it.

The parameter vector (:func:`parameters`, :func:`parameter_names`), the option slots (:func:`options`), the
guards (:func:`guards`), the scene's parameter keys and the mode labels all come from here, in registration
order: the built-in submodels first (seal body, housing, spring, groove, chamber pressure), then those of
installed packages (the entry points of the group ``apexseal.submodels``, by name), then a user's.

>>> from apexseal.derive.submodels import registry
>>> registry.register(MyContact)          # a subclass of Submodel; see docs/extending.md
>>> registry.unregister("my_contact")     # e.g. at the end of a test

A package adds its submodels to every process (the command line, a sweep's workers) by declaring them::

    [project.entry-points."apexseal.submodels"]
    cushion = "my_seal_models.cushion:Cushion"

The content of the registry (the source of every registered class that is on and of the helper modules of its own
package that it imports, :mod:`.sources`) enters the derivation's cache key, so a new or changed submodel is never
served an old derivation, and one that is off changes no model's key (:func:`entering`).
"""

from __future__ import annotations

import hashlib
import importlib
from collections.abc import Iterator
from contextlib import contextmanager

from ...suggest import did_you_mean, not_known
from ..options import NONE, ON, Option, need_met, needed_effects, needed_on, resolve
from ..parameters import Parameter
from . import declarations
from .base import Friction, Guard, State, Submodel, built_in
from .sources import source_key

#: the built-in submodels, in registration order
BUILTIN = (".seal:SealBody", ".housing:HousingContact", ".groove:GrooveContacts", ".spring:SpringContact",
           ".pressure:ChamberPressure", ".gas:ChamberGas")

#: the entry-point group through which an installed package adds submodels
ENTRY_POINTS = "apexseal.submodels"

_registry: dict[str, type[Submodel]] = {}
_installed: dict[str, str] = {}  # submodel name -> "distribution version" of those added by entry points
_loaded = False
_broken: RegistryError | None = None


class RegistryError(ValueError):
    """A submodel whose declarations clash with those already registered, or an installed one that cannot load."""


def _ensure() -> None:
    global _loaded, _broken
    if _broken is not None:
        raise _broken
    if not _loaded:
        _loaded = True
        builtin = [getattr(importlib.import_module(m, __package__), n) for m, n in (s.split(":") for s in BUILTIN)]
        for cls in builtin:
            register(cls, check_needs=False)  # a built-in may need another's effect (v_eps: every friction law)
        for cls in builtin:
            _check_needs(cls)
        try:
            _load_installed()
        except RegistryError as exc:
            _broken = exc
            raise


def _load_installed() -> None:
    """Register the submodels installed packages declare as entry points of :data:`ENTRY_POINTS`, by name."""
    from importlib.metadata import entry_points

    for ep in sorted(entry_points(group=ENTRY_POINTS), key=lambda e: (e.name, e.value)):
        dist = f"{ep.dist.name} {ep.dist.version}" if ep.dist is not None else "an unknown distribution"
        where = f"the submodel entry point {ep.name} = {ep.value!r} of {dist}"
        try:
            cls = ep.load()
        except Exception as exc:  # noqa: BLE001 - whatever the package raises, name the package
            raise RegistryError(f"{where} cannot be loaded: {type(exc).__name__}: {exc}; uninstall the package "
                                "or fix it") from exc
        try:
            register(cls)
        except RegistryError as exc:
            raise RegistryError(f"{where}: {exc}") from None
        _installed[cls.name] = dist


@contextmanager
def laws_of(cls: type[Submodel], method: str):
    """Around a call of a submodel's laws (``contacts()``, ``rates()``, ...) while a model is derived: an error of
    a user's or an installed package's submodel names the submodel, its method and where it comes from (the
    package and its version, or its module), as a loading error does."""
    try:
        yield
    except Exception as exc:
        if built_in(cls):
            raise  # apexseal's own: a bug to report as it is
        raise RegistryError(f"the submodel {cls.name} ({origin(cls)}) failed in {method}: {type(exc).__name__}: "
                            f"{exc}; fix its code, or switch it off in the scene") from exc


def origin(cls: type[Submodel]) -> str:
    """Where submodel ``cls`` comes from, for messages: "installed by <package> <version>" or "from module <m>"."""
    return f"installed by {_installed[cls.name]}" if cls.name in _installed else f"from module {cls.__module__}"


def _check_declarations(cls: type[Submodel]) -> None:
    """Refuse a submodel whose own declarations are wrong (:mod:`.declarations`: its parameters' names, scene keys,
    ranges, defaults and units (present), its guards' outputs, activations, signs and mode labels, the parameters
    its oscillators, dampers and damping ratios name, its switch), naming it and each mistake. What pint reads of
    the units is checked by the scene layer when it builds its tables (runtime/scenes/declared_units.py)."""
    problems = declarations.parameter_problems(cls)
    problems += declarations.guard_problems(cls, [g for c in _registry.values() for g in c.guards])
    problems += declarations.reference_problems(cls, {p.name for c in (*_registry.values(), cls)
                                                      for p in c.parameters})
    slots = {o.name: o for c in (*_registry.values(), cls) for o in c.options}
    problems += [p for p in (declarations.switch_problem(cls, slots),) if p is not None]
    if problems:
        raise RegistryError(f"submodel {cls.name!r} ({origin(cls)}): " + "; ".join(problems))


def _check_needs(cls: type[Submodel]) -> None:
    """Refuse a parameter of ``cls`` whose ``needs`` names what is not an effect or a modelling choice of the
    registry or of ``cls``, or that a modelling choice reads and that has no default (a scene that makes the
    choice need not give it: only an effect's parameters may be required while it is on)."""
    slots = {o.name: o for c in (*_registry.values(), cls) for o in c.options}
    effects = {n for n, o in slots.items() if o.table == "effects"}
    choices = {f"{n}={c}" for n, o in slots.items() if o.table != "effects" for c in o.choices}
    unknown = [f"parameter {p.name!r}: needs={n!r}{did_you_mean(n, [*effects, *choices])}" for p in cls.parameters
               for n in needed_effects(p.needs) if n not in effects | choices]
    if unknown:
        raise RegistryError(f"submodel {cls.name!r} ({origin(cls)}) declares parameters that need what is not an "
                            f"effect: {'; '.join(unknown)} (needs names an effect, a switch of [effects], "
                            "or a choice of [assumptions] as \"slot=choice\")")
    undefaulted = sorted(p.name for p in cls.parameters if p.default is None and not p.optional
                         and any("=" in n for n in needed_effects(p.needs)))
    if undefaulted:
        raise RegistryError(f"submodel {cls.name!r} declares parameters that a modelling choice reads without a "
                            f"default: {', '.join(undefaulted)} (give each a default)")


def installed(opts=None) -> dict[str, str]:
    """The submodels added by installed packages: name -> "distribution version" (part of a run's provenance); with
    ``opts`` (a model's options) those that enter that model alone (:func:`entering`: on, or off with a choice of
    its own made, which its scene then records)."""
    _ensure()
    if opts is None:
        return dict(_installed)
    return {cls.name: _installed[cls.name] for cls in entering(opts) if cls.name in _installed}


def register(cls: type[Submodel], *, check_needs: bool = True) -> type[Submodel]:
    """Add a submodel (usable as a class decorator). Its parameters, options and guards must be new names.

    A class defined again where it was defined before (same module and name: a notebook cell run again, a script
    re-run with ``%run``) replaces its earlier definition, in place in the registration order."""
    _ensure()
    if not (isinstance(cls, type) and issubclass(cls, Submodel)) or not cls.name:
        raise RegistryError(f"{cls!r} is not a named subclass of apexseal's Submodel")
    old = _registry.get(cls.name)
    if old is not None and _redefinition(old, cls):
        return _replace(old, cls)
    if old is cls:
        raise RegistryError(f"the submodel {cls.name!r} ({cls.__module__}.{cls.__qualname__}) is registered already "
                            "(this very class: register it once; registry.registered(...) registers it for a block)")
    if old is not None:
        raise RegistryError(f"a submodel named {cls.name!r} is registered already (by {old.__module__}."
                            f"{old.__qualname__})")
    _check_declarations(cls)
    for what, declared in (("parameter", "parameters"), ("option", "options"), ("guard", "guards"),
                           ("state", "states")):
        owners = {d.name: c.name for c in submodels() for d in getattr(c, declared)}
        clash = sorted({d.name for d in getattr(cls, declared)} & set(owners))
        if clash:
            raise RegistryError(f"submodel {cls.name!r} declares {what}s that exist already: "
                                + ", ".join(f"{n} (the {owners[n]}'s)" for n in clash))
    keys = {p.key: (p.name, c.name) for c in submodels() for p in c.parameters if p.key is not None}
    taken = sorted(f"parameter {p.name!r}: key={p.key!r} is already that of parameter {keys[p.key][0]!r} of the "
                   f"{keys[p.key][1]}" for p in cls.parameters if p.key in keys)
    if taken:
        raise RegistryError(f"submodel {cls.name!r} ({origin(cls)}) declares scene keys that exist already: "
                            f"{'; '.join(taken)} (give each parameter a key of its own)")
    own = cls.contact_names or (cls.name,)
    strays = sorted({g.contact or cls.name for g in cls.guards} - set(own))
    if strays:
        raise RegistryError(f"submodel {cls.name!r} declares guards of contacts it does not declare: "
                            f"{', '.join(strays)} (its contacts: {', '.join(own)}; a guard names its contact "
                            "with contact=...)")
    loose = sorted({c for f in cls.frictions for c in f.contacts} - set(own))
    if loose:
        raise RegistryError(f"submodel {cls.name!r} declares friction laws on contacts it does not declare: "
                            f"{', '.join(loose)} (its contacts: {', '.join(own)})")
    mine = {p.name for p in cls.parameters}
    unknown = sorted({f.mu for f in cls.frictions} - mine)
    if unknown:
        raise RegistryError(f"submodel {cls.name!r} declares friction laws whose coefficient is none of its "
                            f"parameters: {', '.join(unknown)}")
    uneven = [f.mu for f in cls.frictions if f.offsets and len(f.offsets) != len(f.contacts)]
    if uneven:
        raise RegistryError(f"submodel {cls.name!r} declares friction laws ({', '.join(uneven)}) whose offsets are "
                            "not one per contact")
    known = set(options()) | {o.name for o in cls.options}
    if check_needs:
        _check_needs(cls)
    for o in cls.options:
        if o.parent is not None and o.parent not in known:
            raise RegistryError(f"option {o.name!r} of {cls.name!r} names an unknown parent {o.parent!r}")
        if o.parent is not None and o.table != "effects":
            raise RegistryError(f"option {o.name!r} of {cls.name!r} is a modelling choice ([{o.table}]) with a "
                                f"parent: only an effect has one (a choice applies whether its effect is on or not)")
    _registry[cls.name] = cls
    return cls


def _redefinition(old: type[Submodel], new: type[Submodel]) -> bool:
    """``new`` is ``old`` defined again: same module and name, and not one of the package's own."""
    return (old is not new and (old.__module__, old.__qualname__) == (new.__module__, new.__qualname__)
            and not old.__module__.startswith(__package__))


def _replace(old: type[Submodel], new: type[Submodel]) -> type[Submodel]:
    """Register ``new`` where ``old`` was (its declarations checked against the others'); ``old`` stays if not."""
    saved = dict(_registry)
    del _registry[old.name]
    try:
        register(new)
    except RegistryError:
        _registry.clear()
        _registry.update(saved)
        raise
    _registry.clear()
    _registry.update({n: new if n == old.name else c for n, c in saved.items()})
    return new


def extended(opts=None) -> bool:
    """True while a user's submodel is registered besides the built-in ones; with ``opts``, while one enters a
    model of those options (:func:`entering`: the committed default artefacts, generated from the built-in
    registry, are then not for that model; one that is off at its defaults leaves every model as it was)."""
    _ensure()
    return any(not built_in(cls) and (opts is None or not untouched(cls, opts)) for cls in _registry.values())


def entering(opts) -> tuple[type[Submodel], ...]:
    """The submodels a model of the options ``opts`` is derived from, as far as its cache keys go: the built-in
    ones (their sources are the derivation's own), and a user's or a package's unless it is off with every option
    of its own at its default (:func:`untouched`). Such a one is the model without it, so registering or
    installing it changes no model's key (:func:`digest`, :func:`apexseal.derive.cache.model_inputs`). One that is
    on, or off against its default, or with a choice of its own made, enters: its options are then recorded (a
    manifest reads its effects back from them) and a submodel that reads another's option gets its own key."""
    return tuple(cls for cls in submodels() if built_in(cls) or not untouched(cls, opts))


def untouched(cls: type[Submodel], opts) -> bool:
    """Submodel ``cls`` is off under ``opts`` and every option slot it declares has the value the default options
    give it (a child under a parent that is off: "none")."""
    defaults = resolve({}, options())
    return not cls.active(opts) and all(opts[o.name] == defaults[o.name] for o in cls.options)


def left_out_options(opts) -> frozenset[str]:
    """The option slots of the submodels that do not enter a model of ``opts`` (:func:`entering`): each at its
    default, so a record without them reads back as the same options."""
    entered = set(entering(opts))
    return frozenset(o.name for cls in submodels() if cls not in entered for o in cls.options)


def unregister(name: str) -> None:
    """Remove a user's submodel (built-in ones stay)."""
    _ensure()
    cls = _registry.get(name)
    if cls is not None and cls.__module__.startswith(__package__):
        raise RegistryError(f"{name!r} is a built-in submodel; switch it off with its option instead")
    _registry.pop(name, None)
    _installed.pop(name, None)


@contextmanager
def registered(*classes: type[Submodel]) -> Iterator[None]:
    """Register submodels for the duration of a ``with`` block."""
    for cls in classes:
        register(cls)
    try:
        yield
    finally:
        for cls in classes:
            unregister(cls.name)


def submodels() -> tuple[type[Submodel], ...]:
    _ensure()
    return tuple(_registry.values())


def contact_names(name: str) -> tuple[str, ...]:
    """The contacts submodel ``name`` declares (their output prefixes): its ``contact_names``, or its own name."""
    _ensure()
    if name not in _registry:
        raise RegistryError(f"no submodel named {name!r}; registered: {', '.join(_registry)}")
    cls = _registry[name]
    return tuple(cls.contact_names) or (cls.name,)


def parameters(*, all_inputs: bool = False, opts=None) -> tuple[Parameter, ...]:
    """The parameter vector of the model of the options ``opts`` (None: the default options), in order: the
    parameters of the submodels that are on whose effect (:func:`needing`) is on. What is off has no slot, so it
    never enters the generated C, not even as an index. ``all_inputs``: every declared parameter and scene input."""
    if all_inputs:
        return tuple(p for cls in submodels() for p in cls.parameters)
    if opts is None:
        opts = resolve({}, options())

    def read(cls, p) -> bool:
        return p.in_vector and cls.active(opts) and needed_on(_needing(cls, p), lambda n: need_met(n, opts, False))

    return tuple(p for cls in submodels() for p in cls.parameters if read(cls, p))


def parameter_names(*, all_inputs: bool = False, opts=None) -> tuple[str, ...]:
    """The names of the parameter vector of the generated Functions, in order (for the options ``opts``; None:
    the default options)."""
    return tuple(p.name for p in parameters(all_inputs=all_inputs, opts=opts))


def unmet(need) -> str:
    """What is off while a parameter whose :func:`needing` is ``need`` is not read, as a scene states it:
    "effects.spring is off", "effects.a and effects.b are off", "assumptions.damping_law is not 'penetration'",
    "pressure.source is neither 'chamber' nor 'chamber+leakage'" (a choice another key decides: its ``set_by``)."""
    entries = needed_effects(need)
    effects = [f"effects.{n}" for n in entries if "=" not in n]
    wanted: dict[str, list[str]] = {}
    for slot, _, choice in (n.partition("=") for n in entries if "=" in n):
        wanted.setdefault(slot, []).append(repr(choice))
    choices = [f"{choice_key(slot)} is not {ws[0]}" if len(ws) == 1 else
               f"{choice_key(slot)} is neither {', '.join(ws[:-1])} nor {ws[-1]}" for slot, ws in wanted.items()]
    said = ([f"{', '.join(effects[:-1])} and {effects[-1]} are off" if len(effects) > 1 else f"{effects[0]} is off"]
            if effects else [])
    return " and ".join(said + choices)


def choice_key(slot: str) -> str:
    """The scene key that makes a modelling choice: ``assumptions.<slot>``, or the key that decides it
    (``Option.set_by``: ``pressure.source`` for ``pressure_model``)."""
    o = options().get(slot)
    return o.set_by if o is not None and o.set_by else f"assumptions.{slot}"


def is_read(p: Parameter | str, effects, assumptions=None) -> bool:
    """Whether a law of a model with the effects ``effects`` (an :class:`~..effects.Effects`) and the modelling
    choices ``assumptions`` (an :class:`~..assumptions.Assumptions`; None: the defaults) reads parameter ``p`` (a
    :class:`Parameter`, its name or its scene key, e.g. ``"friction.mu2"``): always one that no effect or choice
    switches, else while an entry its :func:`needing` names holds (:func:`need_met`), inside its submodel (a
    ``needs`` of a parameter whose submodel is off does not hold). An effect that ``effects``
    does not name (its submodel registered after they were made) counts as on. The one answer of the scene's
    checks, a sweep's and a calibration's: what is not read is neither required, range-checked as an error,
    questioned nor varied."""
    q = p if isinstance(p, Parameter) else _declared(p)
    return need_holds(needing(q, effects, assumptions), effects, assumptions)


def need_holds(need: str | tuple[str, ...] | None, effects, assumptions=None) -> bool:
    """Whether ``need`` (a :func:`needing`: effects or "slot=choice" entries, None for always) holds for the
    effects ``effects`` and the modelling choices ``assumptions`` (None: the defaults); an effect that ``effects``
    does not name counts as on."""
    if assumptions is None:  # their defaults
        asked = slots("assumptions")
        chosen = {n: c for n, c in resolve({}, options()).items() if n in asked}
    else:
        chosen = assumptions.as_dict()
    choices = {**{n: ON if on else NONE for n, on in effects.as_dict().items()}, **chosen}
    return needed_on(need, lambda n: need_met(n, choices, True))


def scene_inputs() -> dict[str, str | tuple[str, ...] | None]:
    """The scene keys (or sections of keys) that submodels read besides their parameters' keys
    (``Submodel.scene_inputs``: the gas model's ports), each with what must hold for them to be read (the
    submodel's switch or the choices that bring it in, as :func:`needing` gives for its parameters)."""
    return {key: cls.switch if cls.switch is not None else (cls.enters_with or None)
            for cls in submodels() for key in cls.scene_inputs}


def _declared(name_or_key: str) -> Parameter:
    """The declared parameter of a scene key (``"contacts.kw"``) or a name (``"kw"``)."""
    return parameter(name_or_key) if "." not in name_or_key else parameter_of_key(name_or_key)


def parameter_of_key(key: str) -> Parameter:
    """The declared parameter whose scene key is ``key`` (``"contacts.kw"``); KeyError for a key that holds none."""
    for p in parameters(all_inputs=True):
        if p.key == key:
            return p
    raise KeyError(key)


def needing(p: Parameter, effects=None, assumptions=None) -> str | tuple[str, ...] | None:
    """The effect that must be on for ``p`` to be read: its ``needs``, else its submodel's switch, else the
    modelling choices that bring its submodel in (``Submodel.enters_with``); None for a parameter read whatever the
    effects and choices (the seal body's). A ``needs`` holds only inside its submodel: with ``effects`` (and the
    choices ``assumptions``, None: the defaults), where the ``needs`` holds but the submodel's own switch or
    choices do not (a package's parameter that needs a choice of its own, while the package's effect is off),
    those; else as without them."""
    for cls in submodels():
        if p in cls.parameters:
            if effects is not None and p.needs is not None and need_holds(p.needs, effects, assumptions):
                own = [e for e in (cls.switch, tuple(cls.enters_with) or None) if e is not None]
                unmet_own = next((e for e in own if not need_holds(e, effects, assumptions)), None)
                if unmet_own is not None:
                    return unmet_own
            return _needing(cls, p)
    raise KeyError(p.name)


def _needing(cls: type[Submodel], p: Parameter) -> str | tuple[str, ...] | None:
    """:func:`needing` of a parameter of submodel ``cls``."""
    if p.needs is not None:
        return p.needs
    return cls.switch if cls.switch is not None else (cls.enters_with or None)


def omissible_while_off(p: Parameter) -> str | tuple[str, ...] | None:
    """The effect while which is off a scene may leave ``p`` out: for a scene key without a default that an effect
    reads (:func:`needing`); None for any other parameter (required, defaulted, optional or derived)."""
    if p.key is None or p.default is not None or p.optional:
        return None
    return needing(p)


class UnknownParameter(KeyError):
    """A parameter name that no registered submodel declares (``ctx.P["Fx"]`` in a submodel's laws)."""

    def __str__(self) -> str:  # KeyError's own repr()s its argument; this one is a sentence
        return str(self.args[0])


def parameter(name: str) -> Parameter:
    """The parameter ``name`` of the registered submodels (``ctx.P[name]`` in a submodel's laws)."""
    for p in parameters(all_inputs=True):
        if p.name == name:
            return p
    raise UnknownParameter(not_known(f"parameter {name!r}", name, parameter_names(all_inputs=True),
                                     "declared by any registered submodel"))


def options() -> dict[str, Option]:
    """Every option slot by name, parents before children."""
    return {o.name: o for cls in submodels() for o in cls.options}


def slots(table: str) -> dict[str, Option]:
    """The option slots written in the scene table ``table`` ("effects" or "assumptions"), parents first."""
    return {n: o for n, o in options().items() if o.table == table}


def states(opts=None) -> tuple[State, ...]:
    """The continuous states, in the order of the state vector (of the active submodels; all with ``opts`` None)."""
    return tuple(s for cls in submodels() if opts is None or cls.active(opts) for s in cls.states)


def state_names(opts=None) -> tuple[str, ...]:
    return tuple(s.name for s in states(opts))


def state(name: str) -> State:
    """The declaration of a state by name."""
    for s in states():
        if s.name == name:
            return s
    raise KeyError(f"no submodel declares a state {name!r}")


def guards() -> tuple[Guard, ...]:
    return tuple(g for cls in submodels() for g in cls.guards)


def contacts() -> dict[str, str]:
    """Every contact or load a submodel declares (the prefixes of the outputs F_<c>_X, F_<c>_Y, M_<c>, Pf_<c>) ->
    what it is (the submodel's :attr:`~.base.Submodel.contact_meanings`, else its name with its summary, a noun
    phrase either way: "... from the {meaning}"), in registration order."""
    return {c: cls.contact_meanings.get(c, f"{c} ({cls.summary})" if cls.summary else c) for cls in submodels()
            if _has_contacts(cls) for c in (cls.contact_names or (cls.name,))}


def _has_contacts(cls: type[Submodel]) -> bool:
    return bool(cls.contact_names or cls.guards or cls.contact_meanings) or cls.contacts is not Submodel.contacts


def guard_contacts() -> dict[str, str]:
    """The contact each guard opens and closes, by the guard's name (the guard's ``contact``, else its
    submodel's name)."""
    return {g.name: g.contact or cls.name for cls in submodels() for g in cls.guards}


def guard(name: str) -> Guard:
    for g in guards():
        if g.name == name:
            return g
    raise KeyError(name)


def guard_label(name: str) -> str:
    """A guard as messages name it: its name, the contact it opens and closes named by its submodel as the chattering
    message names a damped contact (``the groove contact``, runtime/solving/checks.py) and its declared meaning
    (``b3 (the groove contact i2: gap at g3, the mouth corner on the seal's positive side (Eq. 42))``, ``xs5 (the
    housing contact: ...)``); the name alone for a guard no registered submodel declares."""
    found = next(((cls, g) for cls in submodels() for g in cls.guards if g.name == name), None)
    if found is None:
        return name
    owner, g = found
    contact = guard_contacts()[name]
    return f"{name} (the {owner.name} contact{'' if contact == owner.name else ' ' + contact}: {g.meaning})"


def activation_symbols() -> dict:
    """The activation symbol of every declared guard, by the activation's name (e.g. ``"s_h"``)."""
    return {g.activation: g.symbol for g in guards()}


def oscillators(opts=None) -> tuple[tuple[str, str], ...]:
    """The (stiffness, damping) pairs of the active submodels (all with ``opts`` None), for the stability
    check of the explicit fixed-step methods (runtime/solving/contact_stability.py)."""
    return tuple(pair for cls in submodels() if opts is None or cls.active(opts) for pair in cls.oscillators)


def dampers(opts=None) -> tuple[str, ...]:
    """The damping parameters of the dampers without a stiffness of the active submodels (all with ``opts`` None),
    for the stability check of the explicit fixed-step methods (runtime/solving/contact_stability.py)."""
    return tuple(c for cls in submodels() if opts is None or cls.active(opts) for c in cls.dampers)


def frictions(opts=None) -> tuple[Friction, ...]:
    """The friction laws that can stick of the active submodels (all with ``opts`` None), for the
    explicit fixed-step methods' stability check on the friction regularisation (runtime/solving/friction_stability.py)."""
    return tuple(f for cls in submodels() if opts is None or cls.active(opts) for f in cls.frictions)


def alternatives() -> tuple[tuple[str, str], ...]:
    """The pairs of scene keys that state one thing two ways (e.g. ``contacts.cw`` and ``contacts.zeta_w``): a scene
    gives at most one of each, but those of :func:`superseding`."""
    return tuple(pair for cls in submodels() for pair in cls.scene_alternatives())


def superseding() -> tuple[tuple[str, str], ...]:
    """The pairs (key, key it makes unread) of :func:`alternatives` that a scene may give both of (``seal.ms`` and
    ``seal.density``): the second is then not read, and the scene warns."""
    return tuple(pair for cls in submodels() for pair in cls.supersedes)


def digest(opts) -> str:
    """sha256 over the source of every submodel that enters a model of the options ``opts`` (:func:`entering`)
    and of its helpers (part of the derivation's cache key; :func:`.sources.source_key`)."""
    h = hashlib.sha256()
    for cls in entering(opts):
        h.update(cls.name.encode())
        h.update(source_key(cls).encode())
    return h.hexdigest()
