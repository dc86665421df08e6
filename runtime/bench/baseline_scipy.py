"""What a user would otherwise write: the derived sympy model through ``sympy.lambdify`` and ``scipy.integrate.solve_ivp``.

The same equations (``derive.cache.cached_model``: mass matrix, forcing, contact
guards), the same scene, initial state and pressure grid as the CasADi methods:

* accelerations ``M^-1 f`` (sympy ``LUsolve``) and the guards are lambdified once
  (``modules="numpy"``, ``cse=True``; without ``cse`` one evaluation costs ~12x
  more, so this is the favourable choice for the baseline);
* contacts switch inside the right-hand side (activation = guard < 0), as a user
  would write it without event location;
* the chamber pressures are the engines' (interval means, or linear between the values at the edges), looked
  up per output interval of the crank angle;
* physical states in time; ``atol = rtol * (1 µm, 1 µm, 1 mrad, and the same
  per 1/omega)``, i.e. the same scaled absolute tolerance as the CasADi methods.

Each run has a CPU budget (enforced by the caller); exceeding it is a recorded failure.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ...derive import symbols as S
from ...generated.scaling import state_scale, to_scaled
from ..solving.methods import RevolutionResult


@dataclass
class LambdifiedModel:
    accelerations: object  # f(theta, x, y, phi, xd, yd, phid, *activations, *params, Pa, Pb) -> (3, 1)
    guards: object  # g(theta, x, ..., phid, *params, Pa, Pb) -> list
    n_guards: int
    setup_s: float  # CPU: sympy LUsolve + lambdify (the model derivation itself is cached and not included)
    derive_s: float  # CPU to load (or derive) the sympy model


def lambdify_model(effects, assumptions, *, cse: bool = True) -> LambdifiedModel:
    import sympy as sp

    from ...derive.cache import cached_model

    c0 = time.process_time()
    m = cached_model(effects, assumptions)
    c1 = time.process_time()
    pars = [S.P[n] for n in S.PARAMETER_NAMES]
    state = [*S.qs, *S.us]
    acc = m.mass_matrix.LUsolve(m.forcing)
    f = sp.lambdify([S.theta, *state, *m.activations.values(), *pars, S.Pa, S.Pb], acc, modules="numpy", cse=cse)
    g = sp.lambdify([S.theta, *state, *pars, S.Pa, S.Pb], list(m.guards.values()), modules="numpy", cse=cse)
    return LambdifiedModel(f, g, len(m.guards), time.process_time() - c1, c1 - c0)


def make_rhs(model: LambdifiedModel, problem):
    """dX/dt(t, X) of the problem in time from the span's start, contacts switched inside, as a user would write."""
    omega, N = problem.omega, problem.samples
    th0, dth = problem.theta0, problem.span / N
    P = problem.pressures
    linear = problem.pressure == "linear"
    pars = [float(v) for v in problem.params]
    f, g = model.accelerations, model.guards

    def rhs(t, X):
        th = th0 + omega * t
        if linear:  # between the values at the interval's ends
            k = min(max(int(np.floor((th - th0) / dth)), 0), N - 1)
            w = (th - th0) / dth - k
            pa, pb = P[0, k] + w * (P[0, k + 1] - P[0, k]), P[1, k] + w * (P[1, k + 1] - P[1, k])
        else:
            k = min(max(int(np.ceil((th - th0) / dth)) - 1, 0), N - 1)  # interval (t_k-1, t_k] holds P[:, k]
            pa, pb = P[0, k], P[1, k]
        act = [1.0 if v < 0 else 0.0 for v in g(th, *X, *pars, pa, pb)]
        return np.r_[X[3:], np.ravel(f(th, *X, *act, *pars, pa, pb))]

    return rhs


def solve(model: LambdifiedModel, problem, method: str, rtol: float) -> RevolutionResult:
    """One span with ``solve_ivp``; returns integrator-like states (scaled state, closed flags, switch counts).

    The caller times it and enforces the CPU budget (``timing.measure``)."""
    try:
        from scipy.integrate import solve_ivp
    except ModuleNotFoundError as exc:  # scipy is only needed for this baseline
        raise ModuleNotFoundError("the scipy baselines need scipy: pip install 'apexseal[bench]'") from exc

    omega, N = problem.omega, problem.samples
    th0, dth = problem.theta0, problem.span / N
    P = problem.sample_pressures
    pars = [float(v) for v in problem.params]
    g = model.guards
    rhs = make_rhs(model, problem)
    T = problem.span / omega
    t_eval = dth * np.arange(1, N + 1) / omega
    t_eval[-1] = T
    atol = rtol * state_scale(omega)
    sol = solve_ivp(rhs, (0.0, T), problem.X0, method=method, t_eval=t_eval, rtol=rtol, atol=atol)
    if sol.status != 0 or sol.y.shape[1] != N:
        raise RuntimeError(f"solve_ivp {method} failed: {sol.message}")
    closed = np.array([[1.0 if v < 0 else 0.0 for v in g(th0 + omega * t, *sol.y[:, i], *pars, P[0, i], P[1, i])]
                       for i, t in enumerate(sol.t)]).T.reshape(model.n_guards, N)
    prev = np.c_[problem.closed0, closed[:, :-1]]
    counts = np.cumsum(closed != prev, axis=1)
    stats = {"n_rhs": int(sol.nfev), "n_jac": int(sol.njev), "n_lu": int(sol.nlu)}
    return RevolutionResult(np.vstack([to_scaled(sol.y, omega), closed, counts]), stats)

