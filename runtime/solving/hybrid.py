"""The hybrid seal model for event-locating integrators (CasADi's erk and rosenbrock).

Within a mode (a set of closed contacts) the right-hand side is smooth. The
integrator's state carries the mode: z = [scaled state, activation s_i of each
contact (1 = closed), event count of each contact]. Each contact i has a zero
function e_i = (1 - 2 s_i) g_i / l: positive while the mode is consistent with the
gap g_i, it crosses from + to - exactly when the contact closes (s_i = 0, g_i
falls below 0) or opens (s_i = 1, g_i rises above 0). CasADi's events fire only on
+ to - crossings; this form turns both directions into such a crossing. The
transition toggles s_i and counts the event.

CasADi locates an event to ``event_tol`` and then ignores every crossing in the
next ~10 event_tol (measured with erk and rosenbrock in 3.8.2: a second zero
function crossing 8 event_tol after the first is lost, 12 event_tol after is
found; docs/hard-cases.md). A contact that switches in that window (the seal
pivots: b1 opens as b2 closes) would keep the wrong mode for good, and a contact
left open while its gap is negative lets the seal pass through the wall without
force. So the transition also switches every other contact whose zero function,
extrapolated along the motion to the end of the window, is negative: such a
contact switches at most a window early, never late.

The independent variable is the crank angle since the start of the call; the
parameters are [physical parameters, crank angle at the start]; the controls u
are the chamber pressures [Pa, Pb], constant over each output interval.
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca

from .layout import HybridLayout
from .scaling import LENGTH, scaled_rhs, state_scale


@dataclass(frozen=True)
class HybridDae:
    dae: dict
    transition: ca.Function
    layout: HybridLayout


#: after an event CasADi's erk and rosenbrock ignore crossings for 10 event_tol (measured); the margin covers it
BLIND_WINDOW = 20


def build_hybrid_dae(rhs: ca.Function, guards: ca.Function, n_par: int, omega_index: int, *,
                     event_tol: float = 1e-10, state_names=None) -> HybridDae:
    """The DAE dict and transition Function of the hybrid model (see the module docstring).

    ``event_tol`` (crank angle, rad) is the tolerance the integrator locates events
    to; the transition switches the contacts that cross within ``BLIND_WINDOW`` of it.
    """
    lay = HybridLayout.of_functions(rhs, guards)
    n_g = lay.n_g
    z = ca.SX.sym("z", lay.size)
    tau = ca.SX.sym("tau")
    p = ca.SX.sym("p", n_par + 1)
    u = ca.SX.sym("u", 2)
    par, theta0 = p[:n_par], p[n_par]
    omega = par[omega_index]
    theta = theta0 + tau
    zs, s, counts = z[lay.x], z[lay.active], z[lay.counts]
    X = zs * state_scale(omega, state_names)
    xdot = rhs(theta, X, s, par, u)
    g = guards(theta, X, par, u) / LENGTH
    ode = ca.vertcat(scaled_rhs(xdot, omega, state_names), ca.SX.zeros(2 * n_g))
    zero = (1 - 2 * s) * g
    dae = {"x": z, "t": tau, "p": p, "u": u, "ode": ode, "zero": zero}

    idx = ca.SX.sym("index")
    new_s, new_counts = [], []
    # every zero function at the end of the blind window, extrapolated along the motion
    ahead = zero + BLIND_WINDOW * event_tol * ca.jtimes(zero, ca.vertcat(z, tau), ca.vertcat(ode, 1))
    for i in range(n_g):
        switch = ca.logic_or(idx == i, ahead[i] < 0)
        new_s.append(ca.if_else(switch, 1 - s[i], s[i]))
        new_counts.append(counts[i] + switch)
    post = ca.vertcat(zs, *new_s, *new_counts)
    transition = ca.Function("transition", {"index": idx, "t": tau, "x": z, "p": p, "u": u, "post_x": post},
                             ca.event_in(), ca.event_out())
    return HybridDae(dae, transition, lay)
