"""A prototype: an exponential Rosenbrock method with events, on the benchmark's problem (not a run method).

``python -m apexseal.runtime.bench.exponential [--rtols 1e-5,1e-6,1e-7] [--velocity-weight 1,1000]`` (under half a
minute; docs/bench/levers.md, "Where the error and the work are").

What it asks: can a step that is not limited by the metal contacts' stability cross the degrees between the switch
windows (runtime/bench/anatomy.py) in a few steps? The method is exprb32 (Hochbruck, Ostermann and Schweitzer,
SIAM J. Numer. Anal. 47 (2009)): with J the Jacobian of the mode's right-hand side F at w (the scaled state and the
crank angle, so the pressure's slope is in J),

    U = w + h phi1(hJ) F(w),   w+ = U + 2 h phi3(hJ) D,   D = g(U) - g(w),   g = F - J w,

order 3, and 2 h phi3(hJ) D (what the third order adds to the exponential Euler step U) is the error estimate.
A linear mode is integrated exactly whatever h, so a contact's ringing costs nothing; only what is nonlinear
over a step (friction, geometry) limits it. The phi functions come from one matrix exponential each
(Al-Mohy and Higham's augmented matrix; Pade 7 with scaling and squaring, by loops), the Jacobian from finite differences
(7 evaluations). Events are the zero functions of generated/hybrid.py, looked for at step ends and located
by the Illinois method on the same step from its start; steps end at the output samples (where the linear
pressures change slope).

The error norm weights the three velocity components by ``1 / velocity_weight`` (1: the benchmark's scaled state
with ``atol = rtol``, like every other method; 1000: a velocity tolerance 1000 times looser). It is written with
numba on the peer's right-hand side (runtime/bench/peer_source.py), so its counts are comparable with the peer's;
its CPU times are a prototype's (a numba matrix exponential, allocations in every step), not a compiled method's.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from ...generated.scaling import LENGTH, state_scale
from .anatomy import Anatomy, windowed_errors
from .metrics import errors, trajectory


def make_kernels(problem, nm) -> dict:
    """numba functions of ``problem`` with the peer model ``nm``, on w = [scaled state (6), crank angle since the
    span's start] in mode ``s`` and output interval ``k``: ``F(w, s, k, out)``, ``zeros(w, s, k, e)``,
    ``jacobian(w, s, k, f0, J, cnt)``, the exprb32 step ``exprb(w, s, k, h, f0, J, cnt) -> (w+, error estimate)``
    ``make_locate(step)``, the earliest crossing of a zero function on a step of ``step`` from w, and the error norm
    ``norm(w, w1, err, rtol, vw)``."""
    import numba

    acc_f, guards_f, n_g = nm.accelerations, nm.guards, nm.n_guards
    DTH = problem.span / problem.samples
    PT = np.asarray(problem.pressures, float)  # linear: the values at the N + 1 edges
    SC, OM = state_scale(problem.omega), problem.omega
    PAR, TH0 = np.asarray(problem.params, float), problem.theta0
    NW = 7  # the integrated w: the scaled state (6) and the crank angle

    @numba.njit
    def F(w, s, k, out):
        x = w[:6] * SC
        acc = np.empty(3)
        u = w[6] / DTH - k
        acc_f(TH0 + w[6], x, s, PAR, PT[0, k] + u * (PT[0, k + 1] - PT[0, k]),
              PT[1, k] + u * (PT[1, k + 1] - PT[1, k]), acc)
        for i in range(3):
            out[i] = x[3 + i] / (SC[i] * OM)
            out[3 + i] = acc[i] / (SC[3 + i] * OM)
        out[6] = 1.0

    @numba.njit
    def zeros(w, s, k, e):
        g = np.empty(n_g)
        u = w[6] / DTH - k
        guards_f(TH0 + w[6], w[:6] * SC, PAR, PT[0, k] + u * (PT[0, k + 1] - PT[0, k]),
                 PT[1, k] + u * (PT[1, k + 1] - PT[1, k]), g)
        for i in range(n_g):
            e[i] = (1.0 - 2.0 * s[i]) * g[i] / LENGTH

    @numba.njit
    def mm(A, B):
        """A B by loops: for these few rows a loop costs less than a call into BLAS."""
        n, m, q = A.shape[0], B.shape[0], B.shape[1]
        out = np.zeros((n, q))
        for i in range(n):
            for j in range(m):
                a = A[i, j]
                if a != 0.0:
                    for c in range(q):
                        out[i, c] += a * B[j, c]
        return out

    @numba.njit
    def solve(A, B):
        """A^-1 B by Gaussian elimination with partial pivoting (A and B are overwritten)."""
        n, q = A.shape[0], B.shape[1]
        for c in range(n):
            piv = c + np.argmax(np.abs(A[c:, c]))
            if piv != c:
                for j in range(n):
                    A[c, j], A[piv, j] = A[piv, j], A[c, j]
                for j in range(q):
                    B[c, j], B[piv, j] = B[piv, j], B[c, j]
            for r in range(c + 1, n):
                f = A[r, c] / A[c, c]
                if f != 0.0:
                    for j in range(c, n):
                        A[r, j] -= f * A[c, j]
                    for j in range(q):
                        B[r, j] -= f * B[c, j]
        for c in range(n - 1, -1, -1):
            for j in range(q):
                acc = B[c, j]
                for r in range(c + 1, n):
                    acc -= A[c, r] * B[r, j]
                B[c, j] = acc / A[c, c]
        return B

    @numba.njit
    def expm(A):
        """exp(A): Pade (7, 7) with scaling and squaring (Higham, SIAM J. Matrix Anal. Appl. 26 (2005))."""
        n = A.shape[0]
        norm = np.max(np.sum(np.abs(A), axis=0))
        sq = max(0, int(np.ceil(np.log2(norm / 3.925724783138660)))) if norm > 0.0 else 0
        B = A / 2.0 ** sq
        b = (17297280.0, 8648640.0, 1995840.0, 277200.0, 25200.0, 1512.0, 56.0, 1.0)
        B2 = mm(B, B)
        B4 = mm(B2, B2)
        B6 = mm(B4, B2)
        odd = b[7] * B6 + b[5] * B4 + b[3] * B2
        even = b[6] * B6 + b[4] * B4 + b[2] * B2
        for i in range(n):
            odd[i, i] += b[1]
            even[i, i] += b[0]
        U = mm(B, odd)
        E = solve(even - U, even + U)
        for _ in range(sq):
            E = mm(E, E)
        return E

    @numba.njit
    def phi(hJ, v, p):
        """phi_p(hJ) v: the exponential of [[hJ, v, 0], [0, 0, I], [0, 0, 0]] (size n + p)."""
        n = hJ.shape[0]
        M = np.zeros((n + p, n + p))
        M[:n, :n] = hJ
        M[:n, n] = v
        for i in range(p - 1):
            M[n + i, n + i + 1] = 1.0
        return expm(M)[:n, n + p - 1]

    @numba.njit
    def exprb(w, s, k, h, f0, J, cnt):
        U = w + h * phi(h * J, f0, 1)
        fU = np.empty(NW)
        F(U, s, k, fU)
        cnt[0] += 1
        corr = 2 * h * phi(h * J, (fU - J @ U) - (f0 - J @ w), 3)
        return U + corr, corr

    @numba.njit
    def jacobian(w, s, k, f0, J, cnt):
        wp, fp = w.copy(), np.empty(NW)
        for j in range(NW):
            d = 1e-7 * max(abs(w[j]), 1.0)
            wp[j] = w[j] + d
            F(wp, s, k, fp)
            J[:, j] = (fp - f0) / d
            wp[j] = w[j]
        cnt[0] += NW

    @numba.njit
    def toggle(e1, s, counts):
        """Switch every contact whose zero function is negative (the located one and any that crossed with it);
        how many switched."""
        n = 0
        for i in range(n_g):
            if e1[i] < 0.0:
                s[i] = 1.0 - s[i]
                counts[i] += 1.0
                n += 1
        return n

    def make_locate(step):
        @numba.njit
        def locate(w, s, k, hh, f0, J, cnt, e0, e1, ev_tol):
            """The step from w to the earliest crossing of the zero functions that crossed (e0 >= 0 > e1 at the
            step's end), to ``ev_tol``, by the Illinois method on the step length; (w there, its zero functions)."""
            crossed = (e1 < 0.0) & (e0 >= 0.0)
            em = np.empty(n_g)
            a, b = 0.0, hh
            fa, fb = np.min(np.where(crossed, e0, np.inf)), np.min(np.where(crossed, e1, np.inf))
            side, it = 0, 0
            while b - a > ev_tol and it < 100:
                it += 1
                m = b - fb * (b - a) / (fb - fa)
                if not a < m < b or it % 4 == 0:
                    m = 0.5 * (a + b)
                wm, _ = step(w, s, k, m, f0, J, cnt)
                zeros(wm, s, k, em)
                fm = np.min(np.where(e0 >= 0.0, em, np.inf))
                if fm < 0.0:
                    b, fb = m, fm
                    if side == -1:
                        fa *= 0.5
                    side = -1
                else:
                    a, fa = m, fm
                    if side == 1:
                        fb *= 0.5
                    side = 1
            w1, _ = step(w, s, k, b, f0, J, cnt)
            zeros(w1, s, k, em)
            return w1, em

        return locate

    @numba.njit
    def norm(w, w1, err, rtol, vw):
        """The error's largest ratio to its tolerance rtol (1 + |w|), the velocities' ``vw`` times looser."""
        out = 0.0
        for i in range(6):
            out = max(out, abs(err[i]) / ((rtol + rtol * max(abs(w[i]), abs(w1[i]))) * (vw if i >= 3 else 1.0)))
        return out

    return {"F": F, "zeros": zeros, "jacobian": jacobian, "exprb": exprb, "make_locate": make_locate,
            "toggle": toggle, "norm": norm, "NW": NW}


def make_integrator(problem, nm):
    """The numba exprb32 integrator of ``problem`` with the peer model ``nm``: ``run(z0, rtol, velocity_weight,
    ev_tol, Z, per) -> (steps, rejected, evaluations, jacobians, events)``, filling the hybrid states at the samples
    ``Z`` and the steps taken by the end of each output interval ``per``."""
    import numba

    kn = make_kernels(problem, nm)
    F, zeros, jacobian, step, NW = kn["F"], kn["zeros"], kn["jacobian"], kn["exprb"], kn["NW"]
    locate, toggle, norm = kn["make_locate"](step), kn["toggle"], kn["norm"]
    N, DTH, n_g = problem.samples, problem.span / problem.samples, nm.n_guards

    @numba.njit
    def run(z0, rtol, vw, ev_tol, Z, per):
        w = np.empty(NW)
        w[:6], w[6] = z0[:6], 0.0
        s, counts = z0[6:6 + n_g].copy(), z0[6 + n_g:].copy()
        f0, J, cnt = np.empty(NW), np.empty((NW, NW)), np.zeros(1, np.int64)
        e0, e1 = np.empty(n_g), np.empty(n_g)
        h, steps, rejected, jacobians, events = 1e-5, 0, 0, 0, 0
        for k in range(N):
            t_end = (k + 1) * DTH
            while w[6] < t_end * (1 - 1e-14):
                F(w, s, k, f0)
                cnt[0] += 1
                jacobian(w, s, k, f0, J, cnt)
                jacobians += 1
                zeros(w, s, k, e0)
                while True:  # until a step from w is accepted
                    hh = min(h, t_end - w[6])
                    w1, corr = step(w, s, k, hh, f0, J, cnt)
                    err = norm(w, w1, corr, rtol, vw)
                    if np.isfinite(err) and err <= 1.0:
                        break
                    rejected += 1
                    h = hh * (max(0.2, 0.9 * err ** (-1 / 3)) if np.isfinite(err) else 0.2)
                zeros(w1, s, k, e1)
                if ((e1 < 0.0) & (e0 >= 0.0)).any():
                    w1, e1 = locate(w, s, k, hh, f0, J, cnt, e0, e1, ev_tol)
                    events += toggle(e1, s, counts)
                    h = max(0.5 * hh, 1e-9)
                else:
                    h = hh * min(5.0, max(0.2, 0.9 * max(err, 1e-10) ** (-1 / 3)))
                w = w1
                steps += 1
            per[k] = steps
            Z[:6, k], Z[6:6 + n_g, k], Z[6 + n_g:, k] = w[:6], s, counts
        return steps, rejected, cnt[0], jacobians, events

    return run


def rows(an: Anatomy, rtols=(1e-5, 1e-6, 1e-7), velocity_weights=(1.0, 1000.0), ev_tol: float = 1e-10,
         log=print) -> list[dict]:
    """Steps (inside and outside the switch windows), evaluations, events and errors at each rtol and weight."""
    from .peer_source import numba_model

    p = an.problem
    nm = numba_model(p.effects, p.scene.assumptions)
    out = []
    n_g = nm.n_guards
    run = make_integrator(p, nm)
    Z, per = np.empty((6 + 2 * n_g, p.samples)), np.zeros(p.samples, np.int64)
    run(p.z0, 1e-3, 1.0, ev_tol, Z, per)  # compiles
    for vw in velocity_weights:
        for rtol in rtols:
            c0 = time.process_time()
            steps, rejected, rhs, jac, events = run(p.z0, rtol, vw, ev_tol, Z, per)
            cpu = time.process_time() - c0
            per_interval = np.diff(np.r_[0, per])
            traj = trajectory(p, Z)
            row = {"velocity_weight": vw, "rtol": rtol, "steps": int(steps),
                   "steps_inside": int(per_interval[an.windows].sum()), "rejected": int(rejected), "rhs": int(rhs),
                   "jacobians": int(jac), "events": int(events), "cpu_ms": 1e3 * cpu,
                   "friction_power": errors(traj, an.ref)["friction_power"]} | windowed_errors(traj, an.ref,
                                                                                               an.windows)
            out.append(row)
            log(row)
    return out


def markdown(an: Anatomy, rs: list[dict]) -> str:
    deg = int(round(np.degrees(an.problem.span)))
    outside = int((~an.windows).sum() * np.degrees(an.dtheta))
    ref_events = int(an.ref.events.sum())
    lines = [f"| {r['velocity_weight']:g} | {r['rtol']:g} | {r['state']:.1e} | {r['inside']:.1e} | "
             f"{r['outside']:.1e} | {r['steps']:,} ({(r['steps'] - r['steps_inside']) / outside:.1f}) | "
             f"{r['events']} ({ref_events}) | {r['rhs']:,} ({r['jacobians']:,}) | {r['cpu_ms']:.0f} ms |" for r in rs]
    return "\n".join([f"exprb32 with events over {deg} deg, {outside} deg of them outside the switch windows.", "",
                      "| velocity weight | rtol | scaled error | inside | outside | steps (outside the windows: per "
                      "degree) | events (reference) | RHS evaluations (Jacobians) | CPU / rev (prototype) |",
                      "|---" * 9 + "|", *lines])


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rtols", default="1e-5,1e-6,1e-7")
    ap.add_argument("--velocity-weight", default="1,1000", help="factors on the velocities' tolerance")
    a = ap.parse_args(argv)
    print("reference and switch windows ...", flush=True)
    an = Anatomy()
    rs = rows(an, tuple(float(x) for x in a.rtols.split(",")),
              tuple(float(x) for x in a.velocity_weight.split(",")), log=lambda r: print("  ", r, flush=True))
    print(markdown(an, rs))


if __name__ == "__main__":
    main()
