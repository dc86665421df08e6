"""Where the composite method's evaluations go on the benchmark's problem: the clusters, the ringing, the rest.

``python -m apexseal.runtime.bench.phases [--rtols 1e-6,1e-8] [--scale v_eps=10]`` (about 16 s for three rtols;
``--scale mu1=0,mu2=0,mus=0``: no friction at all;
docs/bench/phases.md, read in docs/bench/levers.md, "Where the run method's evaluations go").

The run method ``composite`` (runtime/solving/composite.py) is called over the first k output intervals of the
benchmark's problem for k = 1 .. N, each call from the problem's start, so the difference of two calls' counts is
what the method spent in one interval (the sum over the intervals is one call's count, bit for bit: the method is
deterministic). Where the composite's quiet step may cross the end of an output interval (the pressures one line
over both), the call that ends there cuts it, so a single interval's count can be off by a step, even negative;
a group's is right to a step at each of its ends. The intervals are grouped by the reference's switches
(runtime/bench/anatomy.py):

* *cluster*: from the first to the last interval in which the reference switched a contact, of each run of
  switches closer together than the ring;
* *ring*: the :data:`~apexseal.runtime.solving.composite.RING` of crank angle after each cluster, where the
  composite's quiet phase may start only once its stiffness test finds RK45 at its stability boundary;
* *quiet*: the rest.

For each kind of group: evaluations, RK45 and exprb32 steps, events, and the stiffest eigenvalue of the mode's
Jacobian (the scaled state's six rates against the crank angle, from the model's CasADi Function at the
reference's state in the middle interval of the kind's longest group), with the RK45 steps per degree that
eigenvalue alone would impose (RK5(4)'s stability boundary on the negative real axis, h |lambda| = 3.3).
``--scale name=factor`` multiplies model parameters (for example ``v_eps=10``: a friction regularisation ten
times wider); the reference is then not that problem's, so the table reports work, not errors.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass

import numpy as np

from ...generated.hybrid import controls
from ..solving.composite import RING, CompositeIntegrator
from .anatomy import Anatomy

#: RK5(4)'s stability boundary on the negative real axis (Hairer and Wanner, Solving ODEs II, Sec. IV.2)
RK45_BOUNDARY = 3.3


@dataclass(frozen=True)
class Group:
    """Output intervals [start, stop) of one kind."""

    kind: str
    start: int
    stop: int


def groups(switched: np.ndarray, ring: int) -> list[Group]:
    """The intervals grouped into clusters of switches (gaps shorter than ``ring`` intervals), the ``ring``
    intervals after each, and the quiet intervals between."""
    n = switched.size
    idx = np.flatnonzero(switched)
    clusters: list[list[int]] = []
    for i in idx:
        if clusters and i - clusters[-1][1] <= ring:
            clusters[-1][1] = int(i)
        else:
            clusters.append([int(i), int(i)])
    out: list[Group] = []
    at = 0
    for a, b in clusters:
        if a > at:
            out.append(Group("quiet", at, a))
        out.append(Group("cluster", a, b + 1))
        end = min(n, b + 1 + ring)
        if end > b + 1:
            out.append(Group("ring", b + 1, end))
        at = end
    if at < n:
        out.append(Group("quiet", at, n))
    return out


def compiled_functions(an: Anatomy):
    """The problem's compiled model library's Functions: the composite runs inside it."""
    from ...generated.load import load_functions

    p = an.problem
    loaded = load_functions(p.effects, p.scene.assumptions, compiled=True).c
    if loaded.library is None:
        raise RuntimeError("the model library is not compiled (no C compiler): the composite needs it")
    return loaded


def per_interval(an: Anatomy, rtol: float, params: np.ndarray, functions) -> np.ndarray:
    """(N, 4): evaluations, RK45 steps, exprb32 steps and events of the composite (in the compiled
    ``functions``) in each output interval."""
    p = an.problem
    pressures = np.asarray(p.pressures)
    cum = np.zeros((p.samples + 1, 4), np.int64)
    for k in range(1, p.samples + 1):
        eng = CompositeIntegrator(functions, n_samples=k, span=k * an.dtheta, rtol=rtol, max_steps=10**6,
                                  max_events=10**8, pressure=p.pressure)
        eng.run(p.z0, params, p.theta0, pressures[:, :k + 1] if p.pressure == "linear" else pressures[:, :k])
        st = eng.stats()
        cum[k] = (st["n_rhs"], st["n_tight_steps"], st["n_quiet_steps"], st["n_events"])
    return np.diff(cum, axis=0)


def stiffest(an: Anatomy, params: np.ndarray, k: int) -> complex:
    """The eigenvalue of largest modulus of the mode's Jacobian (the six scaled rates) at the reference's state at
    the end of interval ``k``, per radian of crank angle."""
    import casadi as ca

    p, f = an.problem, an.problem.functions.hybrid_ode
    z = an.ref_z[:, k]
    t = (k + 1) * an.dtheta
    u = controls(np.asarray(p.pressures), an.dtheta * np.arange(1, p.samples + 1), p.pressure, f.size1_in(3))[:, k]
    zs = ca.SX.sym("z", f.size1_in(1))
    jac = ca.Function("j", [zs], [ca.jacobian(f(t, zs, np.r_[params, p.theta0], u), zs)])
    J = np.asarray(jac(z))[:6, :6]
    ev = np.linalg.eigvals(J)
    return complex(ev[np.argmax(np.abs(ev))])


def rows(an: Anatomy, rtols=(1e-6, 1e-8), scale: dict[str, float] | None = None, *, ring: float = RING,
         functions=None, log=print) -> list[dict]:
    """One row per rtol and group kind (the groups of a kind summed; the eigenvalue of the kind's longest group);
    ``ring`` (rad) as the composite's, ``functions`` compiled (default: :func:`compiled_functions`)."""
    p = an.problem
    functions = compiled_functions(an) if functions is None else functions
    params = np.array(p.params, float)
    names = list(p.functions.parameter_names)
    for name, factor in (scale or {}).items():
        params[names.index(name)] *= factor
    gs = groups(an.switched, int(round(ring / an.dtheta)))
    deg = math.degrees(an.dtheta)
    kinds = {}  # kind -> (its intervals, the stiffest eigenvalue in its longest group): the same at every rtol
    for kind in ("cluster", "ring", "quiet"):
        mine = [g for g in gs if g.kind == kind]
        if mine:
            sel = np.zeros(p.samples, bool)
            for g in mine:
                sel[g.start:g.stop] = True
            longest = max(mine, key=lambda g: g.stop - g.start)
            kinds[kind] = (sel, stiffest(an, params, (longest.start + longest.stop) // 2))
    out = []
    for rtol in rtols:
        per = per_interval(an, rtol, params, functions)
        total = int(per[:, 0].sum())
        for kind, (sel, lam) in kinds.items():
            width = sel.sum() * deg
            row = {"rtol": rtol, "kind": kind, "degrees": float(width), "evaluations": int(per[sel, 0].sum()),
                   "share": float(per[sel, 0].sum() / total), "rk45_steps": int(per[sel, 1].sum()),
                   "exprb32_steps": int(per[sel, 2].sum()), "events": int(per[sel, 3].sum()),
                   "rk45_per_degree": float(per[sel, 1].sum() / width), "stiffest": lam,
                   "stability_per_degree": abs(lam) / RK45_BOUNDARY * math.radians(1.0)}
            out.append(row)
            log(row)
    return out


def markdown(an: Anatomy, rs: list[dict], scale: dict[str, float] | None, ring: float = RING) -> str:
    deg = math.degrees(an.dtheta)
    gs = groups(an.switched, int(round(ring / an.dtheta)))
    spans = ", ".join(f"{g.kind} {g.start * deg:.0f}-{g.stop * deg:.0f}" for g in gs)
    lines = [f"| {r['rtol']:g} | {r['kind']} | {r['degrees']:.0f} | {r['evaluations']:,} ({100 * r['share']:.0f} %) | "
             f"{r['rk45_steps']:,} ({r['rk45_per_degree']:.1f}) | {r['exprb32_steps']:,} | {r['events']} | "
             f"{r['stiffest'].real:.3g}{r['stiffest'].imag:+.3g}j | {r['stability_per_degree']:.0f} |" for r in rs]
    what = "" if not scale else " Parameters scaled: " + ", ".join(f"{k} x {v:g}" for k, v in scale.items()) + "."
    return "\n".join([f"The composite on the benchmark's problem, by groups of output intervals ({spans} deg).{what}",
                      "", "| rtol | group | degrees | evaluations (share) | RK45 steps (per degree) | exprb32 steps | "
                      "events | stiffest eigenvalue (per rad) | RK45 steps per degree at its stability boundary |",
                      "|---" * 9 + "|", *lines])


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rtols", default="1e-6,1e-8")
    ap.add_argument("--scale", default="", help="model parameters multiplied, e.g. v_eps=10,mu2=0")
    a = ap.parse_args(argv)
    scale = {k: float(v) for k, v in (kv.split("=") for kv in a.scale.split(",") if kv)}
    print("reference and switch windows ...", flush=True)
    an = Anatomy()
    rs = rows(an, tuple(float(x) for x in a.rtols.split(",")), scale, log=lambda r: print("  ", r, flush=True))
    print(markdown(an, rs, scale))


if __name__ == "__main__":
    main()
