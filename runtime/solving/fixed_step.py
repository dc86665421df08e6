"""Fixed-step engines on the switched right-hand side, chained in CasADi and compiled to C.

Each stage evaluates the one Function that covers all modes (``rhs_switched``: the
activations computed from the gaps inside it, ``if_else``); a :class:`StepRule`
turns it into one step z_{n+1} = z_n + h Φ(theta_n, z_n). Steps are chained inside
CasADi with ``fold`` (the steps of one output interval) and ``mapaccum`` (the
intervals of a span), so a whole revolution is one call, and it compiles to C.
Contact switches are not located: a step that straddles one loses the rule's
order. They are counted at every step: the fold carries each contact's state at the
last step's start and its running count of switches, so a contact that closes and
opens within one output interval counts twice, and the count does not depend on how
often the run is sampled. Two rules: explicit (forward) Euler (``solver.method = "euler"``, apexseal's reading
of the paper's "Euler method", Section 1, which does not say which Euler) and classical RK4 (the benchmark's
``rk4-C``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ...generated.layout import HybridLayout
from ...generated.scaling import LENGTH, scaled_rhs, state_scale
from .methods import Engine, RevolutionResult, fixed_steps, run_params


@dataclass(frozen=True)
class StepRule:
    """One explicit step: ``advance(f, theta, z, h)`` is z at theta + h from z at theta (f: dz/dtheta)."""

    name: str
    stages: int  # right-hand-side evaluations per step
    advance: Callable


def _euler(f, theta, z, h):
    return z + h * f(theta, z)


def _rk4(f, theta, z, h):
    k1 = f(theta, z)
    k2 = f(theta + h / 2, z + h / 2 * k1)
    k3 = f(theta + h / 2, z + h / 2 * k2)
    k4 = f(theta + h, z + h * k3)
    return z + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


EULER = StepRule("euler", 1, _euler)
RK4 = StepRule("rk4", 4, _rk4)


class FixedStepIntegrator(Engine):
    """``rule`` on ``rhs_switched`` with ``steps_per_revolution`` equal steps, one compiled call per span."""

    rule: StepRule = EULER
    pressure_profiles = ("steps", "linear")
    parameter_profiles = ("constant", "linear")

    @classmethod
    def build(cls, functions, settings, *, method, n_samples, span, compile_c):
        names = tuple(functions.parameter_names)
        sx = functions.sx()  # the SX set (of compiled Functions too): the fold embeds it
        return cls(sx.rhs_switched, sx.guards, len(names), names.index("omega"), n_samples=n_samples,
                   steps_per_revolution=settings.steps_per_revolution, span=span, compile_c=compile_c,
                   flags=settings.flags, model_hash=sx.model_hash, state_names=functions.state_names,
                   pressure=settings.pressure, parameters=settings.parameters)

    def __init__(self, rhs_switched: ca.Function, guards: ca.Function, n_par: int, omega_index: int, *,
                 n_samples: int, steps_per_revolution: int, span: float = 2 * np.pi, compile_c: bool = True,
                 flags: str = "optimised", model_hash: str | None = None, state_names=None, pressure: str = "steps",
                 parameters: str = "constant"):
        """``parameters = "linear"``: the parameters follow a line over each output interval (a scene's schedule),
        their slopes in the interval's column after theta_k."""
        self.pressure, self.parameters = pressure, parameters
        self.model_hash = model_hash  # the model the fold embeds, as its compiled C's record names it
        self.layout = layout = HybridLayout.sized(rhs_switched.size1_in(1), guards.size1_out(0))
        n_x, n_g = layout.n_x, layout.n_g
        self.n_samples = n_samples
        self.sub = sub = fixed_steps(steps_per_revolution, span / n_samples)  # steps per sample
        self.h = h = span / (n_samples * sub)
        # accumulated: [theta, z (n_x), each contact closed (1) or open (0) at the last step's start, its running
        # count of switches (n_g each)]; per interval: [params at its start theta_k, [Pa, Pb] there, their slopes
        # d/dtheta (zero for the "steps" profile: P + 0 is P exactly), theta_k, and with parameters = "linear" the
        # parameters' slopes d/dtheta]
        n_u = rhs_switched.size1_in(3)
        i_t = n_par + 2 * n_u  # theta_k's row
        n_dp = n_par if parameters == "linear" else 0
        n_q = i_t + 1 + n_dp
        n_a = 1 + n_x + 2 * n_g
        acc = ca.SX.sym("acc", n_a)
        q = ca.SX.sym("q", n_q)
        par, u0, du, theta_k = q[:n_par], q[n_par:n_par + n_u], q[n_par + n_u:i_t], q[i_t]
        omega = par[omega_index]
        sc = state_scale(omega, state_names)

        def par_at(theta):
            return par + q[i_t + 1:] * (theta - theta_k) if n_dp else par

        def f(theta, z):
            return scaled_rhs(rhs_switched(theta, z * sc, par_at(theta), u0 + du * (theta - theta_k)), omega,
                              state_names)

        theta, z, before, count = acc[0], acc[1:1 + n_x], acc[1 + n_x:1 + n_x + n_g], acc[1 + n_x + n_g:]
        closed = guards(theta, z * sc, par_at(theta), u0 + du * (theta - theta_k)) < 0  # as rhs_switched's activations
        out = ca.vertcat(theta + h, self.rule.advance(f, theta, z, h), closed, count + (closed != before))
        step = ca.Function(f"{self.rule.name}_step", [acc, q], [ca.cse(out)])  # the guards share the rhs's gaps
        interval = step.fold(sub)  # q repeated for each step of the interval
        ai, qi = ca.MX.sym("ai", n_a), ca.MX.sym("qi", n_q)
        one = ca.Function("one_interval", [ai, qi], [interval(ai, ca.repmat(qi, 1, sub))])
        a0, Q = ca.MX.sym("a0", n_a), ca.MX.sym("Q", n_q, n_samples)
        A = one.mapaccum(n_samples)(a0, Q)
        past = A[0, :] - Q[i_t, :]  # from each interval's start to its sample
        u_end = Q[n_par:n_par + n_u, :] + Q[n_par + n_u:i_t, :] * ca.repmat(past, n_u, 1)
        p_end = Q[:n_par, :] + Q[i_t + 1:, :] * ca.repmat(past, n_par, 1) if n_dp else Q[:n_par, 0]
        g = guards.map(n_samples)(A[0, :], A[1:1 + n_x, :] * ca.repmat(state_scale(Q[omega_index, 0], state_names),
                                                                       1, n_samples),
                                  p_end, u_end) / LENGTH
        self.vm = self.function = ca.Function(f"apexseal_{self.rule.name}", [a0, Q], [A, g])
        self.compiled = False
        if compile_c:
            from ...generated.compile import compile_function

            compiled = compile_function(self.function, flags=flags, model_hash=model_hash)
            self.compiled = compiled is not self.function
            self.function = compiled
        self.stats = {"n_steps": sub * n_samples, "n_rhs": self.rule.stages * sub * n_samples}

    @classmethod
    def steps_taken(cls, steps_per_revolution: int, dtheta: float) -> int:
        """The fold's steps per revolution: each output interval of ``dtheta`` rad takes its share of
        ``steps_per_revolution``, rounded and at least one (:func:`~.methods.fixed_steps`, the ``sub`` of
        ``__init__``), so a revolution takes more or fewer than asked (asked for 1000 at 720 intervals, 720)."""
        return int(round(2 * np.pi / dtheta)) * fixed_steps(steps_per_revolution, dtheta)

    def run(self, z0: np.ndarray, params: np.ndarray, theta0: float, pressures: np.ndarray) -> RevolutionResult:
        lay = self.layout
        n, dth = self.n_samples, self.h * self.sub
        P = np.asarray(pressures, float)
        slope = np.zeros((P.shape[0], n)) if self.pressure == "steps" else np.diff(P, axis=1) / dth
        params = run_params(params, self.parameters)
        if params.ndim == 1:
            par, dpar = np.repeat(params[:, None], n, axis=1), np.zeros((params.size, n))
        else:  # the values at the edges: each interval's start and slope
            par, dpar = params[:, :n], np.diff(params, axis=1) / dth
        Q = np.vstack([par, P[:, :n], slope, theta0 + dth * np.arange(n)] + ([dpar] if self.parameters == "linear"
                                                                               else []))
        n_x, n_g = lay.n_x, lay.n_g
        A, g = self.function(np.r_[theta0, z0[lay.x], z0[lay.active], np.zeros(n_g)], Q)
        A, g = np.array(A), np.array(g)
        closed = (g < 0).astype(float)
        # the switches counted at the steps' starts, and the one between the last step's start and the sample
        before, steps = A[1 + n_x:1 + n_x + n_g], A[1 + n_x + n_g:]
        counts = z0[lay.counts, None] + steps + (closed != before)
        return RevolutionResult(np.vstack([A[1:1 + n_x], closed, counts]), dict(self.stats))


class EulerIntegrator(FixedStepIntegrator):
    """Explicit (forward) Euler on the switched right-hand side: apexseal's reading of the paper's "Euler method"
    (Section 1). Its stability, as every explicit fixed-step method's: :mod:`.contact_stability`,
    :mod:`.friction_stability` (the negative numerical damping they guard against is explicit Euler's; a
    semi-implicit Euler would behave differently)."""

    rule = EULER


class RK4Integrator(FixedStepIntegrator):
    """Classical RK4 on the switched right-hand side (the benchmark's ``rk4-C``; erk-rk4 locates events instead)."""

    rule = RK4
