"""The spring-preload study: the smallest delta_s that keeps the seal tip pressed on the housing.

``optimise_preload(scene, min_force=5.0)`` solves, with IPOPT,

    minimise    delta_s
    subject to  the seal's motion over one revolution is periodic (the machine's steady state), and
                the tip's contact force >= min_force at every check sample of that revolution,

where the motion is the simulator's: the hybrid model of runtime/solving/hybrid.py (contact switches
as events) integrated by CasADi's ``erk`` on the scene's output grid, with the scene's
parameter vector in which delta_s is one entry (and delta_w = ks delta_s / kw, Eq. 9, and Li,
Eq. 12, follow it). The spring presses the seal out with ks (delta_s - travel of s6) (Eqs. 38-39,
with the erratum of docs/paper-check.md); the contact force is kw xs5 + cw max(v, 0) (Eq. 34
and the damping of Eq. 67). runtime/studies/preload/problem.py defines the force measure and the checks.

Formulation (multiple shooting, every choice measured on the default scene, docs/preload.md):

* **Decision variables**: delta_s in mm and the 6 scaled states (runtime/solving/scaling.py) at
  ``nodes`` shooting nodes, each divided by the largest magnitude that component reaches on
  the start trajectory, so every variable is of order 1 (unscaled, IPOPT stops at points
  that violate constraints by a few per cent of their bound, as measured on a probe model).
* **Shooting intervals**: one ``erk`` integrator with events over 360/nodes degrees whose
  output grid is the scene's samples, mapped over the nodes on two threads; its parameters
  are [p(delta_s), crank angle of the node] and its controls the pressure means of the
  samples, exactly as in a simulation. Its sensitivities include those of the event times.
  The whole constraint function and its Jacobian are generated to C and compiled once (cached
  by content: later runs with another ``min_force`` or other windows reuse it).
* **Modes at the nodes**: the contact activations at a node are not decision variables; they
  follow from the node's gaps (closed where the gap is negative), with no derivative. That is
  exact as long as no gap is zero at a node, so the nodes are placed on the sample grid at the
  offset that keeps them farthest from every contact switch of the start trajectory.
* **Constraints**: continuity at every node and periodicity (the last interval ends at the
  first node); the force measure / 10 N >= min_force / 10 N at every check sample (excluded
  samples get no lower bound, so the compiled function does not depend on the windows).
* **Objective**: delta_s in mm (gradient 1: with the L-BFGS Hessian approximation a smaller
  objective scale makes IPOPT crawl, as measured on a probe model).
* **Start**: a feasible periodic trajectory. With the tip lifted off, the force has no
  gradient and IPOPT starting there would sit on a flat, infeasible region; the signed
  measure (-kw x gap in lift-off) has a gradient, but the lift-off pattern changes with every
  bounce, so the start is the periodic simulation at the scene's preload times 1.5^k for the
  smallest k at which every check passes (found with a few mapped simulations).
* **Nodes**: 4 by default (90 deg each). The tip and the groove contacts rattle for ~70 deg
  after the chamber switch at ~182 deg (about 40 switches); a node inside that stretch carries a
  state that depends on rtol-level details of every impact, and its continuity defect could not
  be closed (measured with 8 nodes: IPOPT stalled or declared the problem infeasible with a
  defect of ~1e-3 at the node at 217.5 deg). With 90 deg between nodes every node sits in a
  quiet stretch (the offset rule above) and IPOPT converges (13 iterations at 3600 samples).
* **Tolerances**: IPOPT's tol and constr_viol_tol are 1e-3 (a contact force of 0.01 N, a
  defect of 1e-3 of a state's range): the constraint function is noisy at the erk rtol (1e-6),
  and at tighter tolerances IPOPT keeps iterating on that noise.
* **Which crossing**: the lowest contact force of the ringing after a chamber switch is not
  monotone in delta_s (runtime/studies/preload/bisect.py has the numbers), so the checks pass on a
  union of intervals. Starting above and descending, IPOPT stops at the first crossing below
  the start: the smallest preload from which every larger one (up to the start) passes, which
  is also what keeps sealing when the spring relaxes. Lower passing islands are not sought.

IPOPT uses MUMPS (the only linear solvers in the CasADi wheel are MUMPS and SPRAL) and the
limited-memory Hessian (second derivatives through events would cost ~50 integrations per
iteration). Solutions are accurate to the integrator's tolerance: the adaptive step makes the
constraint function noisy at the level of rtol, so IPOPT's tolerance is set above that.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import asdict, dataclass, field

import casadi as ca
import numpy as np

from ....derive.symbols import PARAMETER_NAMES
from ...solving.scaling import state_scale
from .problem import KW, MM, PreloadSetup, PreloadStudyError

_DS = PARAMETER_NAMES.index("delta_s")
_KS = PARAMETER_NAMES.index("ks")

#: the force measure is divided by this in the constraints (forces are 1..100 N, the defects of order 1)
F_REF = 10.0
#: IPOPT statuses taken as a solution
SOLVED = ("Solve_Succeeded", "Solved_To_Acceptable_Level")


class PreloadStudyFailed(RuntimeError):
    """The study could not give an answer; the message says what failed, where and why."""


@dataclass
class PreloadResult:
    """What the study found. ``delta_s`` is None when it failed (``message`` says why)."""

    ok: bool
    message: str
    min_force: float  # N, the requirement
    exclude_deg: list  # excluded crank-angle windows [(start, end), ...] in degrees
    delta_s: float | None = None  # m, the optimum
    spring_force: float | None = None  # N, ks * delta_s (the spring's force at rest, Eq. 39)
    scene_delta_s: float = 0.0  # m
    friction_power: float | None = None  # W, mean over the periodic revolution at the optimum
    scene_friction_power: float | None = None  # W, at the scene's preload
    min_measure: float | None = None  # N, the smallest contact force at the checks (simulation at the optimum)
    min_measure_angle: float | None = None  # deg, where
    nlp_min_measure: float | None = None  # N, the same in the NLP's own solution
    ipopt_status: str = ""
    ipopt_iterations: int = 0
    ipopt_time_s: float = 0.0
    compile_time_s: float = 0.0
    start_delta_s: float | None = None  # m, the feasible start
    nodes: int = 0
    samples: int = 0
    checks: int = 0
    rtol: float = 0.0
    max_defect: float | None = None  # largest continuity/periodicity defect at the solution (scaled state)
    history: list = field(default_factory=list)  # [(delta_s m, min measure N), ...] of the start search

    def to_dict(self) -> dict:
        return asdict(self)

    def describe(self) -> str:
        if not self.ok:
            return f"preload study failed: {self.message}"
        lines = [
            f"smallest preload delta_s* = {self.delta_s / MM:.4f} mm (spring force ks*delta_s = {self.spring_force:.3f} N; "
            f"scene: {self.scene_delta_s / MM:.4g} mm)",
            f"contact force >= {self.min_force:g} N at {self.checks} of {self.samples} samples per revolution"
            + (f" (excluded: {', '.join(f'{a:g}..{b:g} deg' for a, b in self.exclude_deg)})" if self.exclude_deg else ""),
            f"  smallest contact force at the checks: {self.min_measure:.4f} N at {self.min_measure_angle:.1f} deg "
            f"(simulation at delta_s*; NLP: {self.nlp_min_measure:.4f} N)",
            f"  friction power {self.friction_power:.2f} W at delta_s* vs {self.scene_friction_power:.2f} W at the "
            f"scene's preload ({self.friction_power - self.scene_friction_power:+.2f} W)",
            f"  IPOPT: {self.ipopt_status}, {self.ipopt_iterations} iterations, {self.ipopt_time_s:.1f} s; compile "
            f"{self.compile_time_s:.1f} s; {self.nodes} shooting nodes, erk rtol {self.rtol:g}",
        ]
        return "\n".join(lines)


def optimise_preload(scene, *, min_force: float = 5.0, exclude=(), nodes: int = 4, samples: int | None = None,
                     rtol: float | None = None, functions=None, max_iter: int = 100, revolutions: int = 3,
                     max_preload: float = 0.1, flags: str = "quick", verbose: bool = False,
                     ipopt_options: dict | None = None) -> PreloadResult:
    """Smallest spring preload delta_s (m) keeping the tip's contact force >= ``min_force`` (N) at the checks.

    ``exclude``: crank-angle windows ``(start_deg, end_deg)`` where the force is not checked;
    ``samples``: check samples (= output samples) per revolution, default the scene's;
    ``nodes``: shooting nodes (a divisor of ``samples``); ``max_preload`` (m): the largest
    delta_s tried for a feasible start. See the module docstring for the formulation.
    """
    from ...api import model_functions

    if not (isinstance(nodes, int) and 2 <= nodes <= 64):
        raise PreloadStudyError(f"nodes = {nodes!r}: must be an integer in 2..64")
    exclude = tuple((float(a), float(b)) for a, b in exclude)
    setup = PreloadSetup(scene, functions or model_functions(scene), float(min_force), exclude, samples, rtol,
                         revolutions, flags)
    if setup.samples % nodes:
        raise PreloadStudyError(f"nodes = {nodes}: must divide the {setup.samples} samples per revolution")
    if not (isinstance(max_preload, int | float) and max_preload > 0):
        raise PreloadStudyError(f"max_preload = {max_preload!r}: must be a length > 0 m")
    scene_ds = float(scene.parameter_vector()[_DS])
    res = PreloadResult(False, "", float(min_force), [list(w) for w in exclude], scene_delta_s=scene_ds,
                        nodes=nodes, samples=setup.samples, rtol=setup.rtol)
    keep = setup.mask(setup.theta_start + setup.dth * np.arange(1, setup.samples + 1))
    res.checks = int(keep.sum())
    if not res.checks:
        raise PreloadStudyError(f"exclude = {list(exclude)}: the windows cover every sample; nothing left to check")

    # 1. a feasible start: the periodic simulation at the scene's preload times 1.5^k
    start, per0 = _feasible_start(setup, scene_ds, float(max_preload), res)
    if start is None:
        return res
    res.start_delta_s = float(per0.deltas[0])
    scene_per = setup.periodic([scene_ds])
    res.scene_friction_power = float(scene_per.friction_power[0])

    # 2. the NLP
    nlp = _ShootingNlp(setup, nodes, per0)
    res.compile_time_s = setup.compile_s + nlp.compile_s
    t = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        solver = ca.nlpsol("preload", "ipopt", {"x": nlp.V, "f": nlp.V[0], "g": nlp.g},
                           {"ipopt.hessian_approximation": "limited-memory", "ipopt.tol": 1e-3,
                            "ipopt.constr_viol_tol": 1e-3, "ipopt.acceptable_tol": 1e-2,
                            "ipopt.acceptable_constr_viol_tol": 1e-3, "ipopt.acceptable_iter": 2,
                            "ipopt.max_iter": int(max_iter),
                            "ipopt.linear_solver": "mumps", "ipopt.print_level": 5 if verbose else 0,
                            "print_time": False, "ipopt.sb": "yes",
                            **{f"ipopt.{k}": v for k, v in (ipopt_options or {}).items()}})
        lbx = np.r_[0.0, np.full(nlp.V.numel() - 1, -np.inf)]
        ubx = np.r_[max_preload / MM, np.full(nlp.V.numel() - 1, np.inf)]
        lbg, ubg = nlp.bounds(min_force, keep)
        try:
            sol = solver(x0=nlp.V0, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg)
        except RuntimeError as err:
            res.ipopt_time_s = time.perf_counter() - t
            res.message = (f"IPOPT stopped with an error in the constraint evaluation ({err}); the shooting integrator "
                           "failed at an iterate (a step or event limit): try more nodes or a larger rtol")
            return res
    res.ipopt_time_s = time.perf_counter() - t
    st = solver.stats()
    res.ipopt_status, res.ipopt_iterations = str(st["return_status"]), int(st["iter_count"])
    v = np.array(sol["x"]).ravel()
    g = np.array(sol["g"]).ravel()
    defects, meas = g[:nlp.n_defects], g[nlp.n_defects:] * F_REF
    res.max_defect = float(np.max(np.abs(defects)))
    res.nlp_min_measure = float(meas[nlp.check_order(keep)].min())
    if res.ipopt_status not in SOLVED:
        worst = nlp.describe_violation(defects, meas, min_force, keep)
        res.message = (f"IPOPT returned {res.ipopt_status} after {res.ipopt_iterations} iterations at delta_s = "
                       f"{v[0]:.4g} mm; {worst}. " + _advice(res.ipopt_status))
        return res

    # 3. the answer, checked by a full simulation at the optimum
    ds = float(v[0]) * MM
    per = setup.periodic([ds])
    m, at = setup.min_checked(per)
    res.ok = True
    res.delta_s, res.spring_force = ds, float(setup.pmap(ds)[_KS] * ds)
    res.friction_power = float(per.friction_power[0])
    res.min_measure, res.min_measure_angle = float(m[0]), float(at[0])
    res.compile_time_s = setup.compile_s + nlp.compile_s
    res.message = "solved"
    return res


def _advice(status: str) -> str:
    return {
        "Infeasible_Problem_Detected": "No preload in the allowed range satisfies every check with a periodic motion: "
                                       "lower min_force, exclude the crank-angle windows where the tip lifts off, or "
                                       "raise max_preload.",
        "Maximum_Iterations_Exceeded": "Raise max_iter, or start closer (the start is the feasible simulation).",
        "Restoration_Failed": "The constraints are noisy at the integrator's tolerance: use a smaller rtol.",
        "Error_In_Step_Computation": "The constraints are noisy at the integrator's tolerance: use a smaller rtol.",
    }.get(status, "See IPOPT's documentation of this status.")


def _feasible_start(setup: PreloadSetup, scene_ds: float, max_preload: float, res: PreloadResult):
    """The smallest scene_ds * 1.5^k (k >= 0, up to max_preload) whose periodic revolution passes every check."""
    base = scene_ds if scene_ds > 0 else MM
    k = 0
    while True:
        cands = [base * 1.5 ** (k + i) for i in range(4)]
        cands = [c for c in cands if c <= max_preload * (1 + 1e-12)] or [max_preload]
        per = setup.periodic(cands)
        m, at = setup.min_checked(per)
        res.history += [(float(d), float(v)) for d, v in zip(cands, m, strict=True)]
        ok = np.nonzero(m >= setup.min_force)[0]
        if ok.size:
            i = int(ok[0])
            return cands[i], setup.periodic([cands[i]])
        if cands[-1] >= max_preload * (1 - 1e-12):
            res.message = (f"infeasible: no preload up to max_preload = {max_preload / MM:g} mm keeps the contact "
                           f"force >= {setup.min_force:g} N at every check; at {cands[-1] / MM:.4g} mm it is "
                           f"{m[-1]:.3g} N at crank angle {at[-1]:.1f} deg (negative: the tip lifts off there, by "
                           f"{-m[-1] / setup.pmap.p0[KW] * 1e6:.3g} um). Exclude a window around that angle "
                           "(exclude=[(start, end)] / --exclude START:END), lower min_force, or raise max_preload.")
            return None, None
        k += 4


class _ShootingNlp:
    """The multiple-shooting constraint function g(V), compiled with its Jacobian (see the module docstring)."""

    def __init__(self, setup: PreloadSetup, nodes: int, per0):
        from ....generated.compile import compile_function
        from ...solving.event_integrator import EventIntegrator

        self.setup, self.N = setup, nodes
        m = setup.samples // nodes
        self.m = m
        ng, fn = setup.n_guards, setup.functions
        st = setup.settings()
        Z0 = per0.z[0]  # (n_z, samples + 1), the start's periodic revolution from theta_start
        self.offset = _node_offset(Z0[6:6 + ng], nodes, m)
        idx = self.offset + m * np.arange(nodes)
        theta_nodes = setup.theta_start + setup.dth * idx
        self.theta_nodes = theta_nodes
        S = np.maximum(1.0, np.max(np.abs(Z0[:6]), axis=1))
        self.S = S
        omega = float(setup.pmap.p0[PARAMETER_NAMES.index("omega")])
        sc = state_scale(omega)

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            F = EventIntegrator(fn.rhs, fn.guards, setup.pmap.p0.size, PARAMETER_NAMES.index("omega"), method="erk",
                                rtol=setup.rtol, atol=st.atol, n_samples=m, span=m * setup.dth,
                                max_events=st.max_events_per_revolution, max_steps=st.max_steps_per_interval,
                                event_tol=st.event_tol, compile_c=False).vm
        edges = setup.theta_start + setup.dth * (self.offset + np.arange(setup.samples + 1))
        U = setup.pressures(edges)  # (2, samples), sample j of the rotated revolution
        self.sample_thetas = edges[1:]

        V = ca.MX.sym("V", 1 + 6 * nodes)
        d = V[0] * MM
        p = ca.DM(setup.pmap.p0) + ca.DM(setup.pmap.dp) * d
        W = ca.reshape(V[1:], 6, nodes)
        Z = W * ca.repmat(ca.DM(S), 1, nodes)  # scaled hybrid states at the nodes
        X = Z * ca.repmat(ca.DM(sc), 1, nodes)
        act = []
        for k in range(nodes):
            g_k = fn.guards(theta_nodes[k], X[:, k], p, ca.DM(U[:, k * m]))
            act.append(g_k < 0)  # modes from the gaps, no derivative (nodes are kept away from switches)
        A = ca.horzcat(*act)
        x0 = ca.vertcat(Z, A, ca.MX.zeros(ng, nodes))
        P = ca.vertcat(ca.repmat(p, 1, nodes), ca.DM(theta_nodes).T)
        Fm = F.map(nodes, "thread", 2)
        XF = Fm(x0=x0, p=P, u=ca.DM(U))["xf"]  # (n_z, samples)
        ends = XF[:6, [(k + 1) * m - 1 for k in range(nodes)]]
        nxt = ca.horzcat(*[Z[:, (k + 1) % nodes] for k in range(nodes)])
        defects = ca.vec((ends - nxt) / ca.repmat(ca.DM(S), 1, nodes))
        n = setup.samples
        Xs = XF[:6, :] * ca.repmat(ca.DM(sc), 1, n)
        meas = setup.measure_fn.map(n)(ca.DM(edges[1:]).T, Xs, XF[6:6 + ng, :], ca.repmat(p, 1, n), ca.DM(U))
        G = ca.Function("apexseal_preload_shooting", [V], [ca.vertcat(defects, meas.T / F_REF)], ["V"], ["g"])
        self.n_defects = 6 * nodes
        t = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            self.G = compile_function(G, flags=setup.flags, derivatives=True, model_hash=fn.model_hash)
        self.compile_s = time.perf_counter() - t
        self.V = ca.MX.sym("V", V.numel())
        self.g = self.G(self.V)
        W0 = Z0[:6, idx] / S[:, None]
        self.V0 = np.r_[per0.deltas[0] / MM, W0.ravel(order="F")]

    def check_order(self, keep_abs: np.ndarray) -> np.ndarray:
        """The check mask (given on the grid from theta_start) on the NLP's rotated sample order."""
        return np.roll(keep_abs, -self.offset)

    def bounds(self, min_force: float, keep_abs: np.ndarray):
        keep = self.check_order(keep_abs)
        lbg = np.r_[np.zeros(self.n_defects), np.where(keep, min_force / F_REF, -np.inf)]
        ubg = np.r_[np.zeros(self.n_defects), np.full(keep.size, np.inf)]
        return lbg, ubg

    def describe_violation(self, defects, meas, min_force, keep_abs) -> str:
        keep = self.check_order(keep_abs)
        short = np.where(keep, min_force - meas, -np.inf)
        j = int(np.argmax(short))
        k = int(np.argmax(np.abs(defects))) // 6
        parts = []
        if short[j] > 1e-6 * max(1.0, min_force):
            parts.append(f"the contact force is {meas[j]:.6g} N < {min_force:g} N at crank angle "
                         f"{np.degrees(self.sample_thetas[j]) % 360:.1f} deg")
        if np.abs(defects).max() > 1e-6:
            parts.append(f"the motion is not periodic/continuous at the node at "
                         f"{np.degrees(self.theta_nodes[k]) % 360:.1f} deg (defect {np.abs(defects).max():.3g})")
        return "; ".join(parts) or "every constraint is satisfied to 1e-6 (the optimality test failed)"


def _node_offset(act: np.ndarray, nodes: int, m: int) -> int:
    """The offset (in samples) of the node grid that keeps nodes farthest from every contact switch."""
    n = act.shape[1] - 1
    switches = np.nonzero(np.any(np.abs(np.diff(act, axis=1)) > 0.5, axis=0))[0]  # between sample j and j + 1
    if not switches.size:
        return 0
    best, best_d = 0, -1
    for o in range(m):
        nodes_at = (o + m * np.arange(nodes)) % n
        dist = np.abs(nodes_at[:, None] - switches[None, :] - 0.5)
        dist = np.minimum(dist, n - dist).min()
        if dist > best_d:
            best, best_d = o, dist
    return best
