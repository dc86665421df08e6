"""An explicit fixed-step method on each contact: how much its step amplifies the contact's oscillation per revolution.

Each penalty contact the submodels declare is a damped oscillator (stiffness k, damping c, the seal's mass ms): its
eigenvalues are w (-zeta +- i sqrt(1 - zeta^2)), w = sqrt(k/ms), or real beyond critical damping. One step of length
h of a method with stability function R (runtime/solving/stability.py) multiplies each mode by R(h lambda):
:func:`contact_growth` says how much the steps of one revolution in contact amplify it, and how many steps per
revolution keep that below :data:`MAX_GROWTH`; the preflight refuses a run beyond it, and the run checks name it
when a state turns non-finite (runtime/solving/preflight.py, checks.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...derive.submodels.damping_rule import DAMPING_LAWS
from ...derive.submodels.registry import dampers, oscillators, parameter_names
from ..scenes.damping import continuous_dampers
from .methods import ExplicitSteps

__all__ = ["MAX_GROWTH", "ContactGrowth", "contact_frequencies", "contact_growth"]

#: the most an explicit fixed-step method may amplify a contact's oscillation over one revolution in contact
MAX_GROWTH = 1e3


@dataclass(frozen=True)
class ContactGrowth:
    """How an explicit fixed-step method treats one contact oscillator (stiffness k, damping c, seal mass ms)."""

    name: str  # the stiffness parameter: kw, kg1..kg4, ks
    k: float
    omega: float  # sqrt(k/ms), rad/s
    zeta: float  # effective damping ratio: half of c / (2 sqrt(k ms)), the damping acts on approach only
    log_growth: float  # ln of the amplification over one revolution of closed contact
    steps_needed: int  # steps per revolution that keep the growth below MAX_GROWTH
    steps: ExplicitSteps  # the method and the steps per revolution judged
    #: its damper is counted as none: the damping law "penetration" makes it vanish at the touch
    vanishing: bool = False
    #: a damper without a stiffness (k = 0; ``name`` its coefficient, ``omega`` its rate c/ms, 1/s, zeta 1)
    damper: float | None = None

    def describe(self, steps: int | None = None) -> str:
        """The message, at ``steps`` per revolution (default: those judged)."""
        steps = self.steps.steps_per_revolution if steps is None else steps
        if self.damper is not None:
            return (f"{self.steps.subject} amplifies the motion the {self.name} damper damps ({self.name} = "
                    f"{self.damper:.3g} N*s/m, no stiffness of its own: the motion decays at the rate c/ms = "
                    f"{self.omega:.3g} 1/s, which a step beyond 2 ms/c overshoots) by exp({self.log_growth:.3g}) over "
                    f"one revolution at {steps} steps per revolution: use at least "
                    f"{self.steps.setting(self.steps_needed)} solver.euler_steps_per_revolution, or method "
                    "'rosenbrock'")
        damping = (f"undamped: under assumptions.damping_law = {DAMPING_LAWS[1]!r} its damper vanishes at the touch"
                   if self.vanishing else f"damping ratio {self.zeta:.3g} on average")
        return (f"{self.steps.subject} amplifies the oscillation of the {self.name} contact ({self.name} = {self.k:.3g} "
                f"N/m, sqrt(k/ms) = {self.omega:.3g} rad/s, {damping}) by "
                f"exp({self.log_growth:.3g}) over one revolution in contact at {steps} steps per revolution: use at "
                f"least {self.steps.setting(self.steps_needed)} solver.euler_steps_per_revolution, or method "
                "'rosenbrock'")


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


def eigenvalues(zeta: float) -> tuple[complex, ...]:
    """The eigenvalues of a damped oscillator per unit of its frequency w: -zeta + i sqrt(1 - zeta^2) (with its
    conjugate, which R treats alike) below critical damping, the two real -zeta +- sqrt(zeta^2 - 1) above."""
    if zeta < 1:
        return (complex(-zeta, math.sqrt(1 - zeta * zeta)),)
    s = math.sqrt(zeta * zeta - 1)
    return (complex(-zeta - s), complex(-zeta + s))


def fewest_steps(stability, c_hw: float, zeta: float, log_max: float) -> int:
    """The fewest steps n per revolution at which n/2 (|R(c_hw lambda / n)|^2 - 1) <= ``log_max`` for each
    eigenvalue lambda (:func:`eigenvalues`): ln |R|^2 = ln(1 + x) taken as x, so that for explicit Euler below
    critical damping this is n >= c_hw^2 / (2 log_max + 2 zeta c_hw) (``c_hw`` = h w n, the step times the
    frequency times the steps). Found by bisection, which takes the bound to hold for every n above the fewest: so
    it does for Euler's and RK4's R (their stability regions meet each ray from 0 in one segment), and far beyond it
    the step tends to the true decay."""
    def ok(n: int) -> bool:
        return all(n / 2 * stability.growth_excess(c_hw * lam / n) <= log_max for lam in eigenvalues(zeta))

    hi = 1
    while not ok(hi):
        hi *= 2
    lo = hi // 2  # fails (or 0)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if ok(mid) else (mid, hi)
    return hi


def contact_growth(params: np.ndarray, steps_per_revolution: int | ExplicitSteps, names=None,
                   read=None) -> list[ContactGrowth]:
    """Stability of an explicit fixed-step method on each contact, most amplified first.

    ``steps_per_revolution``: the method and its steps (:func:`~.methods.explicit_steps`), or a number of steps
    of explicit Euler. Per step the method multiplies a damped oscillation (frequency w, damping ratio zeta) by
    |R(h lambda)| (:func:`eigenvalues`; the larger of the two above critical damping); for explicit Euler that is
    |1 + h lambda| = sqrt(1 - 2 zeta h w + (h w)^2) below critical damping: it grows unless h w < 2 zeta, and an
    undamped contact always grows. Over the n steps of one revolution the logarithm of the growth is
    n ln |R(h lambda)|.
    The contacts are the (stiffness, damping) pairs the submodels declare (with ``read``, those whose stiffness
    the model reads); ``names`` are the parameter vector's (default: the registry's). A damper that the damping law
    "penetration" scales by the penetration vanishes at the touch: it is not counted (runtime/scenes/damping.py).
    """
    judged = ExplicitSteps.of(steps_per_revolution)
    R = judged.stability
    names = parameter_names() if names is None else names
    p = dict(zip(names, np.asarray(params, float), strict=True))
    n = judged.steps_per_revolution
    vanishing = continuous_dampers(p)
    out = []
    for (k_name, c_name), w in zip(_present(oscillators(), p, read), contact_frequencies(params, names, read).values(),
                                   strict=True):
        k, ms = p[k_name], p["ms"]
        damped = c_name in p and (read is None or c_name in read)  # its damping off: undamped
        vanishes = damped and c_name in vanishing  # vanishing at the touch: counted as undamped
        c = p[c_name] if damped and not vanishes else 0.0
        zeta = 0.5 * c / (2 * math.sqrt(k * ms))
        c_hw = 2 * math.pi * w / p["omega"]  # h w = c_hw / n
        log_growth = n * max(R.log_modulus(c_hw / n * lam) for lam in eigenvalues(zeta))
        needed = fewest_steps(R, c_hw, zeta, math.log(MAX_GROWTH))
        out.append(ContactGrowth(k_name, k, w, zeta, log_growth, needed, judged, vanishes))
    for c_name in (c for c in dampers() if c in p and (read is None or c in read)):
        # -c v alone: the eigenvalue -c/ms, that of a critically damped oscillator of frequency w = c/ms
        rate = p[c_name] / p["ms"]
        c_hw = 2 * math.pi * rate / p["omega"]
        log_growth = n * max(R.log_modulus(c_hw / n * lam) for lam in eigenvalues(1.0))
        needed = fewest_steps(R, c_hw, 1.0, math.log(MAX_GROWTH))
        out.append(ContactGrowth(c_name, 0.0, rate, 1.0, log_growth, needed, judged, damper=p[c_name]))
    return sorted(out, key=lambda g: -g.log_growth)
