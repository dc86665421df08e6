"""State scaling and crank angle as the independent variable.

Integrators see z = [x/l, y/l, phi/a, x'/(l w), y'/(l w), phi'/(a w)], with
l = 1 µm and a = 1 mrad, differentiated with respect to the crank angle theta
(d/dtheta = (1/w) d/dt). Displacements of the seal are micrometres and
milliradians, so the scaled state is of order 1 to 100 and one absolute tolerance
serves every component.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

LENGTH = 1e-6  # m
ANGLE = 1e-3  # rad
_Q = np.array([LENGTH, LENGTH, ANGLE])


def state_scale(omega: float | ca.SX) -> np.ndarray | ca.SX:
    """Physical state = scale * scaled state (elementwise)."""
    if isinstance(omega, ca.SX | ca.MX):
        return ca.vertcat(*[float(v) for v in _Q], *[float(v) * omega for v in _Q])
    return np.concatenate([_Q, _Q * omega])


def to_scaled(state: np.ndarray, omega: float) -> np.ndarray:
    return np.asarray(state, float) / state_scale(omega)[:, None] if np.ndim(state) == 2 else \
        np.asarray(state, float) / state_scale(omega)


def to_physical(z: np.ndarray, omega: float) -> np.ndarray:
    sc = state_scale(omega)
    return np.asarray(z, float) * (sc[:, None] if np.ndim(z) == 2 else sc)


def scaled_rhs(rhs_time: ca.SX, omega: ca.SX) -> ca.SX:
    """dz/dtheta from the physical time derivative dX/dt."""
    return rhs_time / (state_scale(omega) * omega)
