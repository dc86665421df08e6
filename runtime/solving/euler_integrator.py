"""The paper's method: explicit Euler on the switched right-hand side, fixed step, and its stability.

The engine is :class:`~.fixed_step.FixedStepIntegrator` with the Euler rule
(z_{n+1} = z_n + h f(theta_n, z_n)); this module says how many steps per
revolution keep explicit Euler stable on each contact (:func:`contact_growth`),
which the preflight and the run checks use.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...derive.submodels.registry import oscillators, parameter_names
from ..scenes.damping import continuous_dampers
from .fixed_step import EulerIntegrator

__all__ = ["MAX_GROWTH", "ContactGrowth", "EulerIntegrator", "contact_growth"]

#: the most explicit Euler may amplify a contact's oscillation over one revolution in contact
MAX_GROWTH = 1e3


@dataclass(frozen=True)
class ContactGrowth:
    """How explicit Euler treats one contact oscillator (stiffness k, damping c, seal mass ms)."""

    name: str  # the stiffness parameter: kw, kg1..kg4, ks
    k: float
    omega: float  # sqrt(k/ms), rad/s
    zeta: float  # effective damping ratio: half of c / (2 sqrt(k ms)), the damping acts on approach only
    log_growth: float  # ln of the amplification over one revolution of closed contact
    steps_needed: int  # Euler steps per revolution that keep the growth below MAX_GROWTH

    def describe(self, steps: int) -> str:
        return (f"explicit Euler amplifies the oscillation of the {self.name} contact ({self.name} = {self.k:.3g} N/m, "
                f"sqrt(k/ms) = {self.omega:.3g} rad/s, damping ratio {self.zeta:.3g} on average) by "
                f"exp({self.log_growth:.3g}) over one revolution in contact at {steps} steps per revolution: use at "
                f"least {self.steps_needed} solver.euler_steps_per_revolution, or method 'rosenbrock'")


def contact_frequencies(params: np.ndarray, names=None, read=None) -> dict[str, float]:
    """sqrt(k/ms) of each penalty contact the submodels declare (rad/s), by the name of its stiffness; with
    ``read`` (the parameters the model reads, ``ModelFunctions.parameters_read``), of its contacts only."""
    names = parameter_names() if names is None else names
    p = dict(zip(names, np.asarray(params, float), strict=True))
    return {k_name: math.sqrt(p[k_name] / p["ms"]) for k_name, _ in _present(oscillators(), p, read)}


def _present(pairs, p: dict, read=None) -> list[tuple[str, str]]:
    """The (stiffness, damping) pairs whose stiffness is in the vector (a contact whose effect is off has no
    slot there) and, with ``read``, is read by the model. Its damping may be off (no slot): then undamped."""
    return [(k, c) for k, c in pairs if k in p and (read is None or k in read)]


def contact_growth(params: np.ndarray, steps_per_revolution: int, names=None, read=None) -> list[ContactGrowth]:
    """Stability of explicit Euler on each contact, most amplified first.

    Per step, explicit Euler multiplies a damped oscillation (frequency w, damping
    ratio zeta) by |1 + h lambda| = sqrt(1 - 2 zeta h w + (h w)^2): it grows unless
    h w < 2 zeta, and an undamped contact always grows. Over the n steps of one
    revolution the logarithm of the growth is n/2 ln(1 - 2 zeta h w + (h w)^2).
    The contacts are the (stiffness, damping) pairs the submodels declare (with ``read``, those whose stiffness
    the model reads); ``names`` are the parameter vector's (default: the registry's). A damper that the damping law
    "penetration" scales by the penetration vanishes at the touch: it is not counted (runtime/scenes/damping.py).
    """
    names = parameter_names() if names is None else names
    p = dict(zip(names, np.asarray(params, float), strict=True))
    n = int(steps_per_revolution)
    vanishing = continuous_dampers(p)
    out = []
    for (k_name, c_name), w in zip(_present(oscillators(), p, read), contact_frequencies(params, names, read).values(),
                                   strict=True):
        k, ms = p[k_name], p["ms"]
        # its damping off, or vanishing at the touch: undamped
        c = p[c_name] if c_name in p and (read is None or c_name in read) and c_name not in vanishing else 0.0
        zeta = 0.5 * c / (2 * math.sqrt(k * ms))
        hw = 2 * math.pi * w / (n * p["omega"])
        log_growth = 0.5 * n * math.log1p(hw * hw - 2 * zeta * hw)
        c_hw = 2 * math.pi * w / p["omega"]  # h w = c_hw / n; small h w: log growth ~ (c_hw^2 / n - 2 zeta c_hw) / 2
        needed = math.ceil(c_hw * c_hw / (2 * math.log(MAX_GROWTH) + 2 * zeta * c_hw))
        out.append(ContactGrowth(k_name, k, w, zeta, log_growth, needed))
    return sorted(out, key=lambda g: -g.log_growth)
