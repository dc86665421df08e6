"""Error metrics against the reference, and the CPU time a method needs for a given error.

* State error: for each of x, y and phi, the maximum over the output samples of
  |method - reference|, divided by the reference's range (max - min) over the
  span; the *scaled error* of a point is the largest of the three.
* Friction power error: relative error of the mean of the total friction power
  ``Pf_total`` over the output samples (the cycle's mean friction power).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...derive.names import STATE_NAMES
from ...generated.layout import HybridLayout
from ...generated.scaling import to_physical

#: the seal's positions (x, y, phi), as the seal body declares its state
STATE_KEYS = STATE_NAMES[:3]


@dataclass
class Trajectory:
    X: np.ndarray  # (6, N) physical state at the samples
    closed: np.ndarray  # (n_g, N)
    events: np.ndarray  # (n_g,) switches counted by the integrator (or on the grid)
    friction_power: np.ndarray  # (N,) W

    @property
    def mean_friction_power(self) -> float:
        return float(np.mean(self.friction_power))


def trajectory(problem, z: np.ndarray) -> Trajectory:
    """Physical trajectory and friction power from hybrid integrator states z (generated/layout.py), (size, N)."""
    fns, N = problem.functions, problem.samples
    lay = HybridLayout.of(fns)
    X = to_physical(z[lay.x], problem.omega)
    closed = lay.closed(z).astype(float)
    events = z[lay.counts, -1] - problem.z0[lay.counts]
    if "Pf_total" in fns.output_names:
        Y = np.array(fns.outputs.map(N)(problem.theta[None, :], X, closed, np.repeat(problem.params[:, None], N, 1),
                                        problem.sample_pressures))
        pf = Y[list(fns.output_names).index("Pf_total")]
    else:
        pf = np.zeros(N)
    return Trajectory(X, closed, events, pf)


def errors(traj: Trajectory, ref: Trajectory) -> dict:
    """Scaled state errors (x, y, phi, and their max 'state') and the friction-power relative error."""
    out: dict = {}
    if traj.X.shape != ref.X.shape or not np.isfinite(traj.X).all():
        return {k: math.inf for k in (*STATE_KEYS, "state")} | {"friction_power": math.inf}
    for i, k in enumerate(STATE_KEYS):
        rng = float(np.ptp(ref.X[i]))
        out[k] = float(np.max(np.abs(traj.X[i] - ref.X[i])) / rng) if rng > 0 else None
    out["state"] = max(v for v in (out[k] for k in STATE_KEYS) if v is not None)
    pf = ref.mean_friction_power
    out["friction_power"] = abs(traj.mean_friction_power - pf) / abs(pf) if pf != 0 else None
    return out


def pareto(points: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """The (time, error) points not beaten by a faster, more accurate one, sorted by time."""
    front: list[tuple[float, float]] = []
    for t, e in sorted(p for p in points if p[0] > 0 and p[1] is not None and math.isfinite(p[1]) and p[1] > 0):
        if not front or e < front[-1][1]:
            front.append((t, e))
    return front


def time_at_error(points: list[tuple[float, float]], target: float, *, max_decades: float = 4.0,
                  orders: tuple[float, float] = (0.3, 12.0)) -> dict | None:
    """CPU time at ``target`` error on a curve's Pareto front, by log-log interpolation between the bracketing
    points; beyond the most accurate point, extrapolated along the last two points (flagged), but only over at most
    ``max_decades`` of error and when their slope means an order of convergence within ``orders``."""
    front = pareto(points)
    if not front:
        return None
    for k, (t, e) in enumerate(front):
        if e <= target:
            if k == 0:
                return {"time_s": t, "how": "measured (first point already below the target)", "error": e}
            (t0, e0) = front[k - 1]
            f = math.log(target / e0) / math.log(e / e0)
            return {"time_s": math.exp(math.log(t0) + f * math.log(t / t0)), "how": "interpolated", "error": target}
    if len(front) < 2:
        return {"time_s": None, "how": f"not reached (best error {front[-1][1]:.3g})", "error": front[-1][1]}
    (t0, e0), (t1, e1) = front[-2], front[-1]
    slope = math.log(t1 / t0) / math.log(e1 / e0)  # d log t / d log e (negative)
    order = -1 / slope if slope < 0 else 0.0  # error ~ cost^-order
    if not orders[0] <= order <= orders[1] or math.log10(e1 / target) > max_decades:
        return {"time_s": None, "how": f"not reached (best error {e1:.3g})", "error": e1, "order": order}
    return {"time_s": t1 * (target / e1) ** slope, "how": f"extrapolated from error {e1:.3g}", "error": target,
            "order": order}
