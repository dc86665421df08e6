"""Explicit fixed-step methods on the friction regularisation: the largest step each resolves, and the checks before
and during a run, beside the contacts' (:mod:`.contact_stability`). Written for explicit Euler, they judge every explicit
fixed-step method (euler, rk, erk-rk4) through its stability function (runtime/solving/stability.py;
``Method.stability``).

Each Coulomb law is regularised as mu N tanh(v / v_eps) (Algorithm 1, Eq. 73; derive/submodels/laws.py). Where the
seal sticks (v near 0) that is a damper of coefficient mu N / v_eps on the sliding velocity: with the seal's mass
and inertia a first-order decay at a rate lambda (:class:`~apexseal.derive.submodels.base.Friction`; mu N / (v_eps ms)
for a slide that does not turn the seal). One step of length h multiplies a velocity decaying at that rate by
R(-h lambda), R the method's stability function: it decays while |R(-h lambda)| < 1, up to the real-axis bound of R
(:attr:`~.stability.StabilityFunction.real_bound`: 2 for explicit Euler, 2.785 for classical RK4). Explicit Euler's
step multiplies it by 1 - h lambda: between 1 and 2 the velocity changes sign at each step but still dies out within
a few steps; beyond 2 it grows, until tanh saturates, into a velocity that flips sign at every step and a friction
force that flips with it: Euler completes, with a wrong friction. RK4's R(-x) stays positive and passes 1 at 2.785:
beyond it the velocity grows without changing sign until tanh saturates, and RK4 completes with a wrong friction
too (docs/hard-cases.md). The submodels declare which of their laws can stick (the tip on the housing cannot: it
always slides at the rotor's speed); a law whose coefficient has no slot in the parameter vector (its effect off)
is not checked.

* Before the first step (:func:`friction_at_start`): the normal forces at the start (the spring's preload) are held
  all the run; h lambda beyond the method's bound there refuses the run.
* During the run (:class:`FrictionWatch`): from the normal forces the run reaches. The seal's impacts on the groove
  walls raise them beyond the bound for some hundredths of a degree each, and what the method gets wrong there ends
  with the impact; so the run stops where the bound is exceeded while the law sticks (:meth:`_Laws.steps_at`) over
  more than :data:`MAX_FRICTION_SHARE` of a revolution
  (:func:`beyond_shares` measures that share on any result; docs/hard-cases.md gives those of the repository's
  scenes).

N and the sliding speed are read from each contact's force and friction power (:func:`normal_and_speed`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...derive.submodels.base import Friction
from ...derive.submodels.registry import frictions, parameter
from .methods import METHODS, ExplicitSteps, explicit_steps
from .stability import EXPLICIT_EULER

__all__ = ["MAX_FRICTION_SHARE", "MAX_FRICTION_STEP", "FrictionStep", "FrictionWatch", "beyond_shares",
           "friction_at_start", "normal_and_speed"]

#: the largest h lambda explicit Euler may take: beyond it a sticking velocity flips sign at every step (another
#: method's: the real-axis bound of its stability function)
MAX_FRICTION_STEP = EXPLICIT_EULER.real_bound
#: the share of a revolution over which a run may exceed the method's bound (the seal's impacts on the groove)
MAX_FRICTION_SHARE = 0.02
#: tanh(u) is 1 to double precision beyond this u = v / v_eps
_SATURATED = 20.0


@dataclass(frozen=True)
class FrictionStep:
    """How an explicit fixed-step method treats one friction law where it sticks: h lambda = h mu N / (v_eps m) at
    the run's step, N its normal force (over its contacts) and m the seal's mass as the law moves it (ms, less where
    it turns the seal)."""

    law: Friction
    mu: float
    normal: float  # N
    mass: float  # kg
    v_eps: float  # m/s
    step: float  # h lambda
    steps: ExplicitSteps  # the method and its steps per revolution
    #: the share of a revolution over which the run reached ``step``; None: at the start, held all the run
    share: float | None = None
    #: where the run reached ``step``, if not over ``share`` (the message's words)
    reached: str = ""

    @property
    def steps_per_revolution(self) -> int:
        return self.steps.steps_per_revolution

    @property
    def bound(self) -> float:
        """The largest h lambda the method takes: the real-axis bound of its stability function."""
        return self.steps.stability.real_bound

    @property
    def steps_needed(self) -> int:
        """Steps per revolution that bring h lambda down to the method's bound."""
        return math.ceil(self.steps_per_revolution * self.step / self.bound)

    @property
    def v_eps_needed(self) -> float:
        """The friction.v_eps that brings h lambda down to the method's bound at the run's steps."""
        return self.v_eps * self.step / self.bound

    def describe(self) -> str:
        when = self.reached or ("at the start, held all the run" if self.share is None else
                                f"reached over {self.share:.0%} of a revolution")
        return (f"{self.steps.subject} cannot follow the friction of {self.law.slide} where it sticks: mu N tanh(v / v_eps) "
                f"is a damper mu N / v_eps there, and with {parameter(self.law.mu).key} = {self.mu:.3g}, a normal "
                f"force N = {self.normal:.3g} N ({when}), friction.v_eps = {self.v_eps:.3g} m/s and the seal's mass "
                f"as it slides m = {self.mass * 1e3:.3g} g, h mu N / (v_eps m) = {self.step:.3g} at "
                f"{self.steps_per_revolution} steps per revolution, above {self.bound:.3g}, where the sliding "
                f"velocity {self.steps.stability.beyond_real_bound()} and the friction with it: use at least "
                f"{self.steps.setting(self.steps_needed)} solver.euler_steps_per_revolution, a wider friction.v_eps "
                f"(at least {self.v_eps_needed:.3g} m/s), or method 'rosenbrock' or 'erk'")


def normal_and_speed(F, Pf, mu: float, v_eps: float) -> tuple[np.ndarray, np.ndarray]:
    """The normal force N of a contact and its sliding speed |v| from the magnitude ``F`` of its force and its
    friction power ``Pf`` (arrays).

    The Coulomb law of Algorithm 1 and Eq. 73 (:func:`~apexseal.derive.submodels.laws.coulomb`) adds mu N tanh(u)
    across N, u = v / v_eps, and dissipates Pf = mu N tanh(u) v: so F = N sqrt(1 + mu^2 tanh(u)^2) and
    Pf = mu F v_eps u tanh(u) / sqrt(1 + mu^2 tanh(u)^2), which grows with |u| and gives it by bisection (up to
    :data:`_SATURATED`, beyond which N no longer depends on it: the speeds there are not told apart).
    """
    F, Pf = np.asarray(F, float), np.asarray(Pf, float)
    if mu == 0:
        return F, np.full_like(F, np.inf)

    def power(u):
        t = np.tanh(u)
        return mu * F * v_eps * u * t / np.sqrt(1 + (mu * t) ** 2)

    lo, hi = np.zeros_like(F), np.full_like(F, _SATURATED)
    for _ in range(60):
        mid = (lo + hi) / 2
        below = power(mid) < Pf
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    u = (lo + hi) / 2
    return F / np.sqrt(1 + (mu * np.tanh(u)) ** 2), np.where(hi < _SATURATED, u * v_eps, np.inf)


class _Laws:
    """The friction laws that are on in a model (parameter values ``p`` by name; ``read``: the parameters its
    Functions read, None: all of ``p``; its ``output_names``), and a method's step h lambda on each at
    ``steps_per_revolution`` (its :class:`~.methods.ExplicitSteps`, or a number of explicit Euler's steps)."""

    def __init__(self, p: dict, read, output_names, steps_per_revolution: int | ExplicitSteps):
        self.outputs = list(output_names)
        self.laws = [f for f in frictions() if f.mu in p and (read is None or f.mu in read) and "v_eps" in p
                     and all(f"Pf_{c}" in self.outputs for c in f.contacts)]
        self.judged = ExplicitSteps.of(steps_per_revolution)
        self.bound = self.judged.stability.real_bound  # the largest h lambda the method takes
        self.p = p
        self.h = 2 * math.pi / (self.judged.steps_per_revolution * p["omega"])  # s: one step
        self.offsets = {f: np.array([a * p[name] for a, name in f.offsets] if f.offsets else [0.0] * len(f.contacts))
                        for f in self.laws}

    @classmethod
    def of(cls, functions, params, steps_per_revolution: int | ExplicitSteps) -> _Laws:
        """Those of a model's Functions at the parameter vector ``params``."""
        p = dict(zip(functions.parameter_names, np.asarray(params, float), strict=True))
        return cls(p, functions.parameters_read(), functions.output_names, steps_per_revolution)

    def steps_at(self, law: Friction, Y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(h lambda, the normal force N summed over the law's contacts, whether it sticks) at each column of the
        outputs ``Y`` (n_outputs, n). lambda is the largest eigenvalue of M^-1 C (the 2 x 2 of the slide and the
        seal's turn, :class:`~apexseal.derive.submodels.base.Friction`). The law sticks where a contact that
        carries a load slides slower than one step's friction can change its speed, h lambda v_eps: the step can
        then turn it back or throw it further, and beyond the method's bound does so at every step (a contact that
        slides faster keeps its direction, whatever the step)."""
        p, mu = self.p, self.p[law.mu]

        def at(name):
            return Y[self.outputs.index(name)]

        N, v = (np.array(a) for a in zip(*(normal_and_speed(np.hypot(at(f"F_{c}_X"), at(f"F_{c}_Y")), at(f"Pf_{c}"),
                                                            mu, p["v_eps"]) for c in law.contacts), strict=True))
        d = self.offsets[law][:, None]
        c11, c12, c22 = N.sum(axis=0), (N * d).sum(axis=0), (N * d * d).sum(axis=0)
        half_trace = (c11 / p["ms"] + c22 / p["Icg"]) / 2
        det = (c11 * c22 - c12 * c12) / (p["ms"] * p["Icg"])
        step = self.h * mu / p["v_eps"] * (half_trace + np.sqrt(np.maximum(half_trace**2 - det, 0.0)))
        sticks = ((N > 0) & (v < step * p["v_eps"])).any(axis=0)
        return step, c11, sticks

    def step(self, law: Friction, step: float, normal: float, share: float | None, reached: str = "") -> FrictionStep:
        p = self.p
        mass = self.h * p[law.mu] * normal / (p["v_eps"] * step) if step > 0 else p["ms"]
        return FrictionStep(law, p[law.mu], float(normal), float(mass), p["v_eps"], float(step), self.judged, share,
                            reached)


def friction_at_start(functions, params, steps_per_revolution: int | ExplicitSteps, theta, X, closed,
                      u) -> FrictionStep | None:
    """The law most beyond the method's bound at the start's normal forces (held all the run: the spring's
    preload), or None; ``steps_per_revolution``: the method's steps (:func:`~.methods.explicit_steps`), or a
    number of explicit Euler's."""
    laws = _Laws.of(functions, params, steps_per_revolution)
    y = np.array(functions.outputs(theta, X, closed, params, u)).reshape(-1, 1) if laws.laws else None
    worst = max((laws.step(f, *(float(a[0]) for a in laws.steps_at(f, y)[:2]), None) for f in laws.laws),
                key=lambda s: s.step, default=None)
    return worst if worst is not None and worst.step > laws.bound else None


def beyond_shares(result, steps_per_revolution: int | None = None, method: str = "euler") -> dict[str, float]:
    """For a result of any method: the largest share of a revolution over which each friction law that can stick
    has h lambda beyond the bound of the explicit fixed-step ``method`` (default: explicit Euler's, 2) at the normal
    forces of the result, for that method at ``steps_per_revolution`` (default: the scene's
    ``solver.euler_steps_per_revolution``) and the result's output intervals; by the scene key of the law's
    coefficient (the run check stops the method where one exceeds :data:`MAX_FRICTION_SHARE`)."""
    scene = result.scene
    dtheta = 2 * math.pi / (result.info.get("samples_per_revolution", scene.solver.samples_per_revolution)
                            * result.info.get("pressure_substeps", 1))
    judged = explicit_steps(method, steps_per_revolution or scene.solver.euler_steps_per_revolution, dtheta)
    if judged is None:
        raise ValueError(f"method = {method!r}: not an explicit fixed-step method; allowed: "
                         f"{', '.join(n for n in METHODS if METHODS[n].stability is not None)}")
    laws = _Laws(dict(scene.parameters), None, list(result.outputs), judged)
    Y = np.vstack([np.asarray(result.outputs[n], float) for n in laws.outputs])
    revolution = np.maximum(np.ceil(np.asarray(result.theta) / (2 * math.pi)) - 1, 0)  # a revolution's last sample
    out = {}
    for law in laws.laws:
        steps, _, sticks = laws.steps_at(law, Y)
        beyond = (steps > laws.bound) & sticks
        out[parameter(law.mu).key] = max(float(beyond[revolution == k].mean()) for k in np.unique(revolution))
    return out


class FrictionWatch:
    """The run check: a method's step on each friction law at each sample of a revolution, and where the share of
    the revolution beyond the method's bound first exceeds :data:`MAX_FRICTION_SHARE` (``steps_per_revolution``:
    the method's steps, :func:`~.methods.explicit_steps`, or a number of explicit Euler's)."""

    def __init__(self, functions, params, steps_per_revolution: int | ExplicitSteps):
        self._laws = _Laws.of(functions, params, steps_per_revolution)
        self._revolution = None
        self._seen: dict[Friction, list[tuple[np.ndarray, np.ndarray]]] = {}

    @property
    def active(self) -> bool:
        return bool(self._laws.laws)

    def check(self, revolution: int, Y: np.ndarray, dtheta: float) -> tuple[int, FrictionStep] | None:
        """The first of the samples ``Y`` (the outputs, n_outputs x n; ``dtheta`` rad apart; all in
        ``revolution``) at which a law has spent more than MAX_FRICTION_SHARE of the revolution beyond the
        method's bound, with the step the law reached over that share (of the revolution's samples up to the last
        of ``Y``); None if none has."""
        laws = self._laws
        if revolution != self._revolution:
            self._revolution, self._seen = revolution, {f: [] for f in laws.laws}
        allowed = MAX_FRICTION_SHARE * 2 * math.pi / dtheta  # samples
        first = None
        for law in laws.laws:
            self._seen[law].append(laws.steps_at(law, Y))
            steps, normals, sticks = (np.concatenate(a) for a in zip(*self._seen[law], strict=True))
            steps = np.where(sticks, steps, 0.0)  # a contact that slides fast keeps its direction
            beyond = np.cumsum(steps > laws.bound)[-Y.shape[1]:]  # over the revolution, at the samples of Y
            if beyond.size == 0 or beyond[-1] <= allowed:
                continue
            k = int(np.argmax(beyond > allowed))
            if first is None or k < first[0]:
                held = np.argsort(steps)[-math.ceil(allowed)]  # the sample of the step reached over that share
                first = k, laws.step(law, steps[held], normals[held], MAX_FRICTION_SHARE)
        return first

    def beyond(self) -> FrictionStep | None:
        """The law that has spent the largest share of this revolution's samples so far beyond the method's bound
        while it sticks (less than MAX_FRICTION_SHARE, or the run would have stopped), with the largest step it
        reached there; None if none has been beyond it: what a failure of the run may come from."""
        laws, worst, most = self._laws, None, 0
        for law, seen in self._seen.items():
            if not seen:
                continue
            steps, normals, sticks = (np.concatenate(a) for a in zip(*seen, strict=True))
            beyond = sticks & (steps > laws.bound)
            if beyond.sum() > most:
                k = int(np.argmax(np.where(beyond, steps, -np.inf)))
                most, worst = int(beyond.sum()), (law, steps[k], normals[k])
        if worst is None:
            return None
        return laws.step(*worst, None, f"at its largest, beyond the bound at {most} of this revolution's samples "
                         "before the failure")
