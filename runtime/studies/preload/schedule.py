"""The preload schedule delta_s(theta) and the segment grid the study integrates it on.

A schedule is periodic and piecewise linear in crank angle with K equally spaced knots (K = 1 is the
constant preload: one formulation for both designs). The revolution is cut into ``S = lcm(K, nodes)``
segments of ``samples / S`` output samples, starting at ``theta_first`` (the first shooting node): every
knot and every shooting node is a segment boundary, so on each segment delta_s is affine,
``delta_s = d_s + slope_s (theta - psi_s)``, and one call of the compiled interval integrator
(runtime/studies/preload/shooting.py) integrates it. The segment values are linear in the knot values:
``d = Lseg @ knots``, ``slope = Mseg @ knots``.

:func:`simulate_schedule` chains the segments over several revolutions from the scene's initial state:
the re-simulation of an optimum (and the derivative-free check) with the same hybrid model and event
integrator as the simulator, which also measures the force deficit between samples.
:func:`simulate_schedules` does it for several schedules at once, on every core.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ....cores import parallel_threads
from ...scenes.schedule import periodic_line
from .problem import MM
from .shooting import TWO_PI, q_layout, window_vector


@dataclass(frozen=True)
class Schedule:
    """delta_s(theta): periodic, piecewise linear through ``values`` (m) at ``angles`` (deg, increasing)."""

    angles: tuple[float, ...]
    values: tuple[float, ...]

    def __call__(self, theta_deg):
        return periodic_line(self.angles, self.values, theta_deg, period=360.0)

    def to_dict(self) -> dict:
        return {"angles_deg": list(self.angles), "delta_s_m": list(self.values)}


@dataclass
class SegmentGrid:
    """Segments of one revolution from ``theta_first`` (see the module docstring)."""

    samples: int
    nodes: int
    knots: int
    theta_first: float  # rad, the first node (a segment and knot boundary)
    dth: float

    def __post_init__(self) -> None:
        self.segments = math.lcm(self.nodes, self.knots)
        self.m = self.samples // self.segments
        s = np.arange(self.segments)
        self.psi = self.theta_first + self.dth * self.m * s  # segment starts
        per_knot = self.segments // self.knots
        K = self.knots
        self.Lseg = np.zeros((self.segments, K))
        self.Mseg = np.zeros((self.segments, K))
        span = TWO_PI / K
        for j in s:
            i = j // per_knot
            frac = (j % per_knot) / per_knot
            self.Lseg[j, i] += 1 - frac
            self.Lseg[j, (i + 1) % K] += frac
            if K > 1:
                self.Mseg[j, i] -= 1 / span
                self.Mseg[j, (i + 1) % K] += 1 / span

    @property
    def per_node(self) -> int:
        return self.segments // self.nodes

    @property
    def knot_angles_deg(self) -> np.ndarray:
        return np.degrees(self.theta_first + TWO_PI * np.arange(self.knots) / self.knots)

    def edges(self) -> np.ndarray:
        return self.theta_first + self.dth * np.arange(self.samples + 1)

    def q_columns(self, setup, knots_m, min_force: float, exclude, rev: int = 0):
        """The integrator parameters of every segment (n_q x S), numeric or CasADi (knots in m)."""
        L = q_layout(setup.pmap.p0.size)
        d = self.Lseg @ knots_m if isinstance(knots_m, np.ndarray) else ca.mtimes(ca.DM(self.Lseg), knots_m)
        slope = self.Mseg @ knots_m if isinstance(knots_m, np.ndarray) else ca.mtimes(ca.DM(self.Mseg), knots_m)
        S = self.segments
        p = ca.repmat(ca.DM(setup.pmap.p0), 1, S) + ca.mtimes(ca.DM(setup.pmap.dp), ca.reshape(d, 1, S))
        f_max = setup.max_groove_force if setup.max_groove_force is not None else 0.0  # unused without the bound
        rest = ca.DM(np.r_[[min_force, f_max], window_vector(exclude)])
        Q = ca.vertcat(p, ca.DM(self.psi + rev * TWO_PI).T, ca.reshape(slope, 1, S), ca.repmat(rest, 1, S))
        assert Q.size1() == L["size"]
        return np.array(Q) if isinstance(knots_m, np.ndarray) else Q


def chain_function(sf, grid: SegmentGrid, n_z: int, *, derivatives: bool, nd: int = 0) -> ca.Function:
    """One shooting interval (``grid.per_node`` segments chained) as a Function, to be mapped over the nodes.

    Inputs: z0 (n_z), Q (n_q x per_node), U (the controls, 4 x m per_node: PreloadSetup.controls) and, with
    ``derivatives``, the seeds of z0 (n_z x nd) and of Q (n_q x per_node nd). Outputs: the end state, the two
    quadratures summed, and the samples (n_z x m per_node) or, with ``derivatives``, their forward derivatives in the nd
    directions.
    """
    from .shooting import CHUNK

    k, m = grid.per_node, grid.m
    nq = sf.interval.size1_in(sf.interval.index_in("p"))
    n_u = sf.interval.size1_in(sf.interval.index_in("u"))
    z0, Q, U = ca.MX.sym("z0", n_z), ca.MX.sym("Q", nq, k), ca.MX.sym("U", n_u, m * k)
    ins = [z0, Q, U]
    x, qs, samples = z0, ca.MX.zeros(sf.n_quad), []
    if derivatives:
        dz0, dQ = ca.MX.sym("dz0", n_z, nd), ca.MX.sym("dQ", nq, k * nd)
        ins += [dz0, dQ]
        dx, dq = dz0, ca.MX.zeros(sf.n_quad, nd)
    for j in range(k):
        Uj = U[:, j * m:(j + 1) * m]
        r = sf.interval(x0=x, p=Q[:, j], u=Uj)
        if derivatives:
            cols_x, cols_q = [], []
            for c in range(0, nd, CHUNK):
                f = sf.forward(x0=x, p=Q[:, j], u=Uj, fwd_x0=dx[:, c:c + CHUNK],
                               fwd_p=dQ[:, j * nd + c:j * nd + c + CHUNK], fwd_u=ca.MX.zeros(n_u, m * CHUNK))
                ends = [i * m + m - 1 for i in range(CHUNK)]
                cols_x.append(f["fwd_xf"][:, ends])
                cols_q.append(f["fwd_qf"][:, ends])
            dx = ca.horzcat(*cols_x)
            dq = dq + ca.horzcat(*cols_q)
        else:
            samples.append(r["xf"])
        x = r["xf"][:, -1]
        qs = qs + r["qf"][:, -1]
    outs = [x, qs] + ([dx, dq] if derivatives else [ca.horzcat(*samples)])
    return ca.Function("preload_chain" + ("_fwd" if derivatives else ""), ins, outs)


@dataclass(eq=False)
class Resimulation:
    """A periodic revolution of a schedule, chained from the scene's initial state (see the module docstring).
    Holds arrays, so ``==`` is identity."""

    thetas: np.ndarray  # (samples,) rad, absolute crank angle of the last revolution's samples
    z: np.ndarray  # (n_z, samples + 1) its hybrid states, the start included
    deficit: float  # the force-deficit quadrature over the revolution (N^2 rad, outside the windows)
    friction_power: float  # W, cycle mean (quadrature)
    change: float  # change of the scaled state over the last revolution
    measure: np.ndarray  # (samples,) tip contact measure at the samples (N)
    pressures: np.ndarray  # (2, samples), at the samples
    delta_s: np.ndarray  # (samples,) m, the preload at each sample
    groove_excess: float = 0.0  # N^2 rad, the groove-force excess quadrature (a study with a groove-force bound)
    groove_peak: float | None = None  # N, the largest seal-groove contact force at the samples (idem)
    #: (samples,) N^2 rad, the force-deficit quadrature over each output interval (ending at ``thetas``): where the
    #: force between the samples falls short
    deficit_at: np.ndarray | None = None


def simulate_schedule(setup, sf, grid: SegmentGrid, knots_m, min_force: float, exclude,
                      revolutions: int | None = None, z_start: np.ndarray | None = None) -> Resimulation:
    """Chain the segments over ``revolutions`` revolutions from the scene's initial state at the first node."""
    return simulate_schedules(setup, sf, grid, [knots_m], min_force, exclude, revolutions,
                              None if z_start is None else [z_start])[0]


def simulate_schedules(setup, sf, grid: SegmentGrid, knots_list, min_force: float, exclude,
                       revolutions: int | None = None, z_starts=None) -> list[Resimulation]:
    """:func:`simulate_schedule` for several schedules (or constant preloads) at once, one :class:`Resimulation`
    each. Each segment's integrator call is made for all of them together, in a threaded map of the study's
    compiled interval integrator over the schedules (:func:`parallel_threads`): the same function with the same
    inputs, so the same numbers as one schedule at a time, on every core."""
    knots_list = [np.asarray(k, float) for k in knots_list]
    n = len(knots_list)
    revolutions = revolutions or setup.revolutions
    lay = setup.layout
    C = setup.controls(grid.edges(), grid.m)  # each segment's call from its start
    if z_starts is None:  # the scene's initial state at the first node, with each schedule's parameters there
        n_par = setup.pmap.p0.size
        z_starts = [setup.hybrid_start(grid.theta_first, grid.q_columns(setup, k, min_force, exclude)[:n_par, 0], C[:2, 0])
                    for k in knots_list]
    z = np.column_stack([np.asarray(z0, float) for z0 in z_starts])  # one column per schedule
    interval = sf.interval if n == 1 else sf.interval.map(n, "thread", parallel_threads(n))
    m = grid.m
    starts = [z.copy()]
    for rev in range(revolutions):
        Q = [grid.q_columns(setup, knots_m, min_force, exclude, rev) for knots_m in knots_list]
        cols, qsum, dq = [], np.zeros((sf.n_quad, n)), []
        for s in range(grid.segments):
            r = interval(x0=z, p=np.column_stack([q[:, s] for q in Q]), u=C[:, s * m:(s + 1) * m])
            xf = np.array(r["xf"]).reshape(-1, n, m).transpose(1, 0, 2)  # (schedule, state, sample)
            cols.append(xf)
            qf = np.array(r["qf"])  # (n_quad, schedule x sample), each from its call's start
            qsum += qf[:, m - 1::m]
            dq.append(np.diff(qf[1].reshape(n, m), axis=1, prepend=0.0))  # the deficit over each interval
            z = xf[:, :, -1].T.copy()
        z0_rev = starts[-1]
        z[lay.counts] = 0.0  # event counts per revolution
        starts.append(z.copy())
    U = setup.pressures(grid.edges())  # at the samples, as the outputs see them
    deficit_at = np.concatenate(dq, axis=1)  # (schedule, samples), the last revolution's
    return [_resimulation(setup, sf, grid, knots_list[i], revolutions, U,
                          np.concatenate([z0_rev[:, i:i + 1]] + [c[i] for c in cols], axis=1), qsum[:, i],
                          starts[-2][:, i], starts[-1][:, i], deficit_at[i]) for i in range(n)]


def _resimulation(setup, sf, grid: SegmentGrid, knots_m, revolutions: int, U: np.ndarray, Z: np.ndarray,
                  qsum: np.ndarray, start_before: np.ndarray, start_last: np.ndarray,
                  deficit_at: np.ndarray) -> Resimulation:
    """The last revolution ``Z`` (its start included) of a chained schedule, with its quadratures ``qsum``, as a
    :class:`Resimulation`: the tip's contact measure at the samples (pressures ``U`` there), and the groove forces
    where they are bounded."""

    Z[setup.layout.counts, 0] = 0.0
    if not np.isfinite(Z).all():
        raise RuntimeError("the re-simulation of the schedule turned non-finite")
    thetas = grid.edges()[1:] + (revolutions - 1) * TWO_PI
    change = float(setup.state_change(start_before, start_last))
    # the physical parameters at each sample (delta_s varies along the segment)
    d_at = Schedule(tuple(grid.knot_angles_deg), tuple(knots_m))(np.degrees(thetas))
    P = setup.pmap.p0[:, None] + setup.pmap.dp[:, None] * d_at[None, :]
    meas = setup.at_samples(setup.measure_fn, Z[:, 1:], thetas, P, U).ravel()
    sim = Resimulation(thetas, Z, float(qsum[1]), float(qsum[0] / TWO_PI), change, meas, U, d_at,
                       deficit_at=deficit_at)
    if sf.groove:
        from .shooting import groove_forces

        Y = setup.at_samples(setup.functions.outputs, Z[:, 1:], thetas, P, U)
        sim.groove_excess = float(qsum[2])
        sim.groove_peak = float(max(np.hypot(Y[ix], Y[iy]).max() for ix, iy in groove_forces(setup.functions)))
    return sim


__all__ = ["MM", "Resimulation", "Schedule", "SegmentGrid", "chain_function", "simulate_schedule",
           "simulate_schedules"]
