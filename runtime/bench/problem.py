"""The benchmark problem: one span (a revolution) of a scene from a settled state, on a fixed output grid.

The chamber pressures enter every integrator as constants per output interval
(their exact interval means), so the output grid is part of the problem: every
method, the reference and the scipy baseline use the same ``samples`` intervals.

With ``pressure = "linear"`` (the run setting of runtime/solving/settings.py) the pressures are instead
linear over each interval between their values at its ends, continuous: the engine input is (2, samples + 1).

"Settled start": ``settle_revolutions`` revolutions are run from the scene's
initial state (at its start angle) with the reference method; the state at the
start of the last of them is the benchmark's initial state (x, y, phi and speeds,
plus which contacts are closed there), saved into the results.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ...derive.effects import Effects
from ...derive.names import STATE_NAMES
from ...generated.scaling import to_scaled
from ..solving.preflight import initial_activations
from ..solving.run import RunSettings, run
from ..solving.settings import DEFAULT_PRESSURE


@dataclass
class Problem:
    name: str
    scene: object  # runtime.scene.Scene
    effects: Effects
    functions: object  # ModelFunctions (SX)
    params: np.ndarray
    samples: int
    span: float  # rad
    theta0: float
    X0: np.ndarray  # physical state (6,)
    closed0: np.ndarray  # (n_guards,) 1.0 = closed
    settle: dict = field(default_factory=dict)
    pressure: str = DEFAULT_PRESSURE  # "steps" (interval means) or "linear" (values at the edges, linear in between)

    @property
    def omega(self) -> float:
        return float(self.params[tuple(self.functions.parameter_names).index("omega")])

    @property
    def n_guards(self) -> int:
        return self.functions.guards.size1_out(0)

    @property
    def edges(self) -> np.ndarray:
        return self.theta0 + self.span / self.samples * np.arange(self.samples + 1)

    @property
    def theta(self) -> np.ndarray:
        """Crank angles of the output samples (ends of the intervals)."""
        return self.edges[1:]

    @property
    def pressures(self) -> np.ndarray:
        """The engines' pressure input: (2, samples) [Pa, Pb] held over each output interval, or with
        ``pressure = "linear"`` (2, samples + 1), their values at the interval edges (zeros without chamber
        pressure)."""
        linear = self.pressure == "linear"
        if not self.effects.chamber_pressure:
            return np.zeros((2, self.samples + linear))
        if linear:
            return np.asarray(self.scene.pressure(self.edges), float)
        return np.asarray(self.scene.pressure.interval_means(self.edges), float)

    @property
    def sample_pressures(self) -> np.ndarray:
        """(2, samples): the pressures the model sees at each output sample (for its outputs there)."""
        P = self.pressures
        return P[:, 1:] if self.pressure == "linear" else P

    @property
    def z0(self) -> np.ndarray:
        """Initial integrator state: scaled state, activations, zero event counts."""
        return np.r_[to_scaled(self.X0, self.omega), self.closed0, np.zeros(self.n_guards)]

    def describe(self) -> dict:
        return {"name": self.name, "effects": self.effects.label, "samples": self.samples,
                "span_deg": float(np.degrees(self.span)), "theta0_rad": self.theta0,
                "initial_state": dict(zip(STATE_NAMES, map(float, self.X0), strict=True)),
                "initial_closed": dict(zip(self.functions.guard_names, map(bool, self.closed0 > 0.5), strict=True)),
                "settle": self.settle, "guards": list(self.functions.guard_names),
                "pressure_grid": f"{self.samples} intervals over {np.degrees(self.span):g} deg, "
                                 + ("linear between the values at the edges" if self.pressure == "linear"
                                    else "interval means")}


def make_problem(name: str, scene, effects: Effects, functions, *, samples: int, span: float, settle_revolutions: int,
                 settle_engine=None, settle_settings: RunSettings | None = None,
                 pressure_profile: str = DEFAULT_PRESSURE) -> Problem:
    """Settle the scene (``settle_revolutions`` revolutions with ``settle_engine``) and build the problem."""
    params = scene.parameter_vector(tuple(functions.parameter_names))  # the effects' own vector
    op = scene.operation
    X = np.array([getattr(op.initial_state, k) for k in STATE_NAMES], float)
    theta = float(op.start_angle)
    info: dict = {"revolutions": settle_revolutions, "from": "scene initial state", "start_angle_rad": theta}
    pressure = scene.pressure if effects.chamber_pressure else None  # the source: means and values
    if settle_revolutions > 0:
        c0 = time.process_time()
        res = run(functions, params, settle_settings, theta_start=theta, state0=X, revolutions=settle_revolutions,
                  pressure=pressure, engine=settle_engine)
        info.update(method=settle_settings.method, rtol=settle_settings.rtol, status=res.status,
                    cpu_s=time.process_time() - c0)
        if not res.ok:
            raise RuntimeError(f"settling {name} failed: {res.stop.describe() if res.stop else res.status}")
        i = (settle_revolutions - 1) * settle_settings.samples_per_revolution
        X, theta = res.state[:, i].copy(), theta + float(res.theta[i])
        closed = res.closed[:, i].astype(float)
    else:
        first = np.array([theta, theta + span / samples])  # as the run starts: the value at theta, or the mean
        u0 = (np.zeros(2) if pressure is None else np.asarray(
            pressure(first) if pressure_profile == "linear" else pressure.interval_means(first), float)[:, 0])
        closed = initial_activations(functions, theta, X, params, u0)
    return Problem(name, scene, effects, functions, params, samples, span, theta, X, closed, info, pressure_profile)


def load_model(effects: Effects, assumptions):
    """The model's SX Functions (derived, or from the derivation cache) and how long that took."""
    from ...derive.cache import cache_dir, derivation_key
    from ...generated.load import load_functions

    cached = (cache_dir() / "derive" / f"{derivation_key(effects, assumptions)}.pkl").exists()
    c0, w0 = time.process_time(), time.perf_counter()
    functions = load_functions(effects, assumptions, compiled=False).sx
    return functions, {"derive_cached": cached, "derive_cpu_s": time.process_time() - c0,
                       "derive_wall_s": time.perf_counter() - w0}
