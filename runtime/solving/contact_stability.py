"""An explicit fixed-step method on the contacts: how much its step amplifies the seal's ringing per revolution.

The seal on its closed contacts is a damped oscillator: its fastest ringing in a contact mode has the eigenvalues
w (-zeta +- i sqrt(1 - zeta^2)), or real ones beyond critical damping. One step of length h of a method with
stability function R (runtime/solving/stability.py) multiplies it by R(h lambda): :func:`contact_growth` says how
much the steps of one revolution in that mode amplify it, and how many steps per revolution keep that below
:data:`MAX_GROWTH`; the preflight refuses a run beyond it, and the run checks name it when a state turns non-finite
(runtime/solving/preflight.py, checks.py). :func:`model_growth` judges every contact mode of the model, with the
frequency and damping ratio of its fastest ringing from the model's Jacobian (runtime/solving/ringing.py,
``mode_damping``): a groove corner pushes at an arm from the centre of gravity and turns the seal too, so that two
corners and the tip closed ring at 5.07e5 rad/s on the default scene, twice one contact's sqrt(k/ms); its damping
ratio grows with it (0.105 against 0.05). Without the model, :func:`contact_growth` judges each penalty contact
alone (stiffness k, damper c, the seal's mass ms: w = sqrt(k/ms), the ringing of a contact that pushes through the
centre of gravity), the estimate of the parameters only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...derive.submodels.damping_rule import DAMPING_LAWS
from ...derive.submodels.registry import dampers, oscillators, parameter_names
from ..scenes.damping import continuous_dampers
from .methods import ExplicitSteps

__all__ = ["MAX_GROWTH", "ContactGrowth", "beyond", "contact_frequencies", "contact_growth", "model_growth"]

#: the most an explicit fixed-step method may amplify a contact's oscillation over one revolution in contact
MAX_GROWTH = 1e3


@dataclass(frozen=True)
class ContactGrowth:
    """How an explicit fixed-step method treats one contact oscillator (stiffness k, damping c, seal mass ms), or
    the fastest ringing of the seal in one contact mode (``contacts``: the contacts closed in it)."""

    name: str  # the stiffness parameter: kw, kg1..kg4, ks; or the mode's label
    k: float  # 0 for a mode
    omega: float  # sqrt(k/ms), or the mode's ringing, rad/s
    zeta: float  # effective damping ratio: half of c / (2 sqrt(k ms)) (on approach only), or the mode's on average
    log_growth: float  # ln of the amplification over one revolution of closed contact
    steps_needed: int  # steps per revolution that keep the growth below MAX_GROWTH
    steps: ExplicitSteps  # the method and the steps per revolution judged
    #: its damper is counted as none: the damping law "penetration" makes it vanish at the touch
    vanishing: bool = False
    #: a damper without a stiffness (k = 0; ``name`` its coefficient, ``omega`` its rate c/ms, 1/s, zeta 1)
    damper: float | None = None
    #: a contact mode: its closed contacts (guard names)
    contacts: tuple[str, ...] | None = None

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
        if self.contacts is not None:
            damping = f"damping ratio {self.zeta:.3g} on average" + (
                f", counting no damper that vanishes at the touch under assumptions.damping_law = {DAMPING_LAWS[1]!r}"
                if self.vanishing else "")
            return (f"{self.steps.subject} amplifies the ringing of the seal in contact mode {self.name} "
                    f"({', '.join(self.contacts)} closed: {self.omega:.3g} rad/s, {damping}) by "
                    f"exp({self.log_growth:.3g}) over one revolution in that mode at {steps} steps per revolution: use "
                    f"at least {self.steps.setting(self.steps_needed)} solver.euler_steps_per_revolution, or method "
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


def _judged(R, n: int, rate: float, zeta: float, omega: float) -> tuple[float, int]:
    """ln of the amplification over one revolution of ``n`` steps of a method of stability function ``R`` on an
    oscillation of frequency ``rate`` (rad/s) and damping ratio ``zeta`` at the rotor speed ``omega``, and the
    fewest steps per revolution that keep it below :data:`MAX_GROWTH`."""
    c_hw = 2 * math.pi * rate / omega  # h w = c_hw / n
    log_growth = n * max(R.log_modulus(c_hw / n * lam) for lam in eigenvalues(zeta))
    return log_growth, fewest_steps(R, c_hw, zeta, math.log(MAX_GROWTH))


def contact_growth(params: np.ndarray, steps_per_revolution: int | ExplicitSteps, names=None,
                   read=None, modes=None) -> list[ContactGrowth]:
    """Stability of an explicit fixed-step method on each contact, or each contact mode, most amplified first.

    ``steps_per_revolution``: the method and its steps (:func:`~.methods.explicit_steps`), or a number of steps
    of explicit Euler. Per step the method multiplies a damped oscillation (frequency w, damping ratio zeta) by
    |R(h lambda)| (:func:`eigenvalues`; the larger of the two above critical damping); for explicit Euler that is
    |1 + h lambda| = sqrt(1 - 2 zeta h w + (h w)^2) below critical damping: it grows unless h w < 2 zeta, and an
    undamped contact always grows. Over the n steps of one revolution the logarithm of the growth is
    n ln |R(h lambda)|.
    ``modes``: the fastest ringing of each contact mode with its damping ratio (runtime/solving/ringing.py,
    ``mode_damping``: :func:`model_growth`), judged instead of the contacts alone. Without them, the contacts are
    the (stiffness, damping) pairs the submodels declare (with ``read``, those whose stiffness the model reads),
    each ringing at sqrt(k/ms); ``names`` are the parameter vector's (default: the registry's). A damper that the
    damping law "penetration" scales by the penetration vanishes at the touch: it is not counted
    (runtime/scenes/damping.py). The dampers without a stiffness are judged alone either way.
    """
    judged = ExplicitSteps.of(steps_per_revolution)
    R = judged.stability
    names = parameter_names() if names is None else names
    p = dict(zip(names, np.asarray(params, float), strict=True))
    n = judged.steps_per_revolution
    vanishing = continuous_dampers(p)
    out = []
    if modes is not None:
        for m in modes:
            log_growth, needed = _judged(R, n, m.rad_s, m.zeta, p["omega"])
            out.append(ContactGrowth(m.mode, 0.0, m.rad_s, m.zeta, log_growth, needed, judged, bool(vanishing),
                                     contacts=m.contacts))
    else:
        for (k_name, c_name), w in zip(_present(oscillators(), p, read),
                                       contact_frequencies(params, names, read).values(), strict=True):
            k, ms = p[k_name], p["ms"]
            damped = c_name in p and (read is None or c_name in read)  # its damping off: undamped
            vanishes = damped and c_name in vanishing  # vanishing at the touch: counted as undamped
            c = p[c_name] if damped and not vanishes else 0.0
            zeta = 0.5 * c / (2 * math.sqrt(k * ms))
            log_growth, needed = _judged(R, n, w, zeta, p["omega"])
            out.append(ContactGrowth(k_name, k, w, zeta, log_growth, needed, judged, vanishes))
    for c_name in (c for c in dampers() if c in p and (read is None or c in read)):
        # -c v alone: the eigenvalue -c/ms, that of a critically damped oscillator of frequency w = c/ms
        rate = p[c_name] / p["ms"]
        log_growth, needed = _judged(R, n, rate, 1.0, p["omega"])
        out.append(ContactGrowth(c_name, 0.0, rate, 1.0, log_growth, needed, judged, damper=p[c_name]))
    return sorted(out, key=lambda g: -g.log_growth)


def model_growth(functions, params, steps_per_revolution: int | ExplicitSteps, theta: float,
                 X) -> list[ContactGrowth]:
    """:func:`contact_growth` of every contact mode of the model ``functions`` whose contacts close together near
    the state ``X`` at crank angle ``theta``, by the frequency and damping ratio of its fastest ringing
    (runtime/solving/ringing.py, ``mode_damping``; a damper that vanishes at the touch counted as none)."""
    from .ringing import mode_damping

    names, read = functions.parameter_names, functions.parameters_read()
    p = dict(zip(names, np.asarray(params, float), strict=True))
    contact_dampers = [c for _, c in _present(oscillators(), p, read) if c in p and c in read]
    modes = mode_damping(functions, params, theta, X, contact_dampers, continuous_dampers(p))
    return contact_growth(params, steps_per_revolution, names, read, modes)


def beyond(growth: list[ContactGrowth], log_limit: float) -> ContactGrowth | None:
    """Of the oscillations ``growth`` amplified beyond exp(``log_limit``) per revolution, the one that needs the most
    steps (None if none is): its advice covers the others, which need fewer (a mode that needs more steps than
    another is amplified more at every step count below them)."""
    over = [g for g in growth if g.log_growth > log_limit]
    return max(over, key=lambda g: g.steps_needed) if over else None
