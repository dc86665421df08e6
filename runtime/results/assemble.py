"""Turn the hybrid states an engine returned into a :class:`~.result.SimulationResult` (outputs evaluated in C).

The run loop assembles one part at a time (a revolution, or what was completed of it), so the cost of a part
does not depend on how long the run is, and a part can be written to disk as soon as it is complete
(runtime/results/folder.py).
"""

from __future__ import annotations

import numpy as np

from ...derive.submodels.registry import guard
from ...generated.layout import HybridLayout
from ...generated.scaling import to_physical
from .result import SimulationResult
from .sampled import outputs_at


def contact_patterns(closed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct columns of ``closed`` (n_guards, n) and, for each sample, the index of its column
    (``np.unique(closed, axis=1, return_inverse=True)``, on the columns packed into integers: 40x faster)."""
    if not closed.size:
        return closed, np.zeros(closed.shape[1], int)
    codes = (closed.astype(np.int64) << np.arange(closed.shape[0], dtype=np.int64)[:, None]).sum(0)
    _, first, which = np.unique(codes, return_index=True, return_inverse=True)
    return closed[:, first], np.ravel(which)


def assemble(functions, params, Z, theta, U, theta_start, omega, scheduled=()) -> SimulationResult:
    """The result of the hybrid states ``Z`` (layout.size, n) at crank angles ``theta`` (n,), absolute, with
    the chamber pressures ``U`` (2, n) in force over the interval that ends at each sample, and the parameters
    ``params`` (n_par,), or (n_par, n) at each sample (a scene's schedule: then each parameter named in
    ``scheduled`` is an output too, by its name, as ``delta_s``).

    Every named output of the model is evaluated at every sample by the model's ``outputs`` Function in one call
    (runtime/results/sampled.py); the guards give the gaps and penetrations.
    """
    lay = HybridLayout.of(functions)
    X = to_physical(Z[lay.x], omega, lay.state_names)
    closed = lay.closed(Z)
    events = Z[lay.counts]
    P = np.asarray(params, float)
    Y, g = outputs_at(functions, theta, X, closed, P, U)
    outputs = {name: Y[i] for i, name in enumerate(functions.output_names)}
    for name in scheduled:  # a scheduled parameter along the samples
        outputs.setdefault(name, P[list(functions.parameter_names).index(name)])
    for i, name in enumerate(functions.guard_names):  # each guard's declared output: a gap, a penetration, ...
        declared = guard(name)
        outputs[declared.output] = declared.sign * g[i]
    if "Pa" not in outputs:  # the chamber gas model gives them as outputs, else they are the input u
        outputs["Pa"], outputs["Pb"] = U[0], U[1]
    patterns, which = contact_patterns(closed)
    labels = [lay.mode(c) for c in patterns.T]  # a few contact cases, many samples
    modes = [labels[i] for i in which]
    return SimulationResult(theta - theta_start, (theta - theta_start) / omega, X, closed, events, outputs,
                            lay.guard_names, modes, info={"state_names": list(lay.state_names)})


def assemble_blocks(functions, params, blocks, thetas, pressures, theta_start, omega, first=None,
                    first_pressures=None, path=None) -> SimulationResult:
    """The part made of the integrator calls ``blocks`` (hybrid states at ``thetas``, with the pressures
    ``pressures`` of each call), after the initial state ``first`` with the pressures ``first_pressures`` (2,) there
    (both given for the first part of a run only); ``path``: the parameters at given crank angles where a scene
    schedules them (None: ``params`` at every sample).
    """
    Z = np.hstack(blocks) if blocks else np.zeros((HybridLayout.of(functions).size, 0))
    theta = np.concatenate(thetas) if thetas else np.zeros(0)
    U = np.hstack(pressures) if pressures else np.zeros((2, 0))
    if first is not None:
        Z = np.c_[first, Z]
        theta = np.r_[theta_start, theta]
        U = np.c_[np.reshape(first_pressures, (2, 1)), U]
    if path is None:
        return assemble(functions, params, Z, theta, U, theta_start, omega)
    return assemble(functions, path(theta), Z, theta, U, theta_start, omega, scheduled=path.names)
