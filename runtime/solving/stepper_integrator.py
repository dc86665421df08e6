"""Mode switching located by apexseal itself, for integrators without usable events.

CVODES and IDAS events are fragile in CasADi 3.8 (they need a dense output grid
and IDAS misses crossings), and ``rk``/``collocation`` have none. Here the mode
is a parameter: one integrator call advances one output interval with the mode
fixed; afterwards the zero functions e_i = (1 - 2 s_i) g_i are checked, and if
one went negative its crossing is located by the Illinois (regula falsi) method on
the interval length, to ``event_tol`` in crank angle. The integrator runs on a
normalised interval (sigma in [0, 1], length H a parameter), so one integrator
serves every interval length. The zero functions are checked on a sub-grid of
each call (``check_step`` in crank angle, 0.05 deg by default: a housing-contact
bounce lasts about 1 deg at 1500 rpm), so a contact that closes and opens again
inside one output interval is not missed.

Limits, so that a call always ends: ``max_steps`` integrator steps per output
interval (shared by its sub-grid calls), ``max_events`` switches per call, and a
wall-clock ``deadline`` (``time.perf_counter()`` value, set by the caller) checked
after every integrator call; past it, :class:`WallTimeExceeded` carries the samples
finished so far.
"""

from __future__ import annotations

import math
import time
import warnings

import casadi as ca
import numpy as np

from ...generated.layout import HybridLayout
from ...generated.scaling import LENGTH, scaled_rhs, state_scale
from .methods import METHODS, Engine, RevolutionResult, WallTimeExceeded, fixed_steps, run_params

#: zero-function values this far below 0 (in µm) are integration noise, not a crossing
_NOISE = 1e-9
#: the sub-grid on which the zero functions are checked (crank angle, rad; see the module docstring)
CHECK_STEP = np.radians(0.05)


class StepperIntegrator(Engine):
    """One integrator call per output interval with the mode fixed; switches located by apexseal (see above)."""

    pressure_profiles = ("steps", "linear")
    parameter_profiles = ("constant", "linear")
    stops_at_deadline = True

    @classmethod
    def build(cls, functions, settings, *, method, n_samples, span, compile_c):
        names = tuple(functions.parameter_names)
        return cls(functions.rhs, functions.guards, len(names), names.index("omega"), method=method,
                   rtol=settings.rtol, atol=settings.atol, n_samples=n_samples, span=span,
                   steps_per_revolution=settings.steps_per_revolution, event_tol=settings.event_tol,
                   max_events=settings.max_events_per_revolution, max_steps=settings.max_steps_per_interval,
                   state_names=functions.state_names, pressure=settings.pressure, parameters=settings.parameters)

    def __init__(self, rhs: ca.Function, guards: ca.Function, n_par: int, omega_index: int, *, method: str,
                 rtol: float, atol: float | None, n_samples: int, span: float = 2 * np.pi, steps_per_revolution: int = 20000,
                 event_tol: float = 1e-9, max_events: int = 10000, max_steps: int = 200000,
                 check_step: float = CHECK_STEP, state_names=None, pressure: str = "steps",
                 parameters: str = "constant"):
        """``parameters = "linear"``: the parameters follow a line over each output interval too (a scene's
        schedule): the call's vector carries their slopes after the pressures'."""
        plugin = METHODS[method].plugin
        self.pressure, self.parameters = pressure, parameters
        self.layout = layout = HybridLayout.of_functions(rhs, guards)
        n_x, n_g = layout.n_x, layout.n_g
        self.n_samples = n_samples
        self.dtheta = span / n_samples
        self.event_tol = event_tol
        self.max_events = max_events
        # MX, so that compiled (external) right-hand sides can be used as well as SX ones
        z = ca.MX.sym("z", n_x)
        sigma = ca.MX.sym("sigma")
        n_u = rhs.size1_in(4)
        # params, activations, theta0, H, the pressures [Pa, Pb] at theta0 and their slopes d/dtheta (zero for
        # the "steps" profile: P + 0 is P exactly), and with parameters = "linear" the parameters' slopes d/dtheta
        i_u = n_par + n_g + 2
        n_dp = n_par if parameters == "linear" else 0
        P = ca.MX.sym("P", i_u + 2 * n_u + n_dp)
        par, act = P[:n_par], P[n_par:n_par + n_g]
        theta0, H, u0, du = P[n_par + n_g], P[n_par + n_g + 1], P[i_u:i_u + n_u], P[i_u + n_u:i_u + 2 * n_u]
        omega = par[omega_index]
        theta = theta0 + sigma * H
        X = z * state_scale(omega, state_names)
        par_t = par + P[i_u + 2 * n_u:] * (sigma * H) if n_dp else par  # the parameters along the call
        ode = H * scaled_rhs(rhs(theta, X, act, par_t, u0 + du * (sigma * H)), omega, state_names)
        dae = {"x": z, "t": sigma, "p": P, "ode": ode}
        opts: dict = {}
        self.elements = None  # fixed-step methods: finite elements per output interval
        if plugin in ("cvodes", "idas"):
            opts = {"reltol": rtol, "abstol": atol if atol is not None else rtol, "max_num_steps": int(max_steps)}
            if method == "cvodes-adams":
                opts["linear_multistep_method"] = "adams"
                opts["nonlinear_solver_iteration"] = "functional"
        else:  # fixed steps: the interval is cut into equal elements of about the revolution's step
            self.elements = fixed_steps(steps_per_revolution, self.dtheta)
            opts = {"number_of_finite_elements": self.elements}
            if plugin == "collocation":  # Newton on the scaled state: its default 1e-12 is below the round-off floor
                opts["rootfinder_options"] = {"abstol": 1e-10, "abstolStep": 1e-10}
        opts["show_eval_warnings"] = False  # a NaN tried inside a failing step is reported once, by the run
        m = self.check_points(self.dtheta, check_step)
        self.sub = np.linspace(0.0, 1.0, m + 1)[1:]
        if "max_num_steps" in opts:  # CVODES counts per call: share the interval's steps among its sub-grid points
            opts["max_num_steps"] = max(1000, int(max_steps) // m)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            F = ca.integrator("apexseal_" + method.replace("-", "_"), plugin, dae, 0.0, self.sub, opts)
        zs = ca.MX.sym("z", n_x)
        Pm = ca.MX.sym("P", P.size1())
        Z = F(x0=zs, p=Pm)["xf"]  # n_x x m, at the sub-grid
        h_sub = Pm[n_par + n_g + 1] * ca.DM(self.sub).T
        theta_sub = Pm[n_par + n_g] + h_sub
        Xs = Z * ca.repmat(state_scale(Pm[omega_index], state_names), 1, m)
        u_sub = ca.repmat(Pm[i_u:i_u + n_u], 1, m) + Pm[i_u + n_u:i_u + 2 * n_u] @ h_sub
        p_sub = ca.repmat(Pm[:n_par], 1, m) + (Pm[i_u + 2 * n_u:] @ h_sub if n_dp else 0)
        g = guards.map(m)(theta_sub, Xs, p_sub, u_sub) / LENGTH
        e = ca.repmat(1 - 2 * Pm[n_par:n_par + n_g], 1, m) * g
        self.step = ca.Function("step", [zs, Pm], [Z, e])
        X0 = zs * state_scale(Pm[omega_index], state_names)
        g0 = guards(Pm[n_par + n_g], X0, Pm[:n_par], Pm[i_u:i_u + n_u]) / LENGTH
        self.zero = ca.Function("zero", [zs, Pm], [(1 - 2 * Pm[n_par:n_par + n_g]) * g0])
        self.integrator = F
        self.n_par = n_par
        self.stats = {"n_calls": 0, "n_events": 0}
        self.deadline = math.inf  # time.perf_counter() value past which a call stops (set by the caller)
        self._done = layout.empty()

    @staticmethod
    def check_points(dtheta: float, check_step: float = CHECK_STEP) -> int:
        """The points of the sub-grid of an output interval of ``dtheta`` rad (its end included)."""
        return max(1, int(np.ceil(dtheta / check_step)))

    @classmethod
    def steps_taken(cls, steps_per_revolution: int, dtheta: float) -> int:
        """rk: the integrator's output grid is the check sub-grid, m points per output interval, and CasADi's
        fixed-step integrators put ceil(elements / m) equal steps between consecutive output points (elements:
        the interval's share of ``steps_per_revolution``, :func:`~.methods.fixed_steps`): at least m steps per
        output interval, more than asked where the sub-grid is finer than the steps. 2 pi over the longest step."""
        m = cls.check_points(dtheta)
        return int(round(2 * np.pi / dtheta)) * m * math.ceil(fixed_steps(steps_per_revolution, dtheta) / m)

    def _vector(self, line, act, theta0, H):
        """The call's parameter vector from theta0 over H on the interval's line ``(theta_k, P_k, slope_k, p_k,
        dp_k)``: the parameters at theta0, the activations, theta0, H, the pressures at theta0 and their slopes, and
        (parameters = "linear") the parameters' slopes."""
        t_k, P_k, slope, p_k, dp_k = line
        v = np.r_[p_k + dp_k * (theta0 - t_k), act, theta0, H, P_k + slope * (theta0 - t_k), slope]
        return np.r_[v, dp_k] if self.parameters == "linear" else v

    def _advance_all(self, z, act, theta0, H, line):
        """States and zero functions at the sub-grid points of [theta0, theta0 + H] (inputs on ``line``)."""
        if time.perf_counter() > self.deadline:
            raise WallTimeExceeded(self._done)
        self.stats["n_calls"] += 1
        Z, e = self.step(z, self._vector(line, act, theta0, H))
        return np.array(Z), np.array(e)

    def _advance(self, z, act, theta0, H, line):
        Z, e = self._advance_all(z, act, theta0, H, line)
        return Z[:, -1], e[:, -1]

    def _locate(self, z, act, theta0, H, line, i, e0, e1) -> float:
        """Illinois method on h in (0, H] for the crossing of zero function i (e0 > 0 >= e1)."""
        a, b, fa, fb = 0.0, H, e0, e1
        side = 0
        while b - a > self.event_tol:
            c = (a * fb - b * fa) / (fb - fa) if fb != fa else 0.5 * (a + b)
            if not a < c < b:
                c = 0.5 * (a + b)
            _, ec = self._advance(z, act, theta0, c, line)
            fc = ec[i]
            if fc > 0:
                a, fa = c, fc
                if side == -1:
                    fb *= 0.5
                side = -1
            else:
                b, fb = c, fc
                if side == 1:
                    fa *= 0.5
                side = 1
        return b

    def _line(self, pressures: np.ndarray, params: np.ndarray, k: int, t_k: float):
        """Interval k's inputs as lines ``(theta_k, P at theta_k, slope, params at theta_k, slope)``: the pressures'
        mean and zero slope (``pressure = "steps"``, ``pressures`` (2, n_samples)), or through the values at its
        ends ("linear", (2, n_samples + 1)); the parameter vector and zero slope, or through its values at the ends
        (``params`` (n_par, n_samples + 1), a scene's schedule)."""
        if params.ndim == 1:
            p_k, dp_k = params, np.zeros_like(params)
        else:
            p_k, dp_k = params[:, k], (params[:, k + 1] - params[:, k]) / self.dtheta
        if self.pressure == "steps":
            P = pressures[:, k]
            return t_k, P, np.zeros_like(P), p_k, dp_k
        return t_k, pressures[:, k], (pressures[:, k + 1] - pressures[:, k]) / self.dtheta, p_k, dp_k

    def run(self, z0: np.ndarray, params: np.ndarray, theta0: float, pressures: np.ndarray):
        """See :class:`~.methods.Engine`: hybrid states (:mod:`.layout`) at each sample."""
        lay = self.layout
        params = run_params(params, self.parameters)
        self.stats = {"n_calls": 0, "n_events": 0}
        z = np.array(z0[lay.x], float)
        act = np.array(z0[lay.active], float)
        counts = np.array(z0[lay.counts], float)
        out = np.empty((lay.size, self.n_samples))
        self._done = out[:, :0]
        events_here = 0
        for k in range(self.n_samples):
            t = theta0 + k * self.dtheta
            left = self.dtheta
            line = self._line(pressures, params, k, t)
            e_start = np.array(self.zero(z, self._vector(line, act, t, 0.0))).ravel()
            while True:
                Z, E = self._advance_all(z, act, t, left, line)
                below = E < -_NOISE  # a zero function below 0: the mode no longer fits the gap
                cols = np.nonzero(below.any(axis=0))[0]
                if cols.size == 0:
                    z = Z[:, -1]
                    break
                j = cols[0]  # first sub-grid point past a crossing: bracket [sub[j-1], sub[j]]
                h_lo = 0.0 if j == 0 else self.sub[j - 1] * left
                z_lo, e_lo = (z, e_start) if j == 0 else (Z[:, j - 1], E[:, j - 1])
                fired = np.nonzero(below[:, j])[0]
                hits = {i: h_lo + self._locate(z_lo, act, t + h_lo, self.sub[j] * left - h_lo, line, i,
                                               max(e_lo[i], 0.0), E[i, j]) for i in fired}
                i = min(hits, key=hits.get)
                h = hits[i]
                z_new, e_new = self._advance(z, act, t, h, line)
                nudge = self.event_tol
                while e_new[i] > 0 and h + nudge < left:  # land just past the crossing, never before it
                    h += nudge
                    nudge *= 2
                    z_new, e_new = self._advance(z, act, t, h, line)
                z, e_start = z_new, e_new
                act[i] = 1 - act[i]
                counts[i] += 1
                e_start[i] = -e_start[i]
                events_here += 1
                self.stats["n_events"] += 1
                if events_here > self.max_events:
                    raise RuntimeError(f"more than max_events = {self.max_events} events")
                t += h
                left -= h
                if left <= self.event_tol:
                    break
            out[:, k] = lay.pack(z, act, counts)
            self._done = out[:, :k + 1]
        return RevolutionResult(out, dict(self.stats))
