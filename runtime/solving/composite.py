"""The composite method: RK45 where contacts switch, an exponential Rosenbrock step between, in generated C.

``solver.method = "composite"``. The benchmark's anatomy (runtime/bench/anatomy.py, docs/bench/anatomy.md) found
the error of a revolution inside the switch windows (the impacts and the degrees of ringing after them) and two
thirds of erk's steps between them, where the stiffest contact's stability limit, not the accuracy, sets the step.
This method integrates each part with what suits it:

* **tight phase**: Dormand and Prince's RK5(4) (erk's pair) at ``rtol``/``atol``, events located to ``event_tol``
  by the Illinois method on the step's continuous extension (Shampine's, order 4), then reached by an RK45 step;
* **quiet phase**, from :data:`RING` of crank angle after the last contact event, or earlier once :data:`STIFF_STEPS`
  RK45 steps found themselves at their stability boundary (DOPRI5's stiffness test: the step's last two stages,
  both at its end, estimate h |lambda|, above :data:`STIFF_HLAM`; Hairer and Wanner, Solving ODEs II, Sec. IV.2):
  exprb32, an exponential Rosenbrock method (Hochbruck, Ostermann and Schweitzer, SIAM J. Numer. Anal. 47 (2009))
  that is exact for the linearised stiff part, at :data:`LOOSE` times the tolerances, the rate states' :data:`QUIET`
  times looser still, both within :data:`QUIET_CAPS` (:func:`quiet_factors`);
* a quiet step across which a zero function changes sign is not taken: the tight phase takes over from its start,
  so every switch is located and integrated at ``rtol``;
* a quiet step may cross the ends of output intervals over which the pressures are one line (a pressure table's
  rows coarser than the output grid: the default run's 0.5° rows and 0.1° samples), and the states there are
  interpolated (cubic Hermite, from the step's ends and slopes); every other step ends on the next end;
* below ``rtol`` = :data:`QUIET_RTOL_MIN` there is no quiet phase, and events are located to ``min(event_tol,``
  :data:`EVENTS_PER_RTOL` ``rtol)``: so the error keeps falling as ``rtol`` does (RK45 in C with events, then).

The whole loop is C rendered at the generation station (generated/templates/apexseal_composite.in.c) and
compiled into the model library, where it calls ``hybrid_ode`` and ``hybrid_zero`` directly; this engine calls it
through ctypes, one call per engine call. So it needs the compiled model library (a C compiler, and not
``solver.interpreted``). Its limits follow the run's settings: ``max_steps_per_interval`` steps (rejected ones
included) per output interval, ``max_events_per_revolution`` events per call; past either the call fails, and the
run's diagnosis (runtime/solving/diagnosis.py) re-runs it interval by interval and names the reason. The C cannot
stop inside a call at the wall-time deadline: a run with a budget makes 36 calls per revolution
(runtime/solving/settings.py), checks the budget between them, and makes them interval by interval once the next
would end past the deadline (runtime/solving/pace.py).

A call that goes on from where this engine's previous call ended carries the crank angle since the last event, so
a revolution cut into calls keeps its quiet phase; any other start begins in the tight phase. That angle is all a
call carries: the stiffness count and both phases' step sizes start afresh in each call (at 1e-5 and 1e-3 rad), so
a run cut into more calls (a wall-time budget, ``solver.calls_per_revolution``) takes other steps, but the same
calls always take the same. The run stores the angle with each part (:meth:`CompositeIntegrator.carried`, the
part's ``carried``), and a run continued from the part starts its first call with it
(:meth:`CompositeIntegrator.carry_on`): the samples of the run never stopped, to the bit. A part without it (a
result written before parts stored it) continues in the tight phase, as it did then.
"""

from __future__ import annotations

import ctypes
import math

import numpy as np

from ...generated.hybrid import controls, parameter_controls
from ...generated.scaling import declared_scales
from .methods import Engine, RevolutionResult

#: the quiet phase's tolerances are LOOSE times the tight phase's (docs/bench/composite.md, its first setting) ...
LOOSE = 100.0
#: ... and those of the rate states (velocities) QUIET times looser still ...
QUIET = 100.0
#: ... but never looser than these relative tolerances (all states, rate states): looser, the quiet phase's
#: velocity errors move the next impacts, and at rtol 1e-6 a grazing contact switched 12 more times and the scaled
#: error was 0.15 (1.0e-3 at rtol 1e-5; docs/bench/composite-rules.md)
QUIET_CAPS = (1e-5, 1e-3)
#: below this rtol there is no quiet phase: the quiet phase's errors are amplified through the next impacts (about
#: 1000x), so they set the error, which stalled near 1e-6 at rtol 1e-9 and 1e-10; RK45 alone reaches 6.7e-8 and
#: 4.4e-9 there (docs/bench/composite-rules.md)
QUIET_RTOL_MIN = 1e-8
#: without the quiet phase events are located to min(event_tol, EVENTS_PER_RTOL rtol) of crank angle: at rtol
#: 1e-9, RK45 with events located to 1e-10 rad stalled at 9.8e-7, to 1e-12 rad it reached 6.7e-8 (the same
#: evaluations, to 0.1 %); with the quiet phase its errors set the error, and 1e-11 .. 1e-13 rad gained nothing
EVENTS_PER_RTOL = 1e-3
#: the quiet phase starts this long (crank angle, rad) after the last contact event: the ringing after an impact
RING = math.radians(20.0)
#: ... or earlier, once this many RK45 steps (in DOPRI5's count: six steps inside the boundary forget them) found
#: themselves at their stability boundary: the step is limited by stiffness, no longer by the accuracy of the
#: impact's transient (0: only after RING). A third fewer RK45 steps at rtol 1e-6, the same switches and error
#: (tests/runtime/test_composite.py; 5 or 30 change the evaluations by at most 6 %: docs/bench/composite-rules.md)
STIFF_STEPS = 15
#: ... where a step counts as at its boundary when its estimate of h |lambda| (from its last two stages) exceeds
#: this: RK5(4)'s boundary on the negative real axis, as in Hairer and Wanner's DOPRI5. A step held at the boundary
#: by the controller estimates values on both sides of it from step to step (the estimate is a Rayleigh quotient of
#: the step's last stage difference), so a lower threshold hands over sooner: at 2.0, 4-10 % fewer evaluations on the
#: benchmark's problem (docs/bench/composite-rules.md, its "2.0" row), but on the undamped stress scene, run in the
#: 36 calls of a run with a time budget, the quiet phase then took over while the seal still rattled and the
#: revolution registered 606 switches against erk's 412 (416 at 3.25; `python tests/runtime/test_composite.py
#: --stiff-hlam 2.0`): kept at 3.25
STIFF_HLAM = 3.25

#: the C function's return codes, with what each means
FAILURES = {1: "the model failed to evaluate (non-finite right-hand side or zero functions)",
            2: "step limit: more than max_steps_per_interval = {max_steps} steps in one output interval",
            3: "the model's work arrays exceed the composite integrator's (regenerate with a larger WORK)",
            4: "max_events: more than max_events_per_revolution = {max_events} events in one call"}

_DBL = ctypes.POINTER(ctypes.c_double)
_LL = ctypes.POINTER(ctypes.c_longlong)


def composite_function(library) -> ctypes._CFuncPtr:
    """``apexseal_composite_run`` of the compiled model library at ``library`` (a path), with its signature."""
    fn = ctypes.CDLL(str(library)).apexseal_composite_run
    fn.argtypes = [_DBL, _DBL, _DBL, _DBL, _DBL, ctypes.c_int, ctypes.c_double, ctypes.c_double, ctypes.c_double,
                   ctypes.c_double, ctypes.c_double, ctypes.c_double, ctypes.c_longlong, ctypes.c_double,
                   ctypes.c_double, ctypes.c_longlong, ctypes.c_longlong, _DBL, _DBL, _DBL, _LL]
    fn.restype = ctypes.c_int
    return fn


def quiet_factors(rtol: float) -> tuple[float, float]:
    """(loose, quiet) of the quiet phase at ``rtol``: :data:`LOOSE` and :data:`QUIET` within :data:`QUIET_CAPS`,
    never below 1 (the quiet phase is never tighter than the tight one)."""
    loose = max(1.0, min(LOOSE, QUIET_CAPS[0] / rtol))
    return loose, max(1.0, min(QUIET, QUIET_CAPS[1] / (rtol * loose)))


def _ptr(a: np.ndarray):
    return a.ctypes.data_as(_DBL)


class CompositeIntegrator(Engine):
    """RK45 with events where contacts switch, exprb32 between (see the module docstring)."""

    pressure_profiles = ("steps", "linear")
    parameter_profiles = ("constant", "linear")
    compiled = True
    needs_library = True
    counts_steps = True

    @classmethod
    def build(cls, functions, settings, *, method, n_samples, span, compile_c):
        # compile_c is about compiling an integrator of CasADi's; this one is always the library's C
        if functions.library is None:  # no C compiler (interpreted settings are refused before: RunSettings)
            from .settings import SettingsError

            raise SettingsError([("method", method, "runs in the compiled model library, and these model Functions "
                                  "have none (interpreted ones: no working C compiler, or given so); allowed: the "
                                  "compiled Functions, or a method of CasADi's, e.g. 'erk'")])
        return cls(functions, n_samples=n_samples, span=span, rtol=settings.rtol, atol=settings.atol,
                   event_tol=settings.event_tol, max_steps=settings.max_steps_per_interval,
                   max_events=settings.max_events_per_revolution, pressure=settings.pressure)

    def __init__(self, functions, *, n_samples: int, span: float, rtol: float, atol: float | None = None,
                 event_tol: float = 1e-10, max_steps: int = 200000, max_events: int = 10000, pressure: str = "steps",
                 loose: float | None = None, quiet: float | None = None, ring: float | None = None,
                 stiff_steps: int | None = None, stiff_hlam: float | None = None):
        """``loose``, ``quiet``, ``ring``: the quiet phase's factors and start (None: the rules of the module
        docstring; a ``ring`` given is used at every rtol, with events located to ``event_tol``)."""
        self._fn = composite_function(functions.library)
        self.n_samples, self.pressure = n_samples, pressure
        self.dth = span / n_samples
        self.grid = self.dth * np.arange(1, n_samples + 1)
        self.rtol, self.atol = float(rtol), float(rtol if atol is None else atol)
        self.max_steps, self.max_events = int(max_steps), int(max_events)
        rule = quiet_factors(self.rtol)
        self.loose = float(rule[0] if loose is None else loose)
        self.quiet = float(rule[1] if quiet is None else quiet)
        quiet_phase = ring is not None or self.rtol >= QUIET_RTOL_MIN
        self.ring = (RING if ring is None else float(ring)) if quiet_phase else math.inf
        self.stiff_steps = (STIFF_STEPS if stiff_steps is None else int(stiff_steps)) if quiet_phase else 0
        self.stiff_hlam = float(STIFF_HLAM if stiff_hlam is None else stiff_hlam)
        self.event_tol = float(event_tol) if quiet_phase else min(float(event_tol), EVENTS_PER_RTOL * self.rtol)
        self.rate = np.ascontiguousarray(declared_scales(functions.state_names)[1], float)
        self.n_u = functions.hybrid_ode.size1_in(3) if functions.hybrid_ode is not None else 4
        self.function = self  # what the run's diagnosis asks for its statistics (stats())
        self._stats: dict = {}
        self._carry: tuple[bytes, float] | None = None  # (the last call's end state, crank angle since its event)

    def reset(self) -> None:
        """Also forget the last call's end state: a new run starts its quiet-phase count from zero."""
        super().reset()
        self._carry = None

    def carried(self, z: np.ndarray) -> np.ndarray | None:
        """[crank angle since the last contact event] at the end of the last call, if it ended in ``z``; else None
        (a call starting from ``z`` begins in the tight phase)."""
        if self._carry is None or self._carry[0] != np.ascontiguousarray(z, float).tobytes():
            return None
        return np.array([self._carry[1]])

    def carry_on(self, z: np.ndarray, carried: np.ndarray | None) -> None:
        """The next call starting from ``z`` carries ``carried`` (see :meth:`carried`; None: it begins in the tight
        phase)."""
        self._carry = None if carried is None else (np.ascontiguousarray(z, float).tobytes(),
                                                    float(np.asarray(carried, float).reshape(-1)[0]))

    def stats(self) -> dict:
        """The statistics of the last call."""
        return dict(self._stats)

    def run(self, z0: np.ndarray, params: np.ndarray, theta0: float, pressures: np.ndarray) -> RevolutionResult:
        """Integrate from the hybrid state z0 at crank angle theta0 (see :class:`.methods.Engine`); ``params`` at
        the intervals' edges (a scene's schedule) go to the C as each interval's lines."""
        z0 = np.ascontiguousarray(z0, float)
        params = np.asarray(params, float)
        lines = None  # the parameters' lines per interval (a scene's schedule), NULL for the C
        if params.ndim == 2:
            params, u_par = parameter_controls(params, self.grid)
            lines = np.ascontiguousarray(u_par.T)
        par = np.ascontiguousarray(np.r_[params, theta0], float)
        U = np.ascontiguousarray(controls(pressures, self.grid, self.pressure, self.n_u).T)
        since = np.array([self._carry[1] if self._carry and self._carry[0] == z0.tobytes() else 0.0])
        Z, phase, st = np.empty((self.n_samples, z0.size)), np.empty(self.n_samples), np.zeros(8, np.int64)
        status = self._fn(_ptr(z0), _ptr(par), _ptr(U), None if lines is None else _ptr(lines), _ptr(self.rate),
                          self.n_samples, self.dth, self.rtol, self.atol, self.loose, self.quiet, self.ring,
                          self.stiff_steps, self.stiff_hlam, self.event_tol, self.max_steps, self.max_events,
                          _ptr(since), _ptr(Z), _ptr(phase), st.ctypes.data_as(_LL))
        tight, quiet, rejected, evals, jacobians, events, given_back, done = (int(v) for v in st)
        self._stats = {"n_steps": tight + quiet, "n_tight_steps": tight, "n_quiet_steps": quiet, "n_reject": rejected,
                       "n_rhs": evals, "n_jac": jacobians, "n_events": events, "n_given_back": given_back,
                       "quiet_share": float(np.mean(phase[:done])) if done else 0.0}
        if status:
            self._carry = None
            why = FAILURES.get(status, f"status {status}").format(max_steps=self.max_steps, max_events=self.max_events)
            raise RuntimeError(f"composite: {why}, after {done} of {self.n_samples} output intervals")
        self._carry = (Z[-1].tobytes(), float(since[0]))
        return RevolutionResult(Z.T.copy(), self.stats())
