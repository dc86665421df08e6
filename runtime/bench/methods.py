"""Engines for the CasADi methods of the benchmark, built once and shared by every scene of the same model.

An engine integrates one span from ``z0`` (``run(z0, params, theta0, pressures)``);
parameters are inputs, so the default and the stiff scene share every engine (and
every compiled library). Event and stepper methods come from the runtime
(``runtime.simulate.make_engine``), the switched-RHS RK4 from the runtime's fixed-step engine
(runtime/solving/fixed_step.py) with the RK4 rule.
"""

from __future__ import annotations

import math
import time

from ..solving.fixed_step import RK4Integrator
from ..solving.methods import make_engine
from ..solving.settings import DEFAULT_PRESSURE, LIMITS, RunSettings
from .compile_pool import CompileTarget
from .config import MethodSpec


def settings_for(spec: MethodSpec, value: float, *, samples: int, span: float, flags: str, compiled: bool,
                 event_tol: float | None = None, pressure: str = DEFAULT_PRESSURE) -> RunSettings:
    """RunSettings for one point (steps are per revolution, whatever the span)."""
    steps = int(value)
    kw = {"event_tol": event_tol} if event_tol is not None else {}
    # the engine covers ``samples`` intervals of ``span``; the settings' per-revolution count is that density
    per_revolution = max(MIN_SAMPLES, int(round(samples * 2 * math.pi / span)))
    method = RK4Integrator if spec.kind == "rk4" else spec.method  # rk4-C: the fixed-step engine's RK4 rule
    return RunSettings(method=method, rtol=float(value) if spec.sweep == "rtol" else 1e-6,
                       steps_per_revolution=steps if spec.sweep == "steps" else RunSettings().steps_per_revolution,
                       # a method on the model library's C (the composite) has it whether or not its engine compiles
                       samples_per_revolution=per_revolution, compile_c=compiled or spec.model_c, flags=flags,
                       pressure=pressure, **kw)


#: the fewest output samples per revolution a run allows (runtime/solving/settings.py)
MIN_SAMPLES = int(LIMITS["samples_per_revolution"][1].ge)


def build_engine(functions, spec: MethodSpec, value: float, *, samples: int, span: float, flags: str, compiled: bool,
                 event_tol: float | None = None, pressure: str = DEFAULT_PRESSURE):
    st = settings_for(spec, value, samples=samples, span=span, flags=flags, compiled=compiled, event_tol=event_tol,
                      pressure=pressure)
    return make_engine(functions, st, n_samples=samples, span=span)


def compile_target(engine) -> CompileTarget | None:
    """What compiling this engine would generate to C, with the model and library its record names (None: nothing
    to compile)."""
    fn = getattr(engine, "vm", None) or getattr(engine, "function", None)
    return None if fn is None else CompileTarget(fn, engine.model_hash, getattr(engine, "link", None))


def normalise_stats(raw: dict, source: str) -> dict:
    """steps / rhs evaluations / events / rejected steps / Jacobians / integrator calls, where known."""
    names = {"n_steps": "steps", "n_rhs": "rhs_evaluations", "n_events": "events", "n_reject": "rejected_steps",
             "n_jac": "jacobians", "n_calls": "integrator_calls"}
    out = {v: int(raw[k]) for k, v in names.items() if k in raw and isinstance(raw[k], int | float)}
    out["source"] = source
    return out


class EngineCache:
    """Engines keyed by (model, method, setting, compiled, grid); also records their build times."""

    def __init__(self, *, samples: int, span: float, flags: str, pressure: str = DEFAULT_PRESSURE):
        self.samples, self.span, self.flags, self.pressure = samples, span, flags, pressure
        self._engines: dict = {}
        self.build_s: dict = {}

    def key(self, model: str, spec: MethodSpec, value: float, compiled: bool, event_tol=None):
        return (model, spec.kind, spec.method, spec.sweep, float(value), compiled, event_tol)

    def get(self, model: str, functions, spec: MethodSpec, value: float, *, compiled: bool, event_tol=None):
        k = self.key(model, spec, value, compiled, event_tol)
        if k not in self._engines:
            w0 = time.perf_counter()
            self._engines[k] = build_engine(functions, spec, value, samples=self.samples, span=self.span,
                                            flags=self.flags, compiled=compiled, event_tol=event_tol,
                                            pressure=self.pressure)
            self.build_s[k] = time.perf_counter() - w0
        return self._engines[k]


    def reference(self, model: str, functions, rtol: float, event_tol: float, *, compiled: bool = True):
        """The reference engine: erk at ``rtol`` with events located to ``event_tol``."""
        from .config import METHODS

        return self.get(model, functions, METHODS["erk-C"], rtol, compiled=compiled, event_tol=event_tol)

    def settle(self, model: str, functions, rtol: float, event_tol: float):
        """Engine and settings for settling with the reference method, whole revolutions of ``samples`` each."""
        per_revolution = self.samples * math.ceil(MIN_SAMPLES / self.samples)  # a multiple of the engine's samples
        st = RunSettings(method="erk", rtol=rtol, samples_per_revolution=per_revolution, flags=self.flags,
                         event_tol=event_tol, pressure=self.pressure)
        if math.isclose(self.span, 2 * math.pi):
            return self.reference(model, functions, rtol, event_tol), st
        return make_engine(functions, st), st
