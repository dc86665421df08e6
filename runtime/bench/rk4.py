"""Classical fixed-step RK4 on the switched right-hand side, chained in CasADi and compiled to C.

The same construction as the paper's Euler (runtime/solving/euler_integrator.py): each
stage evaluates ``rhs_switched`` (activations from the gaps inside the Function),
the steps of an output interval are a ``fold``, the intervals of a revolution a
``mapaccum``, so one revolution is one call of one compiled Function. Contact
switches are not located: a step that straddles one loses RK4's order, which the
diagram shows next to erk-rk4 (the same RK4 with events located on its dense
output).
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from ..solving.methods import RevolutionResult
from ..solving.scaling import LENGTH, scaled_rhs, state_scale


class RK4Integrator:
    """``run(z0, params, theta0, pressures)`` like the runtime's engines; ``steps`` per ``span``."""

    def __init__(self, rhs_switched: ca.Function, guards: ca.Function, n_par: int, omega_index: int, *,
                 n_samples: int, steps: int, span: float = 2 * np.pi, compile_c: bool = True, flags: str = "optimised"):
        n_g = guards.size1_out(0)
        self.n_g, self.n_samples = n_g, n_samples
        self.sub = max(1, int(round(steps / n_samples)))
        h = span / (n_samples * self.sub)
        acc = ca.SX.sym("acc", 7)  # [theta, z(6)]
        q = ca.SX.sym("q", n_par + 2)  # [params, Pa, Pb]
        par, u = q[:n_par], q[n_par:]
        omega = par[omega_index]
        sc = state_scale(omega)

        def f(theta, z):
            return scaled_rhs(rhs_switched(theta, z * sc, par, u), omega)

        theta, z = acc[0], acc[1:]
        k1 = f(theta, z)
        k2 = f(theta + h / 2, z + h / 2 * k1)
        k3 = f(theta + h / 2, z + h / 2 * k2)
        k4 = f(theta + h, z + h * k3)
        step = ca.Function("rk4_step", [acc, q], [ca.vertcat(theta + h, z + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4))])
        interval = step.fold(self.sub)
        ai, qi = ca.MX.sym("ai", 7), ca.MX.sym("qi", n_par + 2)
        one = ca.Function("one_interval", [ai, qi], [interval(ai, ca.repmat(qi, 1, self.sub))])
        a0, Q = ca.MX.sym("a0", 7), ca.MX.sym("Q", n_par + 2, n_samples)
        A = one.mapaccum(n_samples)(a0, Q)
        Xs = A[1:, :] * ca.repmat(state_scale(Q[omega_index, 0]), 1, n_samples)
        g = guards.map(n_samples)(A[0, :], Xs, Q[:n_par, 0], Q[n_par:, :]) / LENGTH
        self.function = ca.Function("apexseal_bench_rk4", [a0, Q], [A, g])
        self.vm = self.function
        self.compiled = False
        if compile_c:
            from ...generated.compile import compile_function

            compiled = compile_function(self.function, flags=flags)
            self.compiled = compiled is not self.function
            self.function = compiled
        self.stats = {"n_steps": self.sub * n_samples, "n_rhs": 4 * self.sub * n_samples}

    def run(self, z0: np.ndarray, params: np.ndarray, theta0: float, pressures: np.ndarray) -> RevolutionResult:
        n_g = self.n_g
        Q = np.vstack([np.repeat(params[:, None], self.n_samples, axis=1), pressures])
        A, g = self.function(np.r_[theta0, z0[:6]], Q)
        A, g = np.array(A), np.array(g)
        closed = (g < 0).astype(float)
        prev = np.c_[z0[6:6 + n_g], closed[:, :-1]]
        counts = z0[6 + n_g:, None] + np.cumsum(closed != prev, axis=1)
        return RevolutionResult(np.vstack([A[1:], closed, counts]), dict(self.stats))
