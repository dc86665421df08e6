"""The integration methods: one registry of engines with a written contract (SciPy's ``METHODS`` style).

Every engine integrates the hybrid state (:mod:`.layout`) over a whole number of output intervals and
follows :class:`Engine`. ``METHODS`` maps a method name to its engine class (named ``"module:Class"`` so
that reading a scene imports no integrator); :func:`register_method` adds a user's engine, and
``simulate(scene, method=MyEngine)`` accepts an engine class directly.
"""

from __future__ import annotations

import importlib
import math
from dataclasses import dataclass

import numpy as np

from ...suggest import not_known
from .stability import CLASSICAL_RK4, EXPLICIT_EULER, StabilityFunction


@dataclass
class RevolutionResult:
    """What an engine's ``run`` returns: the hybrid states at the output grid and the solver's statistics."""

    z: np.ndarray  # (layout.size, n_samples)
    stats: dict


class Engine:
    """The contract of an integration engine.

    ``build(functions, settings, method=..., n_samples=..., span=..., compile_c=...)`` makes one that covers
    ``n_samples`` equal output intervals of ``span`` rad of crank angle; ``run(z0, params, theta0, pressures)``
    integrates from the hybrid state ``z0`` at crank angle ``theta0`` with the physical parameter vector
    ``params`` and the chamber pressures ``pressures`` (2, n_samples), or, for an engine that lists "linear" in
    ``pressure_profiles`` and was built with ``settings.pressure = "linear"``, their values at the n_samples + 1
    interval edges; it returns a :class:`RevolutionResult`. An engine that lists "linear" in
    ``parameter_profiles`` and was built with ``settings.parameters = "linear"`` (a scene's schedule) also takes
    ``params`` as its values at the n_samples + 1 interval edges (n_par, n_samples + 1), linear between them.
    It raises :class:`WallTimeExceeded` (with the samples done) past ``deadline`` (a ``time.perf_counter()``
    value; engines that cannot stop inside a call may ignore it) and ``RuntimeError`` when the solver fails.
    """

    n_samples: int
    compiled: bool = False
    #: True where the engine runs only in the compiled model library (its C: the composite): the settings refuse it
    #: with ``compile_c = False`` (a scene's ``solver.interpreted = true``), and a model without a library
    needs_library: bool = False
    #: True where ``run`` checks ``deadline`` inside a call (the apexseal event loop's engines): the run then never
    #: cuts its calls into intervals near the end of a wall-time budget (runtime/solving/pace.py)
    stops_at_deadline: bool = False
    #: True where a compiled engine still reports its steps and evaluations (the composite's C counts them)
    counts_steps: bool = False
    deadline: float = math.inf
    #: the settings' pressure profiles this engine can integrate (runtime/solving/settings.py)
    pressure_profiles: tuple[str, ...] = ("steps",)
    #: the settings' parameter profiles this engine can integrate (generated/layout.py ``PARAMETER_PROFILES``):
    #: "linear" for the parameters a scene schedules along the revolution
    parameter_profiles: tuple[str, ...] = ("constant",)

    @classmethod
    def build(cls, functions, settings, *, method: str, n_samples: int, span: float, compile_c: bool) -> Engine:
        raise NotImplementedError

    def run(self, z0: np.ndarray, params: np.ndarray, theta0: float, pressures: np.ndarray) -> RevolutionResult:
        raise NotImplementedError

    def reset(self) -> None:
        """Forget what earlier runs left, before the engine serves another run (:mod:`.engine_pool`): its
        deadline (an engine that carries more from call to call resets that too)."""
        self.deadline = math.inf

    def carried(self, z: np.ndarray) -> np.ndarray | None:
        """What this engine carries into its next call, beside the hybrid state, if that call starts from ``z``
        (the state its last call ended in): a small float array, or None for nothing (every call starts afresh
        from its ``z0``, as here). The run stores it with each part (runtime/results/folder.py), and a run that
        continues from the part hands it back (:meth:`carry_on`), so that its first call is the uninterrupted
        run's."""
        return None

    @classmethod
    def steps_taken(cls, steps_per_revolution: int, dtheta: float) -> int:
        """A fixed-step engine's steps per revolution, 2 pi over its longest step, at the setting
        ``steps_per_revolution`` with output intervals of ``dtheta`` rad: the setting, unless the engine cuts its
        intervals otherwise (the Euler fold, rk: what the stability checks of its ``Method.stability`` judge)."""
        return int(steps_per_revolution)

    def carry_on(self, z: np.ndarray, carried: np.ndarray | None) -> None:
        """Continue from the hybrid state ``z`` as if the last call had ended there, carrying ``carried`` (what
        :meth:`carried` gave for ``z``; None: nothing carried, the next call starts afresh)."""


def run_params(params, parameters: str) -> np.ndarray:
    """``params`` as an engine built with ``parameters`` (``settings.parameters``) takes them: the parameter vector,
    or, built with "linear", their values at the call's interval edges too; a ValueError for values at the edges
    given to an engine built with "constant"."""
    P = np.asarray(params, float)
    if P.ndim != 1 and parameters != "linear":
        raise ValueError("params: one parameter vector; an engine built with parameters = 'constant' does not take "
                         "their values at the interval edges")
    return P


def edge_params(params, k: int, n: int = 1) -> np.ndarray:
    """What an engine's ``run`` takes as the parameters of intervals k..k+n-1 of a call that took ``params``: the
    parameter vector itself, or its values at those intervals' n + 1 edges (a scene's schedule)."""
    P = np.asarray(params, float)
    return P if P.ndim == 1 else P[:, k:k + n + 1]


def first_params(params) -> np.ndarray:
    """The parameter vector at the first edge of a call that took ``params`` (see :func:`edge_params`)."""
    P = np.asarray(params, float)
    return P if P.ndim == 1 else P[:, 0]


class WallTimeExceeded(RuntimeError):
    """The wall-time deadline passed inside an engine's call; ``partial`` holds the samples computed."""

    def __init__(self, partial: np.ndarray):
        super().__init__("wall-time budget used up")
        self.partial = partial


@dataclass(frozen=True)
class Method:
    """A method name's engine, the CasADi plugin it uses, and what it is."""

    engine: str | type  # "module:Class" or the class itself
    plugin: str
    description: str
    #: False for methods that switch contacts inside the right-hand side (no events to miss)
    locates_events: bool = True
    #: an explicit fixed-step method's stability function (runtime/solving/stability.py): its step is checked on
    #: each contact and each friction law that can stick, before and during a run; None for adaptive and implicit
    #: methods, whose step follows the stiffness or does not depend on it
    stability: StabilityFunction | None = None
    #: True where its integrator differentiates the right-hand side (Jacobians, or event location on derivatives):
    #: the start check then refuses a right-hand side whose derivative is not finite (runtime/solving/preflight.py)
    needs_derivatives: bool = False
    #: True for a method that takes fixed steps (solver.euler_steps_per_revolution) and estimates no error: it
    #: reads no rtol or atol, and its run says that it controls no error (runtime/solving/accuracy.py)
    fixed_step: bool = False

    def engine_class(self) -> type:
        if isinstance(self.engine, type):
            return self.engine
        module, name = self.engine.split(":")
        return getattr(importlib.import_module(module, __package__), name)


_EVENTS = ".event_integrator:EventIntegrator"
_STEPPER = ".stepper_integrator:StepperIntegrator"

#: method name -> :class:`Method`
METHODS: dict[str, Method] = {
    "erk": Method(_EVENTS, "erk", "adaptive RK45 (Dormand-Prince) with events located on its dense output; "
                  "compiles to C", needs_derivatives=True),
    "erk-rk4": Method(_EVENTS, "erk", "fixed-step RK4 with events on its dense output; compiles to C",
                      stability=CLASSICAL_RK4, needs_derivatives=True, fixed_step=True),
    "composite": Method(".composite:CompositeIntegrator", "", "RK45 with events where contacts switch, exponential "
                        "Rosenbrock (exprb32) steps between; generated C in the model library"),
    "rosenbrock": Method(_EVENTS, "rosenbrock", "L-stable Rosenbrock order 5(4) for stiff contacts, events on dense "
                         "output; compiles to C", needs_derivatives=True),
    "cvodes": Method(_STEPPER, "cvodes", "SUNDIALS CVODES (BDF), mode switches located by the apexseal event loop",
                     needs_derivatives=True),
    "cvodes-adams": Method(_STEPPER, "cvodes", "SUNDIALS CVODES (Adams), mode switches located by the apexseal event "
                           "loop", needs_derivatives=True),
    "idas": Method(_STEPPER, "idas", "SUNDIALS IDAS, mode switches located by the apexseal event loop",
                   needs_derivatives=True),
    "rk": Method(_STEPPER, "rk", "fixed-step RK4 per output interval, mode switches located by the apexseal event "
                 "loop", stability=CLASSICAL_RK4, fixed_step=True),
    "collocation": Method(_STEPPER, "collocation", "fixed-step Radau collocation, mode switches located by the event "
                          "loop", needs_derivatives=True, fixed_step=True),
    "euler": Method(".fixed_step:EulerIntegrator", "euler", "explicit (forward) Euler on the switched right-hand "
                    "side, fixed step (apexseal's reading of the paper's 'Euler method', Section 1)",
                    locates_events=False, stability=EXPLICIT_EULER, fixed_step=True),
}


def register_method(name: str, engine: type, description: str, *, plugin: str = "", locates_events: bool = True,
                    stability: StabilityFunction | None = None, needs_derivatives: bool = False,
                    fixed_step: bool = False) -> None:
    """Make ``engine`` (a subclass of :class:`Engine`) available as ``solver.method = name``; ``stability``: the
    stability function of an explicit fixed-step engine's step (its steps per revolution: ``Engine.steps_taken``);
    ``needs_derivatives``: its integrator differentiates the right-hand side (``Method.needs_derivatives``);
    ``fixed_step``: it takes fixed steps and estimates no error (``Method.fixed_step``)."""
    if not (isinstance(engine, type) and issubclass(engine, Engine)):
        raise TypeError(f"method {name!r}: the engine must be a subclass of apexseal's Engine, not {engine!r}")
    METHODS[name] = Method(engine, plugin, description, locates_events, stability, needs_derivatives, fixed_step)


def method_of(method: str | type) -> Method:
    """The :class:`Method` of a name, or of an engine class passed directly."""
    if isinstance(method, type):
        if not issubclass(method, Engine):
            raise TypeError(f"method {method!r} is not a subclass of apexseal's Engine")
        return Method(method, "", method.__doc__ or method.__name__)
    check_method(method)
    return METHODS[method]


def check_method(name: str) -> None:
    if name not in METHODS:
        raise ValueError(not_known(f"solver.method = {name!r}", name, METHODS, "a method", listing="allowed"))


def make_engine(functions, settings, *, n_samples: int | None = None, span: float = 2 * np.pi,
                compile_c: bool | None = None) -> Engine:
    """The engine of ``settings.method`` for these model Functions."""
    method = method_of(settings.method)
    return method.engine_class().build(
        functions, settings, method=settings.method if isinstance(settings.method, str) else "",
        n_samples=n_samples or settings.samples_per_revolution, span=span,
        compile_c=settings.compile_c if compile_c is None else compile_c)


def single_interval_engine(functions, settings, dtheta: float, make=make_engine) -> Engine:
    """An interpreted engine of ``settings.method`` over one output interval of ``dtheta`` rad, built by ``make``
    (the run's engine factory): what a failed call is re-run with (runtime/solving/diagnosis.py), and what makes the
    calls near the end of a wall-time budget (runtime/solving/pace.py). Interpreted: nothing is compiled then."""
    return make(functions, settings, n_samples=1, span=dtheta, compile_c=False)


def fixed_steps(steps_per_revolution: int, dtheta: float) -> int:
    """Steps of a fixed-step method in an interval of ``dtheta`` rad of crank angle (at least 1).

    ``steps_per_revolution`` counts per revolution whatever the interval: a revolution may be cut into several
    integrator calls (a wall-time budget cuts it into 36), and each output interval gets its share.
    """
    return max(1, int(round(steps_per_revolution * dtheta / (2 * math.pi))))


@dataclass(frozen=True)
class ExplicitSteps:
    """An explicit fixed-step method's step as its stability checks see it."""

    method: str  # its solver.method
    stability: StabilityFunction
    steps_per_revolution: int  # 2 pi over its longest step (Engine.steps_taken)
    #: the output interval, rad, at which the engine takes them (None: the steps are the setting)
    dtheta: float | None = None

    def setting(self, steps_taken: int) -> int:
        """The least solver.euler_steps_per_revolution at which the method takes at least ``steps_taken`` steps per
        revolution at this output interval (``Engine.steps_taken``: Euler's fold rounds each interval's share, so
        the setting N may take fewer than N), for advice that holds when followed."""
        if self.dtheta is None:
            return int(steps_taken)
        taken = method_of(self.method).engine_class().steps_taken
        n = int(steps_taken)
        while taken(n, self.dtheta) < steps_taken:
            n += 1
        return n

    @classmethod
    def of(cls, steps: int | ExplicitSteps) -> ExplicitSteps:
        """``steps`` as they are, or a number of steps per revolution as explicit Euler's (what the checks judged
        before they covered other methods)."""
        return steps if isinstance(steps, ExplicitSteps) else cls("euler", EXPLICIT_EULER, int(steps))

    @property
    def subject(self) -> str:
        """How a message names the method: explicit Euler as its messages always have, another by its name and its
        rule (``method 'rk' (classical RK4, fixed step)``)."""
        return "explicit Euler" if self.method == "euler" else f"method {self.method!r} ({self.stability.name}, fixed step)"


def run_steps(settings, dtheta: float | None = None) -> ExplicitSteps | None:
    """:func:`explicit_steps` of a run's settings (a ``RunSettings``: its method and steps per revolution) at its
    intervals of ``dtheta`` rad (default: its output intervals); None for a method that is not explicit fixed-step."""
    return explicit_steps(settings.method, settings.steps_per_revolution,
                          dtheta or 2 * math.pi / settings.samples_per_revolution)


def explicit_steps(method: str | type, steps_per_revolution: int, dtheta: float) -> ExplicitSteps | None:
    """The step of ``method`` at the setting ``steps_per_revolution`` with output intervals of ``dtheta`` rad, if it
    is an explicit fixed-step method (its ``Method`` has a stability function; an engine class passed directly has
    none); None for the others."""
    m = method_of(method)
    if m.stability is None:
        return None
    return ExplicitSteps(method, m.stability, m.engine_class().steps_taken(steps_per_revolution, dtheta), dtheta)
