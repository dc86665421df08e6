"""The paper's method: explicit Euler on the switched right-hand side, fixed step.

Each step evaluates the one Function that covers all modes (the activations
computed from the gaps inside it, if_else) and advances
z_{n+1} = z_n + h f(theta_n, z_n). Steps are chained inside CasADi with ``fold``
(the steps of one output interval) and ``mapaccum`` (the intervals of a
revolution), so a whole revolution is one call, and it compiles to C.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ...derive.submodels.registry import oscillators, parameter_names
from .layout import HybridLayout
from .methods import Engine, RevolutionResult, fixed_steps
from .scaling import LENGTH, scaled_rhs, state_scale

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


def contact_frequencies(params: np.ndarray, names=None) -> dict[str, float]:
    """sqrt(k/ms) of each penalty contact the submodels declare (rad/s), by the name of its stiffness."""
    names = parameter_names() if names is None else names
    p = dict(zip(names, np.asarray(params, float), strict=True))
    return {k_name: math.sqrt(p[k_name] / p["ms"]) for k_name, _ in oscillators()}


def contact_growth(params: np.ndarray, steps_per_revolution: int, names=None) -> list[ContactGrowth]:
    """Stability of explicit Euler on each contact, most amplified first.

    Per step, explicit Euler multiplies a damped oscillation (frequency w, damping
    ratio zeta) by |1 + h lambda| = sqrt(1 - 2 zeta h w + (h w)^2): it grows unless
    h w < 2 zeta, and an undamped contact always grows. Over the n steps of one
    revolution the logarithm of the growth is n/2 ln(1 - 2 zeta h w + (h w)^2).
    The contacts are the (stiffness, damping) pairs the submodels declare; ``names`` are the parameter
    vector's (default: the registry's).
    """
    names = parameter_names() if names is None else names
    p = dict(zip(names, np.asarray(params, float), strict=True))
    n = int(steps_per_revolution)
    out = []
    for (k_name, c_name), w in zip(oscillators(), contact_frequencies(params, names).values(), strict=True):
        k, c, ms = p[k_name], p[c_name], p["ms"]
        zeta = 0.5 * c / (2 * math.sqrt(k * ms))
        hw = 2 * math.pi * w / (n * p["omega"])
        log_growth = 0.5 * n * math.log1p(hw * hw - 2 * zeta * hw)
        c_hw = 2 * math.pi * w / p["omega"]  # h w = c_hw / n; small h w: log growth ~ (c_hw^2 / n - 2 zeta c_hw) / 2
        needed = math.ceil(c_hw * c_hw / (2 * math.log(MAX_GROWTH) + 2 * zeta * c_hw))
        out.append(ContactGrowth(k_name, k, w, zeta, log_growth, needed))
    return sorted(out, key=lambda g: -g.log_growth)


class EulerIntegrator(Engine):
    """The paper's explicit Euler on the switched right-hand side, chained in C with ``fold``/``mapaccum``."""

    @classmethod
    def build(cls, functions, settings, *, method, n_samples, span, compile_c):
        names = tuple(functions.parameter_names)
        return cls(functions.rhs_switched, functions.guards, len(names), names.index("omega"), n_samples=n_samples,
                   steps_per_revolution=settings.steps_per_revolution, span=span, compile_c=compile_c,
                   flags=settings.flags)

    def __init__(self, rhs_switched: ca.Function, guards: ca.Function, n_par: int, omega_index: int, *,
                 n_samples: int, steps_per_revolution: int, span: float = 2 * np.pi, compile_c: bool = True,
                 flags: str = "optimised"):
        self.layout = layout = HybridLayout.sized(rhs_switched.size1_in(1), guards.size1_out(0))
        n_x = layout.n_x
        self.n_samples = n_samples
        sub = fixed_steps(steps_per_revolution, span / n_samples)  # steps per sample
        self.h = span / (n_samples * sub)
        self.sub = sub
        # accumulated: [theta, z (n_x)]; per interval: [params, Pa, Pb]
        acc = ca.SX.sym("acc", 1 + n_x)
        q = ca.SX.sym("q", n_par + 2)
        par, u = q[:n_par], q[n_par:]
        omega = par[omega_index]
        theta, z = acc[0], acc[1:]
        X = z * state_scale(omega)
        znew = z + self.h * scaled_rhs(rhs_switched(theta, X, par, u), omega)
        step = ca.Function("euler_step", [acc, q], [ca.vertcat(theta + self.h, znew)])
        interval = step.fold(sub)  # q repeated for each step of the interval
        a0 = ca.MX.sym("a0", 1 + n_x)
        Q = ca.MX.sym("Q", n_par + 2, n_samples)
        qi = ca.MX.sym("qi", n_par + 2)
        ai = ca.MX.sym("ai", 1 + n_x)
        one = ca.Function("one_interval", [ai, qi], [interval(ai, ca.repmat(qi, 1, sub))])
        revolution = one.mapaccum(n_samples)
        A = revolution(a0, Q)
        g = guards.map(n_samples)(A[0, :], A[1:, :] * ca.repmat(state_scale(Q[omega_index, 0]), 1, n_samples),
                                  Q[:n_par, 0], Q[n_par:, :]) / LENGTH
        self.function = ca.Function("apexseal_euler", [a0, Q], [A, g])
        self.compiled = False
        if compile_c:
            from ...generated.compile import compile_function

            compiled = compile_function(self.function, flags=flags)
            self.compiled = compiled is not self.function
            self.function = compiled
        self.stats = {"n_steps": 0}

    def run(self, z0: np.ndarray, params: np.ndarray, theta0: float, pressures: np.ndarray) -> RevolutionResult:
        lay = self.layout
        Q = np.vstack([np.repeat(params[:, None], self.n_samples, axis=1), pressures])
        A, g = self.function(np.r_[theta0, z0[lay.x]], Q)
        A, g = np.array(A), np.array(g)
        closed = (g < 0).astype(float)
        prev = np.c_[z0[lay.active], closed[:, :-1]]
        counts = z0[lay.counts, None] + np.cumsum(closed != prev, axis=1)
        self.stats = {"n_steps": self.sub * self.n_samples}
        return RevolutionResult(np.vstack([A[1:], closed, counts]), dict(self.stats))
