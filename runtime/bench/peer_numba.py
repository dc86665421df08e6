"""The hand-written peer: a numba right-hand side (runtime/bench/peer_source.py) under LSODA and DOP853.

The same problem as every other method of the benchmark (runtime/bench/problem.py):
scaled state z (generated/scaling.py) against the crank angle since the span's start,
one absolute tolerance ``atol = rtol`` on z, the chamber pressures constant over
each output interval. Three ways an expert would integrate it:

* ``numba-scipy-LSODA``: ``scipy.integrate.solve_ivp(method="LSODA")`` calling the
  numba switched right-hand side (contacts switch inside it, activation = gap < 0),
  pressures looked up by output interval; needs only numba and scipy;
* ``numbalsoda-LSODA``: the same switched right-hand side as a numba ``cfunc``
  under numbalsoda's LSODA (C++), one call per span with the output grid;
* ``numbalsoda-DOP853``: Hairer's DOP853 (numbalsoda's Fortran ``solve_ivp``)
  on the mode's smooth right-hand side, driven from a numba loop over the output
  intervals. Events are the zero functions of generated/hybrid.py, e_i = (1 - 2 s_i) g_i / l,
  handed to numbalsoda as one event function, their smallest: numbalsoda locates (by
  Brent's method, to 1e-8 rad of crank angle, fixed in numbalsoda) only the lowest-indexed
  of the functions that changed sign in a step, not the earliest crossing, and with a
  function each a contact that crossed earlier in the same step was integrated in the wrong
  mode up to a later contact's root (on the benchmark's problem: 120 switches instead of the
  reference's 104, and a scaled error of 6e-2 whatever the tolerance). The smallest of them
  first crosses zero where the earliest of them does. numbalsoda's 1e-8 rad leaves the
  located state off the contact's surface by up to that much of its motion, an error
  the clusters of switches amplify (a floor near 2e-5 on the benchmark's problem), so the
  loop takes one Newton step of the located function along the flow, z + h f(z) with
  |h| within that tolerance (its error O(h^2)), unless the step would change the sign of
  another contact's function (:func:`polished_root`). It then toggles the contact whose
  function is smallest there, and every other whose function is negative (crossed with
  it), and restarts. At a restart every zero function that is not positive is shifted to
  a small positive value: a root located exactly would otherwise start the event function
  at zero, and numbalsoda, which looks for a change of sign, would miss the next
  crossing (seen with the Newton step: the seal left its groove at rtol 1e-7); and a
  sign change from - to + right after a restart, the located root's own round-off,
  toggles nothing. Sign changes are looked for at step ends only, so the step is limited
  to an eighth of the period of the stiffest contact (:func:`dop853_max_step`): a bounce
  inside one step would be missed.

numbalsoda needs a Fortran compiler to build from source, so it is optional: without it the
benchmark skips the two numbalsoda methods with a note. LSODA's finite-difference Jacobians are
included in its right-hand-side evaluation counts (counted inside the right-hand side).
"""

from __future__ import annotations

import time

import numpy as np

from ...derive.symbols import PARAMETER_NAMES
from ...generated.scaling import LENGTH, state_scale, to_scaled
from ..solving.contact_stability import contact_frequencies
from ..solving.methods import RevolutionResult

N_PAR = len(PARAMETER_NAMES)
OMEGA = PARAMETER_NAMES.index("omega")
#: restarts (events and their round-off) allowed in one output interval before the run is a failure
MAX_RESTARTS = 1000
#: numbalsoda's tolerance of its event location (crank angle, rad; fixed in its Fortran)
EVENT_LOCATION = 1e-8
#: the step along the flow (rad) of the forward difference that gives a located zero function's rate
NEWTON_PROBE = 1e-9
#: the value (in zero-function units: the gap over 1 um) a zero function that is not positive restarts at
RESTART_FLOOR = 1e-12


def numba_available() -> str | None:
    """None when numba imports, else why not."""
    try:
        import numba  # noqa: F401
    except Exception as exc:  # noqa: BLE001
        return f"numba is not installed ({type(exc).__name__}: {exc}); pip install 'apexseal[bench]'"
    return None


def numbalsoda_available() -> str | None:
    """None when numbalsoda imports, else why not (it builds from source with gfortran and cmake)."""
    why = numba_available()
    if why:
        return why
    try:
        import numbalsoda  # noqa: F401
    except Exception as exc:  # noqa: BLE001
        return (f"numbalsoda is not installed ({type(exc).__name__}: {exc}); pip install 'apexseal[peer]' "
                "(needs gfortran and cmake to build)")
    return None


class Layout:
    """Offsets in the float64 data array every numba function reads (parameters, grid, pressures, scratch)."""

    def __init__(self, n_guards: int, samples: int, linear: bool = False):
        self.n_g, self.N = n_guards, samples
        self.TH0 = N_PAR  # crank angle at the span's start
        self.DTH = N_PAR + 1  # output interval (rad)
        self.SC = N_PAR + 2  # state scale (6)
        self.PA = self.SC + 6  # pressures of the current interval (event driver)
        self.S = self.PA + 2  # activations of the current mode (n_g)
        self.OFF = self.S + n_guards  # offsets of the zero functions since the last restart (see the driver)
        self.CNT = self.OFF + n_guards  # right-hand-side evaluations
        self.X = self.CNT + 1  # scratch: physical state (6), accelerations (3), gaps (n_g), zero functions (n_g)
        self.ACC = self.X + 6
        self.GAP = self.ACC + 3
        self.EV = self.GAP + max(n_guards, 1)  # scratch: the shifted zero functions of the event function (n_g)
        self.TAB = self.EV + max(n_guards, 1)  # Pa (N), then Pb (N); with linear pressures N + 1 edge values each
        self.linear = linear
        self.NP = samples + linear  # pressure values per chamber
        self.size = self.TAB + 2 * self.NP

    def data(self, problem) -> np.ndarray:
        d = np.zeros(self.size)
        d[:N_PAR] = problem.params
        d[self.TH0] = problem.theta0
        d[self.DTH] = problem.span / problem.samples
        d[self.SC:self.SC + 6] = state_scale(problem.omega)
        d[self.TAB:self.TAB + self.NP] = problem.pressures[0]
        d[self.TAB + self.NP:] = problem.pressures[1]
        return d


def make_kernels(nm, layout: Layout):
    """numba functions of one model and grid: right-hand sides (njit and cfunc), zero functions, drivers."""
    import numba

    switched, accelerations, guards = nm.switched, nm.accelerations, nm.guards
    n_g, N = layout.n_g, layout.N
    TH0, DTH, SC, PA, S, OFF, CNT = layout.TH0, layout.DTH, layout.SC, layout.PA, layout.S, layout.OFF, layout.CNT
    XO, ACC, GAP, EV, TAB, SIZE = layout.X, layout.ACC, layout.GAP, layout.EV, layout.TAB, layout.size
    inv_l = 1.0 / LENGTH
    LIN, NP = layout.linear, layout.NP

    @numba.njit(cache=False)
    def table_pressures(t, d):
        """The pressures at t: of the output interval holding t, or linear between its ends (layout.linear)."""
        k = min(max(int(np.ceil(t / d[DTH])) - 1, 0), N - 1)
        if LIN:
            w = t / d[DTH] - k
            return (d[TAB + k] + w * (d[TAB + k + 1] - d[TAB + k]),
                    d[TAB + NP + k] + w * (d[TAB + NP + k + 1] - d[TAB + NP + k]))
        return d[TAB + k], d[TAB + NP + k]

    @numba.njit(cache=False)
    def mode_pressures(t, d):
        """The pressures the event driver set for the current interval, or linear in t (layout.linear)."""
        if LIN:
            return table_pressures(t, d)
        return d[PA], d[PA + 1]

    @numba.njit(cache=False)
    def switched_rhs(t, z, d, dz):
        """dz/dtheta with the contacts switched inside; pressures of the output interval holding t."""
        om = d[OMEGA]
        X = d[XO:XO + 6]
        for i in range(6):
            X[i] = z[i] * d[SC + i]
        acc = d[ACC:ACC + 3]
        pa, pb = table_pressures(t, d)
        switched(d[TH0] + t, X, d[:N_PAR], pa, pb, acc)
        for i in range(3):
            dz[i] = X[3 + i] / (d[SC + i] * om)
            dz[3 + i] = acc[i] / (d[SC + 3 + i] * om)
        d[CNT] += 1.0

    @numba.njit(cache=False)
    def mode_rhs(t, z, d, dz):
        """dz/dtheta in the current mode (activations d[S:]), pressures of the current interval (d[PA:PA+2])."""
        om = d[OMEGA]
        X = d[XO:XO + 6]
        for i in range(6):
            X[i] = z[i] * d[SC + i]
        acc = d[ACC:ACC + 3]
        pa, pb = mode_pressures(t, d)
        accelerations(d[TH0] + t, X, d[S:S + n_g], d[:N_PAR], pa, pb, acc)
        for i in range(3):
            dz[i] = X[3 + i] / (d[SC + i] * om)
            dz[3 + i] = acc[i] / (d[SC + 3 + i] * om)

    @numba.njit(cache=False)
    def zero_functions(t, z, d, e):
        """e_i = (1 - 2 s_i) g_i / l (generated/hybrid.py): positive while the mode agrees with gap i."""
        X = d[XO:XO + 6]
        for i in range(6):
            X[i] = z[i] * d[SC + i]
        g = d[GAP:GAP + n_g]
        pa, pb = mode_pressures(t, d)
        guards(d[TH0] + t, X, d[:N_PAR], pa, pb, g)
        for i in range(n_g):
            e[i] = (1.0 - 2.0 * d[S + i]) * g[i] * inv_l

    @numba.njit(cache=False)
    def grid_closed(Zs, d, closed):
        """Which contacts are closed (gap < 0) at the ends of the output intervals, from scaled states (6, N)."""
        e = np.empty(n_g)
        for j in range(n_g):
            d[S + j] = 0.0  # with every contact open the zero functions are the gaps themselves
        for k in range(N):
            d[PA], d[PA + 1] = d[TAB + k], d[TAB + NP + k]
            zero_functions((k + 1) * d[DTH], Zs[:, k].copy(), d, e)
            for j in range(n_g):
                closed[j, k] = 1.0 if e[j] < 0.0 else 0.0

    dp = numba.types.CPointer(numba.types.double)
    c_sig = numba.types.void(numba.types.double, dp, dp, dp)  # (t, u*, du*, data*): numbalsoda's lsoda_sig

    @numba.cfunc(c_sig)
    def switched_c(t, u, du, data):
        switched_rhs(t, numba.carray(u, (6,)), numba.carray(data, (SIZE,)), numba.carray(du, (6,)))

    @numba.cfunc(c_sig)
    def mode_c(t, u, du, data):
        d = numba.carray(data, (SIZE,))
        mode_rhs(t, numba.carray(u, (6,)), d, numba.carray(du, (6,)))

    @numba.njit(cache=False)
    def shifted_zero_functions(t, z, d, e):
        """The zero functions shifted by their restart offsets (see the module docstring)."""
        zero_functions(t, z, d, e)
        for i in range(n_g):
            e[i] += d[OFF + i]

    @numba.cfunc(c_sig)
    def events_c(t, u, e, data):
        """The one event function numbalsoda sees: the smallest shifted zero function, whose first root is the
        earliest crossing of any contact (see the module docstring)."""
        d = numba.carray(data, (SIZE,))
        g = d[EV:EV + n_g]
        shifted_zero_functions(t, numba.carray(u, (6,)), d, g)
        m = g[0]
        for i in range(1, n_g):
            m = min(m, g[i])
        numba.carray(e, (1,))[0] = m

    return {"switched_rhs": switched_rhs, "mode_rhs": mode_rhs, "zero_functions": zero_functions, "grid_closed": grid_closed,
            "shifted_zero_functions": shifted_zero_functions, "switched_c": switched_c, "mode_c": mode_c,
            "events_c": events_c}


def make_dop853_driver(kernels: dict, layout: Layout):
    """The numba loop over output intervals and events around numbalsoda's DOP853 (see the module docstring)."""
    import numba
    from numbalsoda import solve_ivp

    zero_functions, shifted_zero_functions = kernels["zero_functions"], kernels["shifted_zero_functions"]
    mode_rhs = kernels["mode_rhs"]
    n_g, N, DTH, PA, S, OFF, TAB = layout.n_g, layout.N, layout.DTH, layout.PA, layout.S, layout.OFF, layout.TAB
    NP = layout.NP

    @numba.njit(cache=False)
    def restart_offsets(t, z, d, e0):
        """The zero functions at a restart from (t, z) into ``e0``, and their shifts: each that is not positive to
        RESTART_FLOOR above zero."""
        zero_functions(t, z, d, e0)
        for j in range(n_g):
            d[OFF + j] = RESTART_FLOOR - 2.0 * e0[j] if e0[j] <= 0.0 else 0.0

    @numba.njit(cache=False)
    def polished_root(t, z, d, i, e1):
        """One Newton step of the located shifted zero function i along the flow, z + h f(z), when it falls through
        its root there, |h| is within numbalsoda's location tolerance and no other contact's function changes sign;
        (t, z) at the root, or as located. ``e1`` (the shifted zero functions at (t, z)) is updated."""
        f, e2 = np.empty(6), np.empty(n_g)
        mode_rhs(t, z, d, f)
        shifted_zero_functions(t + NEWTON_PROBE, z + NEWTON_PROBE * f, d, e2)
        slope = (e2[i] - e1[i]) / NEWTON_PROBE
        if not slope < 0.0:
            return t, z
        h = -e1[i] / slope
        if abs(h) > EVENT_LOCATION:
            return t, z
        zh = z + h * f
        shifted_zero_functions(t + h, zh, d, e2)
        for j in range(n_g):
            if j != i and (e2[j] < 0.0) != (e1[j] < 0.0):
                return t, z
        e1[:] = e2
        return t + h, zh

    @numba.njit(cache=False)
    def drive(rhs_ptr, ev_ptr, z0, d, rtol, atol, max_step):
        n_z = 6 + 2 * n_g
        Z = np.empty((n_z, N))
        z = z0[:6].copy()
        s = z0[6:6 + n_g].copy()
        counts = z0[6 + n_g:].copy()
        d[S:S + n_g] = s
        dth = d[DTH]
        e0 = np.empty(n_g)
        e1 = np.empty(n_g)
        nfev = 0
        n_seg = 0
        teval = np.empty(1)
        span = np.empty(2)
        for k in range(N):
            d[PA] = d[TAB + k]
            d[PA + 1] = d[TAB + NP + k]
            t, t_end = k * dth, (k + 1) * dth
            teval[0] = t_end
            restart_offsets(t, z, d, e0)
            restarts = 0
            while True:
                span[0], span[1] = t, t_end
                res = solve_ivp(rhs_ptr, span, z, teval, n_events=1, event_fcn=ev_ptr, data=d.ctypes.data,
                                rtol=rtol, atol=atol, max_step=max_step)
                nfev += res.nfev
                n_seg += 1
                if not res.success:
                    return Z[:, :k], nfev, n_seg, 1
                if not res.event_found:
                    z = res.y[0].copy()
                    break
                t = res.t_event
                z = res.y_event.copy()
                shifted_zero_functions(t, z, d, e1)
                i = np.argmin(e1)  # the contact whose crossing was located (the smallest function there)
                t, z = polished_root(t, z, d, i, e1)
                nfev += 1
                for j in range(n_g):
                    if j == i or e1[j] < 0.0:
                        s[j] = 1.0 - s[j]
                        counts[j] += 1.0
                d[S:S + n_g] = s
                restart_offsets(t, z, d, e0)
                restarts += 1
                if restarts > MAX_RESTARTS:
                    return Z[:, :k], nfev, n_seg, 2
            Z[:6, k] = z
            Z[6:6 + n_g, k] = s
            Z[6 + n_g:, k] = counts
        return Z, nfev, n_seg, 0

    return drive


def dop853_max_step(params: np.ndarray) -> float:
    """DOP853's largest step (crank angle, rad): an eighth of the stiffest contact's period, 2 pi / sqrt(k / ms).

    numbalsoda looks for sign changes of the zero functions only at the ends of its steps, so a contact that
    closes and opens again within one step is missed; on the metal default (k = 1e9 N/m) unlimited steps miss
    bounces and the seal leaves its groove (scaled error 22 over 20 deg of tests/runtime/test_bench_peer.py), a
    quarter period (1.03e-3 rad) still misses some (error 0.46), an eighth (5.2e-4 rad) and less find the
    reference's switches (error 2e-6 to 1e-5 at rtol 1e-10, the floor of numbalsoda's event location). The contacts
    are those of :func:`contact_frequencies` (every oscillator the submodels declare, the spring's included).
    """
    fastest = max(contact_frequencies(params, PARAMETER_NAMES).values())
    return 0.125 * 2 * np.pi * float(params[OMEGA]) / fastest


#: compiled kernels by (numba source file, guards, samples, linear pressures): shared by problems of one model and grid
_KERNELS: dict = {}


class NumbaPeer:
    """The peer for one problem: numba functions, compiled once (``build``), then ``run(method, rtol)``."""

    METHODS = ("numba-scipy-LSODA", "numbalsoda-LSODA", "numbalsoda-DOP853")

    def __init__(self, problem, nm):
        names = tuple(problem.functions.parameter_names)
        if names != tuple(PARAMETER_NAMES):  # the peer is printed from the default effects' model, with its vector
            raise ValueError(f"the numba peer is printed for the default effects (parameters {', '.join(PARAMETER_NAMES)}); "
                             f"problem {problem.name} has others ({', '.join(names)}): run the peer on a scene of the "
                             "default effects")
        self.problem, self.nm = problem, nm
        self.layout = Layout(nm.n_guards, problem.samples, linear=problem.pressure == "linear")
        self.data = self.layout.data(problem)
        self.kernels = None
        self.dop853 = None
        self.build_s = None
        self.max_step = dop853_max_step(problem.params)

    def build(self, *, numbalsoda: bool) -> float:
        """Compile the kernels (and the DOP853 driver) by calling each once (DOP853: the span at rtol 1e-2); wall s."""
        w0 = time.perf_counter()
        key = (str(self.nm.path), self.layout.n_g, self.layout.N, self.layout.linear)
        if self.kernels is None:
            self.kernels = _KERNELS.get(key) or _KERNELS.setdefault(key, make_kernels(self.nm, self.layout))
        z0, n_g = self.z0(), self.layout.n_g
        dz = np.empty(6)
        self.kernels["switched_rhs"](0.0, z0[:6], self.data.copy(), dz)
        N = self.problem.samples  # noqa: N806
        self.kernels["grid_closed"](np.zeros((6, N)), self.data.copy(), np.empty((n_g, N)))
        if numbalsoda and self.dop853 is None:
            if "dop853" not in self.kernels:
                self.kernels["dop853"] = make_dop853_driver(self.kernels, self.layout)
            self.dop853 = self.kernels["dop853"]
            self.dop853(self.kernels["mode_c"].address, self.kernels["events_c"].address, self.problem.z0,
                        self.data.copy(), 1e-2, 1e-2, self.max_step)
        self.build_s = time.perf_counter() - w0
        return self.build_s

    def z0(self) -> np.ndarray:
        return to_scaled(self.problem.X0, self.problem.omega)

    def run(self, method: str, rtol: float) -> RevolutionResult:
        if method == "numba-scipy-LSODA":
            return self._scipy_lsoda(rtol)
        if method == "numbalsoda-LSODA":
            return self._numbalsoda_lsoda(rtol)
        if method == "numbalsoda-DOP853":
            return self._dop853(rtol)
        raise ValueError(f"unknown peer method {method!r}; known: {', '.join(self.METHODS)}")

    # ------------------------------------------------------------------ the three integrations

    def grid_states(self, Zs: np.ndarray, n_rhs: int, extra: dict | None = None) -> RevolutionResult:
        """Integrator states from scaled states on the grid: contacts from the gaps there, switches counted there."""
        p, L = self.problem, self.layout
        closed = np.empty((L.n_g, p.samples))
        self.kernels["grid_closed"](np.ascontiguousarray(Zs), self.data.copy(), closed)
        prev = np.c_[p.closed0, closed[:, :-1]]
        counts = p.z0[6 + L.n_g:, None] + np.cumsum(closed != prev, axis=1)
        return RevolutionResult(np.vstack([Zs, closed, counts]), {"n_rhs": n_rhs, **(extra or {})})

    def _scipy_lsoda(self, rtol: float) -> RevolutionResult:
        return self.scipy("LSODA", rtol)

    def scipy(self, method: str, rtol: float, velocity_weight: float = 1.0) -> RevolutionResult:
        """scipy's ``solve_ivp(method=...)`` on the switched right-hand side, ``atol = rtol`` (the velocities'
        ``velocity_weight`` times that: as if they were scaled that many times larger); its statistics count the
        right-hand-side evaluations (finite-difference Jacobians included) and the Jacobians."""
        from scipy.integrate import solve_ivp

        p = self.problem
        d = self.data.copy()
        f = self.kernels["switched_rhs"]

        def rhs(t, z):
            dz = np.empty(6)
            f(t, z, d, dz)
            return dz

        grid = p.span / p.samples * np.arange(1, p.samples + 1)
        atol = rtol * np.array([1.0, 1.0, 1.0, velocity_weight, velocity_weight, velocity_weight])
        sol = solve_ivp(rhs, (0.0, p.span), self.z0(), method=method, t_eval=grid, rtol=rtol, atol=atol)
        if sol.status != 0 or sol.y.shape[1] != p.samples:
            raise RuntimeError(f"solve_ivp {method} failed: {sol.message}")
        return self.grid_states(sol.y, int(d[self.layout.CNT]), {"n_jac": int(sol.njev), "n_lu": int(sol.nlu)})

    def _numbalsoda_lsoda(self, rtol: float) -> RevolutionResult:
        from numbalsoda import lsoda

        p = self.problem
        d = self.data.copy()
        edges = p.span / p.samples * np.arange(p.samples + 1)
        usol, ok = lsoda(self.kernels["switched_c"].address, self.z0(), edges, data=d, rtol=rtol, atol=rtol,
                         mxstep=500000)
        if not ok:
            raise RuntimeError(f"numbalsoda LSODA failed at rtol {rtol:g}")
        return self.grid_states(np.ascontiguousarray(usol[1:].T), int(d[self.layout.CNT]))

    def _dop853(self, rtol: float) -> RevolutionResult:
        d = self.data.copy()
        Z, nfev, n_seg, status = self.dop853(self.kernels["mode_c"].address, self.kernels["events_c"].address,
                                            self.problem.z0, d, rtol, rtol, self.max_step)
        if status:
            why = "integration failed" if status == 1 else f"more than {MAX_RESTARTS} restarts in one output interval"
            raise RuntimeError(f"numbalsoda DOP853: {why} after {Z.shape[1]} of {self.problem.samples} intervals")
        n_g = self.layout.n_g
        events = int(Z[6 + n_g:, -1].sum() - self.problem.z0[6 + n_g:].sum())
        return RevolutionResult(Z, {"n_rhs": int(nfev), "n_calls": int(n_seg), "n_events": events})



def per_evaluation(peer: NumbaPeer, kernel: str, calls: int = 200_000) -> float:
    """CPU seconds per call of one of the peer's right-hand sides in a numba loop (no Python in between)."""
    import numba

    f = peer.kernels[kernel]
    if "loop" not in peer.kernels:

        @numba.njit(cache=False)
        def loop(f, t, z, d, n):
            dz = np.empty(6)
            acc = 0.0
            for _ in range(n):
                z[0] += 1e-12  # a new state each call, so nothing is hoisted out of the loop
                f(t, z, d, dz)
                acc += dz[5]
            return acc

        peer.kernels["loop"] = loop
    d = peer.data.copy()
    d[peer.layout.S:peer.layout.S + peer.layout.n_g] = peer.problem.closed0
    d[peer.layout.PA:peer.layout.PA + 2] = peer.problem.pressures[:, 0]
    z = peer.z0().copy()
    loop = peer.kernels["loop"]
    t = 0.5 * peer.problem.span / peer.problem.samples
    loop(f, t, z, d, 10)
    c0 = time.process_time()
    loop(f, t, z, d, calls)
    return (time.process_time() - c0) / calls
