"""The multiple-shooting NLP of the preload study (runtime/studies/preload/study.py): decision variables, the
hand-assembled Jacobian of the shooting intervals, IPOPT, and its iterations as progress lines."""

from __future__ import annotations

import time
import warnings

import casadi as ca
import numpy as np

from ....cores import parallel_threads
from ....generated.scaling import state_scale
from ....progress import announce
from .problem import MM
from .schedule import SegmentGrid, chain_function
from .shooting import CHUNK, TWO_PI

#: IPOPT statuses taken as a solution
SOLVED = ("Solve_Succeeded", "Solved_To_Acceptable_Level")
#: IPOPT's constr_viol_tol: an iterate within it of every constraint's bounds is feasible (also what
#: _Progress.keep_if_feasible keeps)
CONSTR_VIOL_TOL = 1e-3
#: IPOPT's filter accepts no iterate whose constraint violation exceeds this times max(1, the start's) (its option
#: theta_max_fact; the deficit rows count in units of their bound) in the second solve of a study whose first one
#: ended at its iteration limit from a start where every bounded quadrature is 0 (study.py). IPOPT's default, 1e4,
#: let the lift-off scene's first step go from such a start, where the deficit's gradient is 0 too, to 6980 x the
#: bound, deep in lift-off, where it stayed for 100 iterations; with 10 the line search shortens that step and
#: IPOPT converges in 8 iterations (docs/preload.md, "The lift-off scene")
THETA_MAX_FACT = 10.0
#: the first solve from such a start is given up once its force deficit (or groove-force excess) has stayed above
#: THETA_MAX_FACT times its bound for this many iterations in a row, where the bounded filter never lets an iterate
#: go: it is then solved again bounded at once instead of at its iteration limit (the lift-off scene's first solve
#: spent its 100 iterations there, and a user's own design most of its study's time the same way)
STUCK_ITERATIONS = 25


def _advice(status: str, groove: bool = False, gave_up: bool = False) -> str:
    if status == "Infeasible_Problem_Detected" and groove:
        return ("No preload in the allowed range keeps the force deficit and the groove-force excess within their "
                "bound with a periodic motion: raise max_groove_force (the groove forces between samples can exceed "
                "those at the samples), lower min_force, or try a schedule (--schedule).")
    return {
        "Infeasible_Problem_Detected": "No preload in the allowed range keeps the force deficit within its bound with a "
                                       "periodic motion: lower min_force, exclude the crank-angle windows where the tip "
                                       "lifts off, raise max_preload (--max-preload) or, from Python, "
                                       "deficit_tol.",
        "Maximum_Iterations_Exceeded": "Raise max_iter (--max-iter); the bisection over full simulations "
                                       "(--check, bisect_preload) needs no derivative.",
        "User_Requested_Stop": (f"It stayed beyond {THETA_MAX_FACT:g} x the force-deficit bound for "
                                f"{STUCK_ITERATIONS} iterations (deep in lift-off); the bisection over full "
                                "simulations (--check, bisect_preload) needs no derivative." if gave_up else
                                "It was stopped (a signal, or its callback)."),
        "Restoration_Failed": "The constraints are noisy at the integrator's tolerance: use a smaller rtol.",
        "Error_In_Step_Computation": "The constraints are noisy at the integrator's tolerance: use a smaller rtol.",
    }.get(status, "See IPOPT's documentation of this status.")


class _Progress(ca.Callback):
    """IPOPT's iterations as progress lines (objective, constraint violation), and the best feasible iterate so far
    kept in the result as IPOPT visits it (:meth:`keep_if_feasible`): what a study interrupted during IPOPT's
    iterations reports."""

    def __init__(self, nx: int, ng: int, n_def: int, groove: bool = False, give_up: bool = False, *, res=None,
                 knots: int = 1, bounds=None, tol: float = 1e-3, deficit_tol: float = 1.0):
        ca.Callback.__init__(self)
        self.nx, self.ng, self.k, self.n_def, self.groove = nx, ng, 0, n_def, groove
        #: where the best feasible iterate is kept (a PreloadResult's ``best_feasible``), the knots among the
        #: variables, the constraints' bounds (lbg, ubg), IPOPT's constr_viol_tol and the deficit rows' unit
        self.res, self.knots, self.bounds, self.tol, self.deficit_tol = res, knots, bounds, tol, deficit_tol
        #: stop IPOPT once it has stayed :data:`STUCK_ITERATIONS` iterations beyond the bounded filter's reach
        self.give_up, self.beyond, self.gave_up = give_up, 0, False
        self.construct("preload_progress", {})

    def get_n_in(self):
        return ca.nlpsol_n_out()

    def get_n_out(self):
        return 1

    def get_name_in(self, i):
        return ca.nlpsol_out(i)

    def get_name_out(self, i):
        return "ret"

    def get_sparsity_in(self, i):
        n = ca.nlpsol_out(i)
        if n in ("f",):
            return ca.Sparsity.dense(1)
        if n in ("lam_p",):
            return ca.Sparsity.dense(0)
        if n in ("g", "lam_g"):
            return ca.Sparsity.dense(self.ng)
        return ca.Sparsity.dense(self.nx)

    def eval(self, arg):
        """One line per IPOPT iteration, numbered as IPOPT counts them (0: the starting point), so the last number
        is the result's iteration count."""
        g = np.array(arg[2]).ravel()
        groove = f", groove-force excess {g[self.n_def + 1]:.3g} x its bound" if self.groove else ""
        announce(f"  IPOPT iteration {self.k}{' (the start)' if self.k == 0 else ''}: objective {float(arg[1]):.6g}, "
                 f"force deficit {g[self.n_def]:.3g} x its "
                 f"bound{groove}, largest node defect {np.abs(g[:self.n_def]).max():.2g}")
        self.keep_if_feasible(np.array(arg[0]).ravel(), float(arg[1]), g)
        self.k += 1
        bounded = g[self.n_def:self.n_def + (2 if self.groove else 1)]
        self.beyond = self.beyond + 1 if np.max(bounded) > THETA_MAX_FACT else 0
        if self.give_up and self.beyond >= STUCK_ITERATIONS:  # IPOPT ends with User_Requested_Stop
            self.gave_up = True
            announce(f"  IPOPT has stayed above {THETA_MAX_FACT:g} x the bound for {STUCK_ITERATIONS} iterations, "
                     "where its bounded filter goes nowhere: given up")
            return [1]
        return [0]

    def keep_if_feasible(self, x: np.ndarray, f: float, g: np.ndarray) -> None:
        """Keep iterate ``x`` in ``res.best_feasible`` where it satisfies every constraint within IPOPT's
        constr_viol_tol (the node defects, the force deficit and groove-force excess in units of their bound, the
        schedule's slope bound) and its objective ``f`` is below the one kept: the knots (m, within their bounds as
        :meth:`ShootingNlp.solve` reports its answer), the iteration, the objective, the force deficit (N^2 rad) and
        the largest node defect. Assigned whole, so that a signal between two lines leaves the previous one."""
        if self.res is None or self.bounds is None:
            return
        lbg, ubg = self.bounds
        if not (np.all(g >= lbg - self.tol) and np.all(g <= ubg + self.tol)):
            return
        kept = self.res.best_feasible
        if kept is not None and kept["objective"] <= f:
            return
        self.res.best_feasible = {
            "iteration": self.k, "knots": [float(v) * MM for v in np.maximum(x[:self.knots], 0.0)], "objective": f,
            "deficit": float(g[self.n_def]) * self.deficit_tol, "max_defect": float(np.abs(g[:self.n_def]).max())}


class ShootingNlp:
    """The multiple-shooting NLP with a hand-assembled Jacobian (formulated in study.py's docstring)."""

    def __init__(self, setup, sf, sim, nodes, knots, min_force, exclude, deficit_tol, objective):
        self.setup, self.N, self.K = setup, nodes, knots
        lay = setup.layout
        n, nx, ng = setup.samples, lay.n_x, lay.n_g
        self.n_x = nx  # the node states are the scaled continuous states; the directions are these, then the knots
        Z0 = sim.z  # (n_z, n + 1) from the first node of the previous grid
        first = float(sim.thetas[0] - setup.dth)
        act0 = Z0[lay.active]
        offset = _node_offset(act0, nodes, n // nodes)
        self.grid = SegmentGrid(n, nodes, knots, first + setup.dth * offset, setup.dth)
        g = self.grid
        idx = (offset + (n // nodes) * np.arange(nodes)) % n  # columns of Z0 at the new nodes
        self.S = np.maximum(1.0, np.max(np.abs(Z0[lay.x]), axis=1))
        S = self.S
        nz = Z0.shape[0]
        self.nz = nz
        per = g.per_node
        U = setup.controls(g.edges(), g.m)  # (4, n): each segment's call from its start
        omega = setup.pmap.at("omega")
        sc = state_scale(omega, lay.state_names)
        nd = -(-(nx + knots) // CHUNK) * CHUNK  # the directions, padded to whole chunks
        self.nd = nd
        self.deficit_tol, self.objective = float(deficit_tol), objective

        V = ca.MX.sym("V", knots + nx * nodes)
        kn = V[:knots] * MM
        W = ca.reshape(V[knots:], nx, nodes)
        Z = W * ca.repmat(ca.DM(S), 1, nodes)
        Q = g.q_columns(setup, kn, min_force, exclude)  # (n_q, S)
        node_seg = [k * per for k in range(nodes)]
        act = []
        for k in range(nodes):
            p_k = Q[:setup.pmap.p0.size, node_seg[k]]
            X_k = Z[:, k] * ca.DM(sc)
            act.append(setup.functions.guards(g.psi[node_seg[k]], X_k, p_k, ca.DM(U[:2, node_seg[k] * g.m])) < 0)
        x0 = ca.vertcat(Z, ca.horzcat(*act), ca.MX.zeros(ng, nodes))  # the layout's parts, in its order
        nq = Q.size1()
        Un = ca.DM(U)  # node k takes the columns of its segments, in order
        nominal = chain_function(sf, g, nz, derivatives=False)
        Fn = nominal.map(nodes, "thread", parallel_threads(nodes))
        Qcols = Q
        zend, qs, _ = Fn(x0, Qcols, Un)
        nxt = ca.horzcat(*[Z[:, (k + 1) % nodes] for k in range(nodes)])
        defects = ca.vec((zend[lay.x, :] - nxt) / ca.repmat(ca.DM(S), 1, nodes))
        deficit = ca.sum2(qs[1, :]) / self.deficit_tol
        power = ca.sum2(qs[0, :]) / TWO_PI
        obj = power if objective == "friction" else ca.sum1(V[:knots]) / knots
        self.groove = sf.groove
        groove = [ca.sum2(qs[2, :]) / self.deficit_tol] if sf.groove else []  # the groove-force excess
        G_out = ca.vertcat(defects, deficit, *groove, obj)

        # the Jacobian, from the compiled forward derivative (seeds: node states, knot values)
        full = chain_function(sf, g, nz, derivatives=True, nd=nd)
        Ff = full.map(nodes, "thread", parallel_threads(nodes))
        seed_z = np.zeros((nz, nd))
        seed_z[lay.x, :nx] = np.diag(S)
        L = setup.pmap.p0.size
        sl = L + 1  # the slope row of q
        seeds_q = []
        for k in range(nodes):
            for j in range(per):
                s = k * per + j
                blk = np.zeros((nq, nd))
                for i in range(knots):
                    blk[:L, nx + i] = setup.pmap.dp * MM * g.Lseg[s, i]
                    blk[sl, nx + i] = MM * g.Mseg[s, i]
                seeds_q.append(blk)
        dQ = ca.DM(np.concatenate(seeds_q, axis=1))  # (n_q, S nd), node-major
        _, _, dz, dq = Ff(x0, Qcols, Un, ca.DM(np.tile(seed_z, (1, nodes))), dQ)
        rows = []
        for k in range(nodes):
            Dk = dz[lay.x, k * nd:k * nd + nx + knots] / ca.repmat(ca.DM(S), 1, nx + knots)
            blocks = [Dk[:, nx:]]
            for j in range(nodes):
                if j == k:
                    blocks.append(Dk[:, :nx])
                elif j == (k + 1) % nodes:
                    blocks.append(-ca.DM.eye(nx))
                else:
                    blocks.append(ca.DM.zeros(nx, nx))
            rows.append(ca.horzcat(*blocks))
        dqk = [dq[:, k * nd:k * nd + nx + knots] for k in range(nodes)]
        dsum = sum(d[:, nx:] for d in dqk)
        row_def = ca.horzcat(dsum[1, :], *[d[1, :nx] for d in dqk]) / self.deficit_tol
        row_groove = [ca.horzcat(dsum[2, :], *[d[2, :nx] for d in dqk]) / self.deficit_tol] if sf.groove else []
        if objective == "friction":
            row_obj = ca.horzcat(dsum[0, :], *[d[0, :nx] for d in dqk]) / TWO_PI
        else:
            row_obj = ca.DM(np.r_[np.full(knots, 1.0 / knots), np.zeros(nx * nodes)]).T
        J = ca.vertcat(*rows, row_def, *row_groove, row_obj)
        Vj, Oj = ca.MX.sym("V", V.numel()), ca.MX.sym("out", G_out.numel())
        jac = ca.Function("jac_preload_g", [Vj, Oj], [ca.substitute(J, V, Vj)])
        self.G = ca.Function("preload_g", [V], [G_out], {"custom_jacobian": jac, "jac_penalty": 0,
                                                          "never_inline": True})
        self.nominal = ca.Function("preload_nominal", [V], [zend, qs])
        self.n_def = nx * nodes
        self.n_con = self.n_def + 1 + len(groove)  # defects, deficit (, groove excess): the objective follows
        W0 = Z0[lay.x, idx] / S[:, None]
        self.W0 = W0.ravel(order="F")
        self.V = V
        self.gave_up = False  # whether the last solve was given up (solve's give_up)

    def solve(self, knots0_m, res, *, upper, max_rate, max_iter, verbose, ipopt_options, give_up=False) -> bool:
        """IPOPT from ``knots0_m`` and the node states of the simulated start; ``give_up``: stop once stuck beyond
        the bounded filter's reach (:data:`STUCK_ITERATIONS`; ``self.gave_up`` says whether it did)."""
        K, N = self.K, self.N
        n_w = self.n_x * N  # the node states
        V = ca.MX.sym("V", K + n_w)
        out = self.G(V)
        g = [out[:self.n_con]]
        lbg = list(np.zeros(self.n_def)) + [-np.inf] * (self.n_con - self.n_def)
        ubg = list(np.zeros(self.n_def)) + [1.0] * (self.n_con - self.n_def)
        if K > 1 and max_rate is not None:
            span_deg = 360.0 / K
            diffs = ca.vertcat(*[V[(i + 1) % K] - V[i] for i in range(K)])
            g.append(diffs)
            lim = max_rate / MM * span_deg
            lbg += [-lim] * K
            ubg += [lim] * K
        options = {f"ipopt.{k}": v for k, v in (ipopt_options or {}).items()}
        prog = _Progress(V.numel(), int(sum(gi.numel() for gi in g)), self.n_def, self.groove, give_up, res=res,
                         knots=K, bounds=(np.array(lbg), np.array(ubg)), deficit_tol=self.deficit_tol,
                         tol=float(options.get("ipopt.constr_viol_tol", CONSTR_VIOL_TOL)))
        opts = {"ipopt.hessian_approximation": "limited-memory", "ipopt.tol": 1e-3,
                "ipopt.constr_viol_tol": CONSTR_VIOL_TOL,
                "ipopt.acceptable_tol": 1e10, "ipopt.acceptable_constr_viol_tol": 2e-2, "ipopt.acceptable_iter": 3,
                "ipopt.acceptable_obj_change_tol": 1e-4,
                "ipopt.max_iter": int(max_iter), "ipopt.linear_solver": "mumps",
                "ipopt.print_level": 5 if verbose else 0, "print_time": False, "ipopt.sb": "yes",
                "iteration_callback": prog, **options}
        t = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            solver = ca.nlpsol("preload", "ipopt", {"x": V, "f": out[-1], "g": ca.vertcat(*g)}, opts)
            lbx = np.r_[np.zeros(K), np.full(n_w, -np.inf)]
            ubx = np.r_[np.full(K, upper / MM), np.full(n_w, np.inf)]
            x0 = np.r_[np.asarray(knots0_m) / MM, self.W0]
            try:
                sol = solver(x0=x0, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg)
            except RuntimeError as err:
                res.ipopt_time_s += time.perf_counter() - t
                res.message = (f"IPOPT stopped with an error in the constraint evaluation ({err}); the shooting "
                               "integrator failed at an iterate (a step or event limit): try more nodes or a larger rtol")
                return False
        res.ipopt_time_s += time.perf_counter() - t
        self.gave_up = prog.gave_up
        st = solver.stats()
        res.ipopt_status, res.ipopt_iterations = str(st["return_status"]), res.ipopt_iterations + int(st["iter_count"])
        v = np.array(sol["x"]).ravel()
        gv = np.array(sol["g"]).ravel()
        res.max_defect = float(np.max(np.abs(gv[:self.n_def])))
        # IPOPT relaxes its bounds (bound_relax_factor, 1e-8): a knot on its bound 0 came back as -1e-11 m and was
        # printed as "-0.000 mm"; the design is the point within the bounds
        self.knots_m = np.clip(v[:K], 0.0, upper / MM) * MM
        qs = np.array(self.nominal(v)[1])
        res.nlp_friction_power = float(qs[0].sum() / TWO_PI)
        if res.ipopt_status not in SOLVED:
            groove = f", groove-force excess {gv[self.n_def + 1]:.3g} x its bound" if self.groove else ""
            res.message = (f"IPOPT returned {res.ipopt_status} after {res.ipopt_iterations} iterations at knots "
                           f"{', '.join(f'{x:.4g}' for x in v[:K])} mm; force deficit {gv[self.n_def]:.3g} x its bound"
                           f"{groove}, largest node defect {res.max_defect:.3g}. "
                           + _advice(res.ipopt_status, self.groove, self.gave_up))
            return False
        return True


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
