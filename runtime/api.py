"""The Python API: ``simulate(scene)`` and ``Model(scene).rhs(theta, state)``."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from ..derive.names import STATE_NAMES
from ..files import path_argument
from .results.checked import checked
from .results.gas import GasCycleWarning, describe_cycle
from .results.liftoff import LiftOffWarning, describe_liftoff
from .results.plausibility import FlankWarning, PenetrationWarning, describe, describe_flank, side_clearance
from .results.result import SimulationResult
from .solving.accuracy import AccuracyWarning, UnusedToleranceWarning, loose_tolerances, unused_tolerances
from .solving.near_chatter import NearChatterWarning, describe_near_chatter
from .solving.periodicity import UntilPeriodicWarning, single_revolution
from .solving.run import run
from .solving.settings import RunSettings, merged


def model_functions(scene, *, compiled: bool | None = None):
    """The model Functions of a scene's effects and assumptions, from the generation station's artefacts.

    Compiled (the default unless the scene asks for ``solver.interpreted``): ``casadi.external`` of the
    model library, each carrying the SX Functions it was generated from (``.sx()``), which the integrators
    embed. Derivation (sympy) happens only when the model's artefacts are missing or stale.
    A signal caught by an active :class:`~apexseal.signals.StopSignals` (the command line's, a serial sweep's)
    abandons a derivation or compilation at once with ``KeyboardInterrupt``: nothing is computed yet.
    """
    from ..generated.load import load_functions
    from ..signals import StopSignals

    compiled = (not scene.solver.interpreted) if compiled is None else compiled
    with StopSignals.abandoning():
        loaded = load_functions(scene.effects, scene.assumptions, compiled=compiled, flags=scene.solver.compile)
    return loaded.c if compiled else loaded.sx


def scene_settings(scene) -> dict:
    """The run settings the scene's [solver] table and [operation] revolutions give, by RunSettings field (not
    checked together: :func:`settings_of` does)."""
    base = {}
    for name, (key, _) in _SCENE_KEYS.items():
        section, field = key.split(".")
        value = getattr(getattr(scene, section), field)
        base[name] = (not value) if name == "compile_c" else value  # the scene's solver.interpreted
    base["parameters"] = "constant" if scene.schedule is None else "linear"  # its schedule, not a [solver] key
    return base


def settings_of(scene, **overrides) -> RunSettings:
    """RunSettings from the scene's [solver] table and [operation] revolutions, with keyword overrides (None =
    keep); every value is checked by :class:`RunSettings` (a bad one raises :class:`SettingsError`). A tolerance
    overridden for a fixed-step method, which reads none, warns (:class:`~.solving.accuracy.UnusedToleranceWarning`)."""
    base = scene_settings(scene)
    interpreted = not base.pop("compile_c")
    if overrides.get("compile_c") is None and overrides.get("interpreted") is None:
        base["interpreted"] = interpreted  # under the scene's name, which a problem then names
    settings = RunSettings(**merged(base, overrides))
    unused = unused_tolerances(settings, {k: overrides.get(k) for k in ("rtol", "atol")})
    if unused:
        from ..stacklevel import user_stacklevel

        warnings.warn(unused, UnusedToleranceWarning, stacklevel=user_stacklevel())
    return settings


def check_progress(progress) -> None:
    """``progress`` of :func:`simulate`: True or False (a numpy bool too), or a :class:`SettingsError` naming it
    (``progress="yes"`` was taken silently, and ``"no"`` turned the report on)."""
    if not isinstance(progress, bool | np.bool_):
        from .solving.settings import SettingsError

        raise SettingsError([("progress", progress, "must be True or False (True: report the long stages and the "
                                                    "integration on stderr); a callback is not taken")])


def scene_of(scene):
    """A scene, or a scene loaded from a path (str or Path); anything else is a TypeError naming what was given."""
    from .scenes.scene import Scene, load_scene

    if isinstance(scene, str | Path):
        return load_scene(scene)
    if not isinstance(scene, Scene):
        raise TypeError(f"scene: expected a Scene (apexseal.load_scene(...)) or the path of a scene file, "
                        f"not {type(scene).__name__}")
    return scene


def _radians(value: float) -> str:
    """An angle setting (rad) as the scene writes it: with its unit (a bare angle is refused as ambiguous)."""
    return f"{float(value)!r} rad"


#: RunSettings field -> (scene key, value as the scene writes it): a run's settings written into its scene
_SCENE_KEYS = {
    "method": ("solver.method", str), "rtol": ("solver.rtol", float), "atol": ("solver.atol", float),
    "samples_per_revolution": ("solver.samples_per_revolution", int),
    "steps_per_revolution": ("solver.euler_steps_per_revolution", int), "event_tol": ("solver.event_tol", _radians),
    "max_events_per_revolution": ("solver.max_events_per_revolution", int),
    "chatter_window": ("solver.chatter_window", _radians), "chatter_events": ("solver.chatter_events", int),
    "flags": ("solver.compile", str),
    "compile_c": ("solver.interpreted", lambda c: not c), "revolutions": ("operation.revolutions", int),
    "pressure": ("solver.pressure", str), "calls_per_revolution": ("solver.calls_per_revolution", int),
}


def scene_that_ran(scene, settings: RunSettings):
    """The scene with a run's settings written into it ([solver] keys, operation.revolutions), so that loading
    its resolved TOML re-runs the same computation. Settings that are no scene key (a wall-time budget, a
    user's engine class) are recorded in result.json only; what a budget changes in the computation, the
    integrator calls a revolution is cut into (each starts the integrator afresh), is written as
    ``solver.calls_per_revolution``, so the scene re-runs the same numbers without the budget."""
    from .solving.settings import samples_per_call

    if settings.max_wall_time and settings.calls_per_revolution is None:
        settings = settings.replace(calls_per_revolution=settings.samples_per_revolution // samples_per_call(settings))
    base = scene_settings(scene)
    over = {}
    for name, (key, form) in _SCENE_KEYS.items():
        value = getattr(settings, name)
        if value == base[name] or value is None or (name == "method" and not isinstance(value, str)):
            continue
        over[key] = form(value)
    if not over:
        return scene
    import warnings

    from .scenes.errors import IgnoredValueWarning
    from .scenes.units import PlausibilityWarning

    with warnings.catch_warnings():  # the scene's plausibility and its ignored values were reported when it was loaded
        warnings.simplefilter("ignore", PlausibilityWarning)
        warnings.simplefilter("ignore", IgnoredValueWarning)
        return scene.with_overrides(**over)


def provenance(scene, functions=None) -> dict:
    """What identifies a run's inputs: the scene as given (Scene.reference) and its content hash, the generated
    model's input hash (the ``input_hash`` of its manifest: the model ``functions`` were loaded from, or the
    scene's), and the package versions."""
    from ..derive.choices import options_of
    from ..generated.manifest import input_hash
    from .results.summary import versions

    model_hash = getattr(functions, "model_hash", None) or input_hash(scene.effects, scene.assumptions)
    return {"scene": scene.reference, "scene_hash": scene.content_hash(), "model_hash": model_hash,
            "versions": versions(options_of(scene.effects, scene.assumptions))}


def simulate(scene, *, revolutions: int | None = None, method: str | None = None, rtol: float | None = None,
             progress: bool = False, functions=None, out=None, **settings) -> SimulationResult:
    """Simulate a scene (see :func:`apexseal.load_scene`, or a scene file's path) and return its
    :class:`SimulationResult`.

    Settings given here override the scene's and are checked with the same ranges (:class:`RunSettings`); the
    result keeps the scene that ran with them applied (``result.scene``, saved as scene.toml).
    With ``out`` (a folder) the revolutions are streamed to disk as they finish and the folder is written as
    one unit (runtime/results/folder.py); the returned result is read back from it. ``progress=True`` reports
    the long stages (derivation, code generation, compilation with elapsed times) and the integration on stderr;
    it takes True or False only (no callback: anything else, ``"yes"`` too, is a :class:`SettingsError`).
    Warns with :class:`PenetrationWarning` when a contact sinks into its wall by more than a stated fraction of
    the side clearance, and at least a metal contact's deflection under ordinary loads
    (:mod:`apexseal.runtime.results.plausibility`), with :class:`~apexseal.runtime.results.liftoff.LiftOffWarning`
    when the seal tip is off the housing for half the run or more, or for half a revolution in one stretch
    (:mod:`apexseal.runtime.results.liftoff`), with :class:`~apexseal.runtime.results.gas.GasCycleWarning` when
    the chamber gas model ran a cycle that is not an expander's (:mod:`apexseal.runtime.results.gas`: it has no
    valves; a compressor's chamber pressures are given as a table), with
    :class:`~apexseal.runtime.solving.near_chatter.NearChatterWarning` when a completed run's switches came close
    to a chatter detector's limit (:mod:`apexseal.runtime.solving.near_chatter`), and before the run with
    :class:`~apexseal.runtime.solving.accuracy.AccuracyWarning` when ``rtol`` or ``atol`` is looser than the peaks
    bear (:mod:`apexseal.runtime.solving.accuracy`). After a Ctrl-C the run stops at its next
    check and is kept (written, with ``out``); then, in a script, :class:`~apexseal.signals.RunInterrupted` (a
    ``KeyboardInterrupt`` whose ``result`` is the run) is raised, and in an interactive session the run is returned
    with a :class:`RunInterruptedWarning`.
    """
    from .. import progress as stages
    from ..signals import StopSignals

    check_progress(progress)
    scene = scene_of(scene)
    st = settings_of(scene, method=method, rtol=rtol, revolutions=revolutions, **settings)
    # a SIGTERM stops the run, keeps its result (written when ``out`` is given) and then ends the process
    stop = StopSignals(redeliver_term=True)
    with stages.enabled(progress), stop as signals:
        if out is None:
            result = run_scene(scene, st, progress=progress, functions=functions)
        else:
            from .results.folder import ResultFolder

            sink = ResultFolder(path_argument("out", out, "a folder (str or Path), or None to keep the result in "
                                              "memory"))
            try:
                with sink.discarded_if_empty():  # a run that raised leaves a .partial- folder another process may
                    result = run_scene(scene, st, progress=progress, functions=functions, sink=sink)  # continue
            finally:
                sink.release()
            out = _commit(sink)
        return _after_a_ctrl_c(result, stop, signals, out)  # inside: a SIGTERM ends the process on leaving


def _after_a_ctrl_c(result: SimulationResult, stop, signals, out) -> SimulationResult:
    """``result``, once its run is kept; after a Ctrl-C that stopped it, :func:`after_an_interrupt`."""
    kept = f"{result.revolutions:.2f} revolutions kept" + (f" in {out}" if out is not None else "")
    lost = f"{result.revolutions:.2f} revolutions computed in memory only, lost with the process (out= writes a run " \
           "as it goes)"
    return after_an_interrupt(result, stop, signals, result.status == "interrupted", "the run", kept,
                              kept if out is not None else lost)


def after_an_interrupt(result, stop, signals, interrupted: bool, what: str, kept: str, ending: str | None = None):
    """``result`` (a run, a study's report), once what was computed is kept; after a Ctrl-C that stopped it
    (``interrupted``; caught by this call's own :class:`~apexseal.signals.StopSignals` ``stop``, not by an enclosing
    command's or study's), in a script :class:`~apexseal.signals.RunInterrupted` carrying it, so that the script
    stops as Ctrl-C asks (a loop over designs went on to its next one, and an optimiser took the partial run's
    numbers); in an interactive session (a notebook) it is returned for the next cell to look at, with a
    :class:`RunInterruptedWarning`. ``what`` and ``kept`` say what stopped and what was kept. A SIGTERM or SIGHUP
    ends the process when ``stop`` is left, after one line on stderr saying what was kept (``ending``, where it
    differs from ``kept``: what lives in memory only is lost with the process)."""
    import signal

    from ..signals import RunInterrupted, interactive

    if signals is not stop:
        return result
    stop.farewell = f"{what} was stopped: {ending or kept}"
    if signal.SIGINT not in stop.received or not interrupted:
        return result  # (a Ctrl-C while a completed run was written leaves it completed: nothing to say)
    if interactive():
        from ..stacklevel import user_stacklevel

        warnings.warn(f"{what} was interrupted by Ctrl-C: {kept}", RunInterruptedWarning,
                      stacklevel=user_stacklevel())
        return result
    raise RunInterrupted(f"{what} was interrupted by Ctrl-C: {kept}; the exception's .result holds it", result)


class RunInterruptedWarning(UserWarning):
    """Ctrl-C stopped ``apexseal.simulate``, ``apexseal.resume`` or a study (the preload study, a sweep, the
    calibration) in an interactive session: the returned result is what it computed (in a script,
    :class:`~apexseal.signals.RunInterrupted` is raised instead)."""


def _commit(sink) -> Path:
    """Move the result folder into place and return where it is; a result that stayed aside (see
    ResultFolder.commit) is warned of."""
    from .results.folder import KeptAsideWarning

    where = sink.commit()
    if sink.kept_aside:
        warnings.warn(f"{sink.kept_aside}; this run's result is in {where}", KeptAsideWarning, stacklevel=3)
    return where


def resume(folder, *, revolutions: int | None = None, max_wall_time: float | None = None, progress: bool = False,
           functions=None) -> SimulationResult:
    """Continue the run whose result is in ``folder`` (interrupted, failed, killed outright: its
    ``<out>.partial-<run id>`` folder, or completed and given more ``revolutions``) up to ``revolutions``
    (default: the revolutions it was asked for), with its own scene and settings (``max_wall_time`` may be given).

    The run continues after its last whole revolution from the integrator's state there (and what the integrator
    carried from there into its next call, for a method that carries more: the composite), making the calls the
    uninterrupted run makes (the same samples to the bit), and the result is written back as one unit, under the
    same run id: a killed run's folder becomes its target's. ``info["continued"]`` lists the runs before, with
    their wall times and solver statistics; ``info["wall_time_s"]`` and ``solver_stats`` are this one's.
    Raises :class:`~.results.folder.ResultFolderError` for a folder that cannot be continued, with the reason. A
    Ctrl-C is handled as by :func:`simulate`.
    """
    from .. import progress as stages
    from ..signals import StopSignals
    from .results.folder import ResultFolder

    check_progress(progress)
    cont, st = continuing(folder, revolutions=revolutions, max_wall_time=max_wall_time)
    stop = StopSignals(redeliver_term=True)
    with stop as signals:  # as simulate: a SIGTERM ends the process once the result is written
        functions = functions or model_functions(cont.scene)
        same_model(cont, functions)
        sink = ResultFolder.continuing(cont)
        try:
            with stages.enabled(progress), sink.discarded_if_empty():
                result = run_scene(cont.scene, st, progress=progress, functions=functions, sink=sink,
                                   continuation=cont)
        finally:
            sink.release()
        where = _commit(sink)
        return _after_a_ctrl_c(result, stop, signals, where)  # inside: a SIGTERM ends the process on leaving


def continuing(folder, *, revolutions: int | None = None, max_wall_time: float | None = None):
    """The run in ``folder`` to continue (:class:`~.results.continuation.Continuation`) and the settings to continue
    it with: its scene's, for ``revolutions`` (default: those it was asked for), which must be more than it holds,
    within ``max_wall_time`` (a budget cuts each revolution into 36 calls unless its scene does already)."""
    from .results.continuation import continuation
    from .results.folder import ResultFolderError

    cont = continuation(path_argument("folder", folder, "a result folder (str or Path)"))
    if revolutions is not None:  # its range named first (0 and -5 were taken as "as many as it was asked for")
        settings_of(cont.scene, revolutions=revolutions)
    asked = int(cont.record["info"].get("revolutions_asked") or 0) if revolutions is None else revolutions
    if asked <= cont.revolutions:
        than = f"as many as asked ({asked})" if asked == cont.revolutions else f"more than the {asked} asked"
        raise ResultFolderError(f"{cont.source} holds {cont.revolutions} whole revolution(s), {than}: give at "
                                f"least {cont.revolutions + 1} revolutions to continue it")
    return cont, settings_of(cont.scene, revolutions=asked, max_wall_time=max_wall_time)


def same_model(cont, functions) -> None:
    """Refuse to continue a run with a model other than the one it was computed with."""
    from .results.folder import ResultFolderError

    before, now = cont.record["info"].get("model_hash"), provenance(cont.scene, functions)["model_hash"]
    if before != now:
        raise ResultFolderError(f"{cont.source} was computed with another model (model hash {str(before)[:12]}, now "
                                f"{now[:12]}: the derivation, a submodel or the generator changed): simulate again")


def run_scene(scene, settings: RunSettings, *, progress: bool = False, functions=None, sink=None,
              continuation=None) -> SimulationResult:
    """Run a loaded scene with checked settings (``sink``: where completed revolutions go, see :func:`run`;
    ``continuation``: the stopped run it continues, whose revolutions the sink holds, see :func:`resume`).

    The scene that ran (the settings written into its [solver] and [operation] keys) goes to the sink first
    (scene.toml of a result folder) and is the result's ``scene``."""
    ran = scene_that_ran(scene, settings)
    loose = loose_tolerances(settings)  # said before the run, and recorded in its summary (info["accuracy"])
    if loose is not None:
        warnings.warn(loose, AccuracyWarning, stacklevel=3)
    lonely = single_revolution(scene.operation.until_periodic, settings.revolutions)  # nothing to compare with
    if lonely is not None:
        warnings.warn(lonely, UntilPeriodicWarning, stacklevel=3)
    if hasattr(sink, "write_scene"):
        sink.write_scene(ran)
    functions = functions or model_functions(ran)  # the settings' compile and interpreted too
    op = scene.operation
    pressure = scene.pressure if scene.effects.chamber_pressure else None
    clearance = side_clearance(scene.seal.Ws, scene.seal.Wg)
    info = provenance(ran, functions) | {"side_clearance_m": clearance}
    if continuation is not None:  # what ran before: the result's wall time and statistics are this run's
        before = continuation.record["info"]
        info["scene"] = before.get("scene", info["scene"])  # as the first run was given it
        info["continued"] = [*before.get("continued", []), {
            "after_revolutions": continuation.revolutions, "status": continuation.record["status"],
            "stop": continuation.record["stop"], "wall_time_s": before.get("wall_time_s"),
            "solver_stats": before.get("solver_stats")}]
    result = run(functions, scene.parameter_vector(functions.parameter_names), settings, theta_start=op.start_angle,
                 state0=initial_state(scene, functions), pressure=pressure, until_periodic=op.until_periodic,
                 periodic_tol=op.periodic_tol, progress=progress, info=info, sink=sink,
                 path=scene.parameter_path(functions.parameter_names),
                 continue_from=None if continuation is None else (continuation.revolutions, continuation.z,
                                                                   continuation.carried))
    result.scene = ran
    checks = checked(result)  # kept with the result: its summary reads them, not computed again
    if checks.plausibility is not None and not checks.plausibility["ok"]:
        warnings.warn(describe(checks.plausibility), PenetrationWarning, stacklevel=3)
    if checks.flank is not None and not checks.flank["ok"]:
        warnings.warn(describe_flank(checks.flank), FlankWarning, stacklevel=3)
    if checks.liftoff is not None and not checks.liftoff["ok"]:
        warnings.warn(describe_liftoff(checks.liftoff, result.revolutions, result.guard_names), LiftOffWarning,
                      stacklevel=3)
    if checks.gas is not None and not checks.gas["expander_cycle"]["ok"]:
        warnings.warn(describe_cycle(checks.gas), GasCycleWarning, stacklevel=3)
    cluster = result.info.get("switch_cluster")  # completed close to a chatter detector's limit
    if result.status == "completed" and cluster is not None and cluster["near"]:
        warnings.warn(describe_near_chatter(cluster), NearChatterWarning, stacklevel=3)
    return result


def initial_state(scene, functions=None) -> np.ndarray:
    """The physical initial state in ``functions.state_names`` order (default: the seal's six, SI): the seal's
    from [operation.initial_state], a submodel's own states from its ``initial_state`` (the chamber gas: both
    chambers at the exhaust state)."""
    from ..derive.choices import options_of
    from ..derive.submodels.registry import submodels

    opts = options_of(scene.effects, scene.assumptions)
    op = scene.operation
    values = {k: float(getattr(op.initial_state, k)) for k in STATE_NAMES}
    for cls in submodels():
        if cls.states and cls.active(opts):
            values.update(cls.initial_state(scene.parameters, op.start_angle))
    names = functions.state_names if functions is not None else STATE_NAMES
    return np.array([values[n] for n in names], float)


class Model:
    """The seal model of a scene, evaluated pointwise (for checks and small scripts; slow in loops).

    ``Model(scene).functions`` are the scene's CasADi Functions themselves (docs/codegen.md, "What is generated"),
    with named inputs and outputs: ``functions.rhs(theta, x, a, p, u) -> xdot``, ``guards``, ``outputs``,
    ``rhs_switched``; ``functions.state_names``, ``guard_names``, ``output_names`` and ``parameter_names`` name
    their entries, and ``self.params`` is the scene's parameter vector in that order. Where a C compiler is
    available they are the compiled library (``casadi.external``), which carries first derivatives only: a
    Jacobian works, a Hessian (IPOPT with its exact Hessian, ``ca.hessian``) fails. ``functions.sx()`` is the same
    set as CasADi SX expressions, with derivatives of every order, to embed in an NLP or an integrator.
    """

    def __init__(self, scene, functions=None):
        self.scene = scene = scene_of(scene)
        self.functions = functions or model_functions(scene)
        self.params = scene.parameter_vector(self.functions.parameter_names)

    def pressures(self, theta: float) -> np.ndarray:
        """The chamber pressures (Pa, Pb) at crank angle ``theta`` (rad), as a run sees them (Eq. 75)."""
        theta = self._theta(theta)
        if not self.scene.effects.chamber_pressure:
            return np.zeros(2)
        return np.asarray(self.scene.pressure.interval_means(np.array([theta, theta + 1e-9])), float)[:, 0]

    def closed(self, theta: float, state) -> np.ndarray:
        """Which contacts are closed (guard < 0), in the order of ``guard_names``."""
        theta, state = self._point(theta, state)
        g = np.array(self.functions.guards(theta, state, self.params, self.pressures(theta)))
        return g.ravel() < 0

    def rhs(self, theta: float, state) -> np.ndarray:
        """d/dt of the state (``state_names``: the seal's x, y, phi, x', y', phi', then a submodel's own states,
        such as the chamber gas's) at crank angle theta, contacts set by their gaps."""
        theta, state = self._point(theta, state)
        u = self.pressures(theta)
        return np.array(self.functions.rhs_switched(theta, state, self.params, u)).ravel()

    @staticmethod
    def _theta(theta) -> float:
        try:
            value = float(theta)
        except (TypeError, ValueError):
            raise ValueError(f"theta = {theta!r}: expected a crank angle in rad (a finite number)") from None
        if not np.isfinite(value):
            raise ValueError(f"theta = {theta!r}: expected a finite crank angle in rad")
        return value

    def _point(self, theta, state) -> tuple[float, np.ndarray]:
        """theta as a finite float and state as finite floats, one per name of ``state_names``, or a ValueError
        naming what is wrong."""
        theta = self._theta(theta)
        names = self.state_names
        try:
            x = np.asarray(state, dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"state = {state!r}: expected {len(names)} numbers ({', '.join(names)})") from None
        if x.shape in ((len(names), 1), (1, len(names))):  # a column or row vector (CasADi's DM gives (n, 1))
            x = x.reshape(len(names))
        if x.shape != (len(names),):
            raise ValueError(f"state: expected shape ({len(names)},) ({', '.join(names)}, SI), got shape {x.shape}")
        if not np.isfinite(x).all():
            bad = ", ".join(k for k, v in zip(names, x, strict=True) if not np.isfinite(v))
            raise ValueError(f"state: not finite in {bad}: {x.tolist()}")
        return theta, x

    @property
    def state_names(self) -> tuple[str, ...]:
        """The state's entries, in order: the seal's six, then those of the submodels the scene turns on."""
        return tuple(self.functions.state_names)

    @property
    def guard_names(self) -> tuple[str, ...]:
        return tuple(self.functions.guard_names)
