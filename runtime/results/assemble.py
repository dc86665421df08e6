"""Turn the hybrid states an engine returned into a :class:`~.result.SimulationResult` (outputs evaluated in C)."""

from __future__ import annotations

import numpy as np

from ...derive.submodels.registry import guard
from ..solving.layout import HybridLayout
from ..solving.scaling import to_physical
from .result import SimulationResult


def assemble(functions, params, blocks, thetas, pressures, first, theta_start, omega) -> SimulationResult:
    """The result of the blocks of hybrid states ``blocks`` (one per integrator call) after the state ``first``.

    Every named output of the model is evaluated at every sample by the model's ``outputs`` Function, mapped
    over the samples in one call; the guards give the gaps and penetrations.
    """
    lay = HybridLayout.of(functions)
    if blocks:
        Z = np.c_[first, np.hstack(blocks)]
        theta = np.r_[theta_start, np.concatenate(thetas)]
        U = np.hstack(pressures)
    else:
        Z = first[:, None]
        theta = np.array([theta_start])
        U = np.zeros((2, 1))
    U = np.c_[U[:, :1], U]
    X = to_physical(Z[lay.x], omega)
    closed = lay.closed(Z)
    events = Z[lay.counts]
    n = theta.size
    P = np.repeat(params[:, None], n, 1)
    Y = np.array(functions.outputs.map(n)(theta[None, :], X, closed.astype(float), P, U))
    outputs = {name: Y[i] for i, name in enumerate(functions.output_names)}
    g = np.array(functions.guards.map(n)(theta[None, :], X, P, U))
    for i, name in enumerate(functions.guard_names):  # each guard's declared output: a gap, a penetration, ...
        declared = guard(name)
        outputs[declared.output] = declared.sign * g[i]
    outputs["Pa"], outputs["Pb"] = U[0], U[1]
    modes = [lay.mode(closed[:, i]) for i in range(n)]
    return SimulationResult(theta - theta_start, (theta - theta_start) / omega, X, closed, events, outputs,
                            lay.guard_names, modes)
