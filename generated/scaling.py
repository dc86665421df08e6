"""State scaling and crank angle as the independent variable.

Integrators see every state divided by its scale, differentiated with respect to the crank angle theta
(d/dtheta = (1/w) d/dt). Each scale is declared with the state (derive/submodels/base.py ``State``): the
seal body's are l = 1 µm for x, y and a = 1 mrad for phi, and l w, l w, a w for their rates (``rate=True``),
so the scaled mechanical state is [x/l, y/l, phi/a, x'/(l w), y'/(l w), phi'/(a w)]; a submodel's own states
(chamber masses and energies) have their own fixed scales. Displacements of the seal are micrometres and
milliradians, so the scaled state is of order 1 to 100 and one absolute tolerance serves every component.

``names`` is the state vector's names (``functions.state_names``); without it, the seal body's six.
"""

from __future__ import annotations

from collections.abc import Sequence

import casadi as ca
import numpy as np

from ..derive.names import STATE_NAMES

LENGTH = 1e-6  # m: the seal body's length scale (its declared State scale), for residuals in micrometres


def declared_scales(names: Sequence[str] | None) -> tuple[np.ndarray, np.ndarray]:
    """(scale, rate) of the states ``names`` (the seal's six by default), as their submodels declare them: a
    rate's scale is multiplied by the rotor speed omega (:func:`state_scale`)."""
    from ..derive.submodels.registry import state

    decl = [state(n) for n in (names or STATE_NAMES)]
    return np.array([d.scale for d in decl], float), np.array([d.rate for d in decl], bool)


def state_scale(omega: float | ca.SX, names: Sequence[str] | None = None) -> np.ndarray | ca.SX:
    """Physical state = scale * scaled state (elementwise)."""
    base, rate = declared_scales(names)
    if isinstance(omega, ca.SX | ca.MX):
        return ca.vertcat(*[float(b) * omega if r else float(b) for b, r in zip(base, rate, strict=True)])
    return np.where(rate, base * omega, base)


def to_scaled(state: np.ndarray, omega: float, names: Sequence[str] | None = None) -> np.ndarray:
    sc = state_scale(omega, names)
    return np.asarray(state, float) / (sc[:, None] if np.ndim(state) == 2 else sc)


def to_physical(z: np.ndarray, omega: float, names: Sequence[str] | None = None) -> np.ndarray:
    sc = state_scale(omega, names)
    return np.asarray(z, float) * (sc[:, None] if np.ndim(z) == 2 else sc)


def scaled_rhs(rhs_time: ca.SX, omega: ca.SX, names: Sequence[str] | None = None) -> ca.SX:
    """dz/dtheta from the physical time derivative dX/dt."""
    return rhs_time / (state_scale(omega, names) * omega)
