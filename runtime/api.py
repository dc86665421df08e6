"""The Python API: ``simulate(scene)`` and ``Model(scene).rhs(theta, state)``."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .results.result import SimulationResult
from .solving.run import run
from .solving.settings import RunSettings


def model_functions(scene):
    """The SX Functions of a scene's effects and assumptions (cached derivation).

    The integrators embed these and are compiled to C whole (runtime/solving/event_integrator.py), so the
    model library itself need not be compiled here.
    """
    from ..generated.load import load_functions

    return load_functions(scene.effects, scene.assumptions, compiled=False).sx


def settings_of(scene, **overrides) -> RunSettings:
    """RunSettings from the scene's [solver] table, with keyword overrides (None = keep)."""
    s = scene.solver
    base = RunSettings(method=s.method, rtol=s.rtol, atol=s.atol, samples_per_revolution=s.samples_per_revolution,
                       steps_per_revolution=s.euler_steps_per_revolution, event_tol=s.event_tol,
                       max_events_per_revolution=s.max_events_per_revolution, chatter_window=s.chatter_window,
                       chatter_events=s.chatter_events, compile_c=not s.interpreted,
                       flags="quick" if s.compile == "quick" else "optimised")
    return replace(base, **{k: v for k, v in overrides.items() if v is not None})


def simulate(scene, *, revolutions: int | None = None, method: str | None = None, rtol: float | None = None,
             progress: bool = False, functions=None, **settings) -> SimulationResult:
    """Simulate a scene (see :func:`apexseal.load_scene`) and return its :class:`SimulationResult`."""
    functions = functions or model_functions(scene)
    st = settings_of(scene, method=method, rtol=rtol, **settings)
    op = scene.operation
    pressure = scene.pressure.interval_means if scene.effects.chamber_pressure else None
    return run(functions, scene.parameter_vector(), st, theta_start=op.start_angle,
               state0=np.array([getattr(op.initial_state, k) for k in ("x", "y", "phi", "xd", "yd", "phid")], float),
               revolutions=revolutions or op.revolutions, pressure=pressure, until_periodic=op.until_periodic,
               periodic_tol=op.periodic_tol, progress=progress, info={"scene": str(scene.source_path or "default")})


class Model:
    """The seal model of a scene, evaluated pointwise (for checks and small scripts; slow in loops)."""

    def __init__(self, scene, functions=None):
        self.scene = scene
        self.functions = functions or model_functions(scene)
        self.params = scene.parameter_vector()

    def pressures(self, theta: float) -> np.ndarray:
        if not self.scene.effects.chamber_pressure:
            return np.zeros(2)
        return np.asarray(self.scene.pressure.interval_means(np.array([theta, theta + 1e-9])), float)[:, 0]

    def closed(self, theta: float, state) -> np.ndarray:
        """Which contacts are closed (guard < 0), in the order of ``guard_names``."""
        g = np.array(self.functions.guards(theta, np.asarray(state, float), self.params, self.pressures(theta)))
        return g.ravel() < 0

    def rhs(self, theta: float, state) -> np.ndarray:
        """d/dt of the state (x, y, phi, x', y', phi') at crank angle theta, contacts set by their gaps."""
        u = self.pressures(theta)
        return np.array(self.functions.rhs_switched(theta, np.asarray(state, float), self.params, u)).ravel()

    @property
    def guard_names(self) -> tuple[str, ...]:
        return tuple(self.functions.guard_names)
