"""A wall-time budget inside a run: the pace of its integrator calls, and calls made interval by interval near the end.

The run checks its budget between integrator calls (runtime/solving/run.py). An engine that cannot stop inside a
call (CasADi's erk and rosenbrock, the composite's C, the fixed-step folds: ``Engine.stops_at_deadline`` False)
runs each call to its end, so one call of a stiff stretch could outlast what was left of the budget by the whole
call: its output intervals times ``max_steps_per_interval`` steps (one 10-degree call of erk on a chamber gas at
1e9 Pa took about as long as a 30 s budget, and the run ended a whole call late). As a step-size controller
predicts its next step from the last, :class:`Pace` predicts the next call from the slowest seen so far (seconds
per integrator interval); once that call would end past the deadline, the run makes it, and every call after it,
interval by interval (:class:`IntervalByInterval`), checking the deadline between intervals. A run then overruns
its budget by at most one output interval, itself bounded by ``max_steps_per_interval`` steps; only the first call
has no pace to go by. A run that never comes within a call's time of its deadline makes every call whole, as
before; one that does takes other steps from there (each interval starts the integrator afresh), within its
tolerance, and counts those calls in ``solver_stats["n_calls_split"]``.
"""

from __future__ import annotations

import math
import time

import numpy as np

from .methods import Engine, RevolutionResult, WallTimeExceeded, edge_params, single_interval_engine


class Pace:
    """The slowest pace of a run's integrator calls (s per integrator interval), against its deadline."""

    def __init__(self, deadline: float):
        self.deadline = deadline
        self.rate = 0.0

    def record(self, seconds: float, intervals: int) -> None:
        """A call of ``intervals`` integrator intervals took ``seconds``."""
        if intervals > 0:
            self.rate = max(self.rate, seconds / intervals)

    def would_overrun(self, intervals: int) -> bool:
        """Whether a call of ``intervals`` intervals at the slowest pace seen would end past the deadline."""
        return math.isfinite(self.deadline) and time.perf_counter() + self.rate * intervals > self.deadline


class FailedInterval(RuntimeError):
    """An interval of a call made interval by interval failed; ``partial`` holds the samples of those before it."""

    def __init__(self, err: RuntimeError, partial: np.ndarray):
        super().__init__(str(err))
        self.partial = partial


class IntervalByInterval(Engine):
    """The calls of ``engine`` made one output interval at a time by an engine of one interval of the same method
    (interpreted, as the diagnosis of a failed call makes them: no compiling while the budget runs out), with the
    deadline checked between intervals. Past it :class:`~.methods.WallTimeExceeded` carries the intervals done; a
    failed interval raises :class:`FailedInterval` with those before it."""

    def __init__(self, functions, settings, engine: Engine, dtheta: float, make):
        """``dtheta``: the span of one of ``engine``'s intervals (rad); ``make``: the run's engine factory."""
        self.single = single_interval_engine(functions, settings, dtheta, make)
        self.dtheta = dtheta
        self.n_samples = engine.n_samples
        self.pressure_profiles = engine.pressure_profiles
        self.parameter_profiles = engine.parameter_profiles
        self.compiled = self.single.compiled
        self.counts_steps = self.single.counts_steps

    @property
    def deadline(self) -> float:
        """The single-interval engine's: a signal (which sets it, :mod:`.signals`) stops that too."""
        return self.single.deadline

    @deadline.setter
    def deadline(self, value: float) -> None:
        self.single.deadline = value

    def carried(self, z: np.ndarray) -> np.ndarray | None:
        return self.single.carried(z)

    def carry_on(self, z: np.ndarray, carried: np.ndarray | None) -> None:
        self.single.carry_on(z, carried)

    def run(self, z0: np.ndarray, params: np.ndarray, theta0: float, pressures: np.ndarray) -> RevolutionResult:
        P = np.asarray(pressures, float)
        linear = int(P.shape[1] > self.n_samples)  # the values at the intervals' ends: one column more
        cols, stats, z = [], {"n_calls_split": 1}, z0

        def done() -> np.ndarray:  # the samples of the intervals made so far
            return np.array(cols).T if cols else np.zeros((z0.size, 0))

        for k in range(self.n_samples):
            if time.perf_counter() > self.deadline:
                raise WallTimeExceeded(done())
            try:
                out = self.single.run(z, edge_params(params, k), theta0 + k * self.dtheta, P[:, k:k + 1 + linear])
            except WallTimeExceeded:
                raise WallTimeExceeded(done()) from None
            except RuntimeError as err:
                raise FailedInterval(err, done()) from err
            z = out.z[:, -1]
            cols.append(z.copy())
            for key, v in out.stats.items():
                if key.startswith("n_") and isinstance(v, int | float):
                    stats[key] = stats.get(key, 0) + v
        return RevolutionResult(np.array(cols).T, stats)
