"""The paper's method: explicit Euler on the switched right-hand side, fixed step.

Each step evaluates the one Function that covers all modes (the activations
computed from the gaps inside it, if_else) and advances
z_{n+1} = z_n + h f(theta_n, z_n). Steps are chained inside CasADi with ``fold``
(the steps of one output interval) and ``mapaccum`` (the intervals of a
revolution), so a whole revolution is one call, and it compiles to C.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from .scaling import LENGTH, scaled_rhs, state_scale


class EulerIntegrator:
    def __init__(self, rhs_switched: ca.Function, guards: ca.Function, n_par: int, omega_index: int, *,
                 n_samples: int, steps_per_revolution: int, span: float = 2 * np.pi, compile_c: bool = True,
                 flags: str = "optimised"):
        n_g = guards.size1_out(0)
        self.n_g = n_g
        self.n_samples = n_samples
        sub = max(1, int(round(steps_per_revolution / n_samples)))
        self.h = span / (n_samples * sub)
        self.sub = sub
        # accumulated: [theta, z(6)]; per interval: [params, Pa, Pb]
        acc = ca.SX.sym("acc", 7)
        q = ca.SX.sym("q", n_par + 2)
        par, u = q[:n_par], q[n_par:]
        omega = par[omega_index]
        theta, z = acc[0], acc[1:]
        X = z * state_scale(omega)
        znew = z + self.h * scaled_rhs(rhs_switched(theta, X, par, u), omega)
        step = ca.Function("euler_step", [acc, q], [ca.vertcat(theta + self.h, znew)])
        interval = step.fold(sub)  # q repeated for each step of the interval
        a0 = ca.MX.sym("a0", 7)
        Q = ca.MX.sym("Q", n_par + 2, n_samples)
        qi = ca.MX.sym("qi", n_par + 2)
        ai = ca.MX.sym("ai", 7)
        one = ca.Function("one_interval", [ai, qi], [interval(ai, ca.repmat(qi, 1, sub))])
        revolution = one.mapaccum(n_samples)
        A = revolution(a0, Q)
        g = guards.map(n_samples)(A[0, :], A[1:, :] * ca.repmat(state_scale(Q[omega_index, 0]), 1, n_samples),
                                  Q[:n_par, 0], Q[n_par:, :]) / LENGTH
        self.function = ca.Function("apexseal_euler", [a0, Q], [A, g])
        self.compiled = False
        if compile_c:
            from ..generated.compile import compile_function

            compiled = compile_function(self.function, flags=flags)
            self.compiled = compiled is not self.function
            self.function = compiled
        self.stats = {"n_steps": 0}

    def run(self, z0: np.ndarray, params: np.ndarray, theta0: float, pressures: np.ndarray):
        from .event_integrator import RevolutionResult

        n_g = self.n_g
        Q = np.vstack([np.repeat(params[:, None], self.n_samples, axis=1), pressures])
        A, g = self.function(np.r_[theta0, z0[:6]], Q)
        A, g = np.array(A), np.array(g)
        closed = (g < 0).astype(float)
        prev = np.c_[z0[6:6 + n_g], closed[:, :-1]]
        counts = z0[6 + n_g:, None] + np.cumsum(closed != prev, axis=1)
        self.stats = {"n_steps": self.sub * self.n_samples}
        return RevolutionResult(np.vstack([A[1:], closed, counts]), dict(self.stats))
