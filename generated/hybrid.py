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
are the chamber pressures [Pa, Pb], constant over each output interval (``pressure = "steps"``), or,
with ``pressure = "linear"``, [Pa, Pb] at tau = 0 and their slopes d/dtau, so that the pressures are
continuous and linear over each interval: P(tau) = u[:2] + u[2:] tau (see :func:`linear_controls`).
With ``parameters = "linear"`` (a scene that schedules a parameter along the revolution: the spring's preload,
runtime/scenes/schedule.py) the controls go on with the parameter vector's line over the interval, as offsets
from the call's parameters p: p(tau) = p + u_a + u_b tau (:func:`parameter_controls`); the model sees p(tau)
wherever it reads a parameter, in the right-hand side, the zero functions and the transition.
A pressure that jumps at every output interval strikes the stiff metal contacts 3600 times a
revolution; each strike rings at their natural frequency, and resolving that ringing is what costs an
adaptive integrator its steps on the default scene (docs/bench/levers.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from .layout import PARAMETER_PROFILES, PRESSURE_PROFILES, HybridLayout
from .scaling import LENGTH, scaled_rhs, state_scale


@dataclass(frozen=True)
class HybridDae:
    dae: dict
    transition: ca.Function
    layout: HybridLayout


def linear_controls(edge_values: np.ndarray, grid: np.ndarray, what: str = "pressures", rows: int = 2) -> np.ndarray:
    """Controls of the "linear" profile from values at the output edges.

    ``edge_values`` is (rows, n + 1): [Pa, Pb] (or ``what`` else) at tau = 0 and at each of the n output times
    ``grid`` (tau, rad); the result is (2 rows, n): per interval, the intercept at tau = 0 and the slope of the line
    through its two ends.
    """
    P = np.asarray(edge_values, float)
    tau = np.r_[0.0, np.asarray(grid, float)]
    if P.ndim != 2 or P.shape != (rows, tau.size):
        raise ValueError(f"{what}: expected the values at the {tau.size} interval edges, shape ({rows}, {tau.size}), "
                         f"not shape {P.shape}")
    slope = np.diff(P, axis=1) / np.diff(tau)
    return np.vstack([P[:, :-1] - slope * tau[:-1], slope])


def parameter_controls(params: np.ndarray, grid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The parameters of a call and the controls of the "linear" parameter profile that follow the pressures'.

    ``params`` is the parameter vector (n_par,), the same over the call (the controls' offsets are zero), or its
    values at the call's n + 1 interval edges (n_par, n + 1), those at the first edge becoming the call's p.
    Returns ``(p, u)``: u (2 n_par, n) holds per interval the offset from p at tau = 0 and the slope of each
    parameter's line through the interval's ends.
    """
    P = np.asarray(params, float)
    n = np.size(grid)
    if P.ndim == 1:
        return P, np.zeros((2 * P.size, n))
    u = linear_controls(P, grid, "parameters", P.shape[0])
    u[:P.shape[0]] -= P[:, :1]
    return P[:, 0], u


#: the controls the model library's hybrid Functions take (generated/functions.py ``with_hybrid``): the "linear"
#: form, so that one library serves both profiles ("steps" is the line of zero slope: P + 0 tau is P exactly)
LIBRARY_PROFILE = "linear"


def controls(pressures: np.ndarray, grid: np.ndarray, profile: str, rows: int) -> np.ndarray:
    """The pressures' controls u of an integrator call whose DAE takes ``rows`` of them, from the engine's
    ``pressures``: (2, n) interval means for ``profile = "steps"`` (with 4 rows: zero slopes below them),
    (2, n + 1) values at the edges of the n intervals of ``grid`` for "linear" (:func:`linear_controls`)."""
    if profile == "linear":
        return linear_controls(pressures, grid)
    P = np.asarray(pressures, float)
    return P if rows == P.shape[0] else np.vstack([P, np.zeros_like(P)])


#: after an event CasADi's erk and rosenbrock ignore crossings for 10 event_tol (measured); the margin covers it
BLIND_WINDOW = 20
#: names of the hybrid DAE's two Functions in the model library (generated/functions.py)
HYBRID_FUNCTIONS = ("hybrid_ode", "hybrid_zero")


def hybrid_functions(rhs: ca.Function, guards: ca.Function, n_par: int, omega_index: int, *,
                     state_names=None, pressure: str = "steps") -> tuple[ca.Function, ca.Function]:
    """The hybrid DAE's right-hand side and zero functions as SX Functions of ``(t, z, p, u)``.

    ``hybrid_ode(t, z, p, u) -> ode`` is dz/dtau (the scaled state's rate, zero for activations and counts);
    ``hybrid_zero(t, z, p, u) -> zero`` is e_i = (1 - 2 s_i) g_i / l (see the module docstring); ``t`` is the
    crank angle since the start of the call, ``p = [physical parameters, crank angle at the start]``. The station
    compiles both into the model library (with the derivatives the integrators need), and the compiled event
    integrator calls them there.
    """
    lay = HybridLayout.of_functions(rhs, guards)
    z = ca.SX.sym("z", lay.size)
    tau = ca.SX.sym("t")
    p = ca.SX.sym("p", n_par + 1)
    n_u = rhs.size1_in(4)
    u = ca.SX.sym("u", n_u if pressure == "steps" else 2 * n_u)
    P = u if pressure == "steps" else u[:n_u] + u[n_u:] * tau  # the "linear" profile: intercepts, then slopes
    par, theta0 = p[:n_par], p[n_par]
    omega = par[omega_index]
    theta = theta0 + tau
    zs, s = z[lay.x], z[lay.active]
    X = zs * state_scale(omega, state_names)
    xdot = rhs(theta, X, s, par, P)
    ode = ca.vertcat(scaled_rhs(xdot, omega, state_names), ca.SX.zeros(2 * lay.n_g))
    zero = (1 - 2 * s) * guards(theta, X, par, P) / LENGTH
    names = ["t", "z", "p", "u"]
    return (ca.Function(HYBRID_FUNCTIONS[0], [tau, z, p, u], [ode], names, ["ode"]),
            ca.Function(HYBRID_FUNCTIONS[1], [tau, z, p, u], [zero], names, ["zero"]))


def build_hybrid_dae(rhs: ca.Function, guards: ca.Function, n_par: int, omega_index: int, *,
                     event_tol: float = 1e-10, state_names=None, pressure: str = "steps",
                     library=None, parameters: str = "constant") -> HybridDae:
    """The DAE dict and transition Function of the hybrid model (see the module docstring).

    ``event_tol`` (crank angle, rad) is the tolerance the integrator locates events
    to; the transition switches the contacts that cross within ``BLIND_WINDOW`` of it.
    ``pressure`` is one of :data:`PRESSURE_PROFILES`: what the controls u mean; ``parameters`` one of
    :data:`PARAMETER_PROFILES` ("linear": the parameters' lines follow in u, see the module docstring).

    Without ``library`` the DAE is SX: the hybrid Functions built from ``rhs`` and ``guards`` are expanded
    into it, and generating the integrator's C embeds the model. With ``library`` (the pair ``(hybrid_ode,
    hybrid_zero)`` as ``casadi.external`` of the compiled model library, which take the :data:`LIBRARY_PROFILE`
    controls whatever ``pressure`` is: :func:`controls`) the DAE is MX and calls them, so the integrator's C
    declares the library's symbols ``extern`` and links against it (docs/codegen.md).
    """
    if pressure not in PRESSURE_PROFILES:
        raise ValueError(f"pressure = {pressure!r}: expected one of {', '.join(PRESSURE_PROFILES)}")
    if parameters not in PARAMETER_PROFILES:
        raise ValueError(f"parameters = {parameters!r}: expected one of {', '.join(PARAMETER_PROFILES)}")
    lay = HybridLayout.of_functions(rhs, guards)
    n_g = lay.n_g
    ode_fn, zero_fn = library or hybrid_functions(rhs, guards, n_par, omega_index, state_names=state_names,
                                                  pressure=pressure)
    sym = ca.MX if library else ca.SX
    z = sym.sym("z", lay.size)
    tau = sym.sym("tau")
    p = sym.sym("p", n_par + 1)
    n_pu = ode_fn.size1_in(3)  # the pressures' controls
    u = sym.sym("u", n_pu + (2 * n_par if parameters == "linear" else 0))
    pu, pt = u[:n_pu], p
    if parameters == "linear":  # p(tau) = p + u_a + u_b tau (parameter_controls)
        a, b = u[n_pu:n_pu + n_par], u[n_pu + n_par:]
        pt = ca.vertcat(p[:n_par] + a + b * tau, p[n_par])
    ode, zero = ode_fn(tau, z, pt, pu), zero_fn(tau, z, pt, pu)
    dae = {"x": z, "t": tau, "p": p, "u": u, "ode": ode, "zero": zero}

    s, counts = z[lay.active], z[lay.counts]
    idx = sym.sym("index")
    new_s, new_counts = [], []
    # every zero function at the end of the blind window, extrapolated along the motion
    ahead = zero + BLIND_WINDOW * event_tol * ca.jtimes(zero, ca.vertcat(z, tau), ca.vertcat(ode, 1))
    for i in range(n_g):
        switch = ca.logic_or(idx == i, ahead[i] < 0)
        new_s.append(ca.if_else(switch, 1 - s[i], s[i]))
        new_counts.append(counts[i] + switch)
    post = ca.vertcat(z[lay.x], *new_s, *new_counts)
    transition = ca.Function("transition", {"index": idx, "t": tau, "x": z, "p": p, "u": u, "post_x": post},
                             ca.event_in(), ca.event_out())
    return HybridDae(dae, transition, lay)
