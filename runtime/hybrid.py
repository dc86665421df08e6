"""The hybrid seal model for event-locating integrators (CasADi's erk and rosenbrock).

Within a mode (a set of closed contacts) the right-hand side is smooth. The
integrator's state carries the mode: z = [scaled state (6), activation s_i of each
contact (1 = closed), event count of each contact]. Each contact i has a zero
function e_i = (1 - 2 s_i) g_i / l: positive while the mode is consistent with the
gap g_i, it crosses from + to - exactly when the contact closes (s_i = 0, g_i
falls below 0) or opens (s_i = 1, g_i rises above 0). CasADi's events fire only on
+ to - crossings; this form turns both directions into such a crossing. The
transition toggles s_i and counts the event.

The independent variable is the crank angle since the start of the call; the
parameters are [physical parameters, crank angle at the start]; the controls u
are the chamber pressures [Pa, Pb], constant over each output interval.
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca

from .scaling import LENGTH, scaled_rhs, state_scale


@dataclass(frozen=True)
class HybridDae:
    dae: dict
    transition: ca.Function
    n_guards: int

    @property
    def n_states(self) -> int:
        return 6 + 2 * self.n_guards


def build_hybrid_dae(rhs: ca.Function, guards: ca.Function, n_par: int, omega_index: int) -> HybridDae:
    """The DAE dict and transition Function of the hybrid model (see the module docstring)."""
    n_g = guards.size1_out(0)
    z = ca.SX.sym("z", 6 + 2 * n_g)
    tau = ca.SX.sym("tau")
    p = ca.SX.sym("p", n_par + 1)
    u = ca.SX.sym("u", 2)
    par, theta0 = p[:n_par], p[n_par]
    omega = par[omega_index]
    theta = theta0 + tau
    zs, s = z[:6], z[6:6 + n_g]
    X = zs * state_scale(omega)
    xdot = rhs(theta, X, s, par, u)
    g = guards(theta, X, par, u) / LENGTH
    ode = ca.vertcat(scaled_rhs(xdot, omega), ca.SX.zeros(2 * n_g))
    zero = (1 - 2 * s) * g
    dae = {"x": z, "t": tau, "p": p, "u": u, "ode": ode, "zero": zero}

    idx = ca.SX.sym("index")
    post = ca.SX(z)
    for i in range(n_g):
        hit = idx == i
        post[6 + i] = ca.if_else(hit, 1 - z[6 + i], z[6 + i])
        post[6 + n_g + i] = z[6 + n_g + i] + hit
    transition = ca.Function("transition", {"index": idx, "t": tau, "x": z, "p": p, "u": u, "post_x": post},
                             ca.event_in(), ca.event_out())
    return HybridDae(dae, transition, n_g)
