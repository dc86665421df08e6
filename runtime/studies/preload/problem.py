"""What the spring-preload study optimises: the preload as a parameter, the tip's contact force, the checks.

Shared by the IPOPT study (runtime/studies/preload/study.py) and its derivative-free check
(runtime/studies/preload/bisect.py), so both ask exactly the same question of exactly the
same model: the simulator's hybrid DAE (generated/hybrid.py) integrated by CasADi's
``erk`` with events, on the simulator's output grid and pressure means.

* **The preload as a parameter.** ``delta_s`` is one entry of the simulator's
  parameter vector, but two others follow from it: the rest deflection of the
  housing contact ``delta_w = ks delta_s / kw`` (Eq. 9) and the groove position
  ``Li = L - ds1 + delta_w`` (Eq. 12). The scene derives them; here the vector is
  the affine map ``p(delta_s) = p0 + dp * delta_s`` read off the scene at two
  preloads (and checked against a third), so the study's parameters are always
  those ``scene.with_overrides(spring.delta_s=...)`` would give.
* **The contact force measure.** In contact the tip presses on the housing with
  ``Fw = kw xs5 + cw max(v, 0)`` along the groove axis (Eq. 34 with the damping
  of Eq. 67; the X component of the housing force, Algorithm 2, which the
  simulator reports as ``-F_housing_X``). When the tip has lifted off the force
  is 0 whatever the preload, and a constraint on it has no gradient. The measure
  is therefore the contact force in contact and ``kw xs5 < 0`` (minus kw times
  the gap) in lift-off: continuous at lift-off (the damping term is 0 while the
  tip separates), equal to the force wherever the force is positive, and
  ``measure >= min_force > 0`` holds exactly when the tip is in contact with at
  least ``min_force``.
* **The checks.** The measure is checked at the output samples of one periodic
  revolution (the scene's ``samples_per_revolution``), except in the crank-angle
  windows the caller excludes. Nothing is promised between samples (the tip
  rings at ~1e4 rad/s after a chamber switch, ~4 deg of crank angle per period at
  1500 rpm: use samples of 0.1 deg or finer near the switches) nor in an
  excluded window.
"""

from __future__ import annotations

import math
import numbers
import warnings
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

from ....cores import parallel_threads
from ....generated.hybrid import controls as engine_controls
from ....generated.layout import HybridLayout
from ....generated.scaling import LENGTH, to_physical, to_scaled
from ...scenes.errors import show_repr
from ...scenes.schema import GAS_SOURCES
from ...solving.preflight import initial_activations
from .options import OBJECTIVES

#: the study's preload unit: decision variables and tolerances are in mm
MM = 1e-3
#: the largest force a study takes as min_force or max_groove_force (N), from the command line and the API alike:
#: far above any contact force of a seal
MAX_FORCE = 1e5
#: the largest max_preload (m) a study takes: far above any spring deflection of a seal
MAX_PRELOAD = 1.0


class PreloadStudyError(ValueError):
    """A bad request (the message names the option, the value and the allowed range)."""


@dataclass(frozen=True, eq=False)
class PreloadMap:
    """The simulator's parameter vector (the scene's model's, ``names``) as an affine function of delta_s (m)."""

    p0: np.ndarray
    dp: np.ndarray
    names: tuple[str, ...]

    def __call__(self, delta_s):
        return self.p0 + self.dp * delta_s

    def at(self, name: str) -> float:
        """A parameter's value at delta_s = 0 (the same at every preload for all but delta_s, delta_w and Li)."""
        return float(self.p0[self.names.index(name)])

    def spring_force(self, delta_s: float, **over: float) -> float:
        """N, the spring's force at rest at the preload ``delta_s`` (Eq. 39: the spring submodel's own law,
        ``SpringContact.push``), the parameters at the scene's values but ``over`` (e.g. ``ks=...``)."""
        from apexseal.derive.submodels.spring import SpringContact

        values = dict(zip(self.names, (float(v) for v in self(delta_s)), strict=True)) | over
        return float(SpringContact.rest_force(values))


def preload_parameters(scene) -> PreloadMap:
    """``p(delta_s)`` from the scene: delta_s itself, delta_w (Eq. 9) and Li (Eq. 12) move with it.

    The submodels' own formulas give p as a function of delta_s (``Scene.parameter_function``); its value at 0
    and its derivative make the map, checked at the scene's own preload.
    """
    f = scene.parameter_function("delta_s")
    d = ca.SX.sym("d")
    dp = ca.Function("dp", [d], [ca.jacobian(f(d), d)])
    pmap = PreloadMap(np.array(f(0.0)).ravel(), np.array(dp(0.0)).ravel(), tuple(scene.parameters))
    own = scene.parameter_vector()
    if not np.allclose(pmap(scene.parameters["delta_s"]), own, rtol=1e-12, atol=1e-15):
        moved = [n for n, a, b in zip(scene.parameters, pmap(scene.parameters["delta_s"]), own, strict=True)
                 if not np.isclose(a, b, rtol=1e-12, atol=1e-15)]
        raise PreloadStudyError(
            f"spring.delta_s: the preload study needs the parameters that move with the preload to move in proportion "
            f"(the paper's linear spring, Eq. 39); under this model's spring law (SpringContact.push, "
            f"derive/submodels/spring.py) {', '.join(moved)} do not: a non-linear spring law is not supported by "
            "the study's parametrisation (problem.preload_parameters)")
    return pmap


def contact_measure(functions) -> ca.Function:
    """``measure(theta, X, a, p, u)``: the tip's contact force (N) in contact, ``kw xs5`` (< 0) in lift-off.

    Contact force = ``-F_housing_X`` = kw xs5 + cw max(v, 0) (Eq. 34 with Eq. 67's damping, Algorithm 2).
    """
    g_names, o_names = tuple(functions.guard_names), tuple(functions.output_names)
    theta, X, a, p, u = (functions.outputs.sx_in(i) for i in range(5))
    ih, ifx, kw = g_names.index("xs5"), o_names.index("F_housing_X"), tuple(functions.parameter_names).index("kw")
    xs5 = -functions.guards(theta, X, p, u)[ih]  # the guard is -xs5 (closed while negative)
    force = -functions.outputs(theta, X, a, p, u)[ifx]
    act = a[ih]
    return ca.Function("tip_contact_measure", [theta, X, a, p, u], [act * force + (1 - act) * p[kw] * xs5],
                       ["theta", "x", "a", "p", "u"], ["measure"])


def check_mask(thetas: np.ndarray, exclude: tuple[tuple[float, float], ...]) -> np.ndarray:
    """True for the samples (crank angle, rad) outside every excluded window (start_deg, end_deg), mod 360."""
    deg = np.degrees(np.asarray(thetas, float)) % 360.0
    keep = np.ones(deg.shape, bool)
    for start, end in exclude:
        width = (end - start) % 360.0
        keep &= ~(((deg - start) % 360.0) <= width)
    return keep


def smallest_checked(thetas: np.ndarray, measure: np.ndarray, exclude: tuple[tuple[float, float], ...]) -> int:
    """The index of the smallest contact measure at the samples outside the excluded windows (:func:`check_mask`)."""
    return int(np.argmin(np.where(check_mask(thetas, exclude), measure, np.inf)))


def excluded(exclude: tuple[tuple[float, float], ...]) -> str:
    """The excluded windows as a run states them, e.g. ``" outside 350-10 deg (20 of 360 deg excluded)"``; the
    degrees excluded counted at the middles of a 0.01 deg grid, windows that overlap once; ``""`` for none."""
    if not exclude:
        return ""
    grid = np.radians((np.arange(36000) + 0.5) / 100.0)
    out = 360.0 - np.count_nonzero(check_mask(grid, exclude)) / 100.0
    windows = ", ".join(f"{start:g}-{end:g}" for start, end in exclude)
    return f" outside {windows} deg ({out:g} of 360 deg excluded)"


def parse_window(text: str) -> tuple[float, float]:
    """'START:END' in degrees of crank angle -> (start, end), checked as :func:`windows` checks it."""
    try:
        start, end = (float(v) for v in text.split(":"))
    except ValueError:
        raise PreloadStudyError(f"exclude = {text!r}: not a window START:END in degrees (e.g. 180:200)") from None
    return check_window(start, end, repr(text))


def check_window(start: float, end: float, shown: str) -> tuple[float, float]:
    """One excluded window (degrees of crank angle, taken mod 360: 350:10 wraps through 0). Its ends finite and less
    than a revolution apart: a whole revolution would exclude nothing (mod 360) although meant as everything."""
    if not (math.isfinite(start) and math.isfinite(end)):
        raise PreloadStudyError(f"exclude = {shown}: START and END must be finite (degrees, e.g. 180:200)")
    if start == end or abs(end - start) >= 360.0:
        raise PreloadStudyError(f"exclude = {shown}: END - START = {end - start:g} deg; allowed: 0 < |END - START| < 360 "
                                "deg (taken mod 360, a whole revolution would be an empty window), e.g. 180:200 or "
                                "350:10")
    return start, end


def check_grid(samples: int, nodes: int, knots: int) -> int:
    """lcm(nodes, knots), which must divide the samples: the shooting nodes and the schedule's knots fall on
    samples."""
    common = math.lcm(nodes, knots)
    if samples % common:
        raise PreloadStudyError(f"nodes = {nodes}, knots = {knots}: their least common multiple {common} must divide "
                                f"the {samples} samples per revolution")
    return common


#: the most excluded windows a study takes (the compiled functions' parameters hold this many)
MAX_WINDOWS = 4


def windows(exclude) -> tuple[tuple[float, float], ...]:
    """``exclude`` of the API (pairs of degrees, or the command line's "START:END" texts) as checked windows, or a
    :class:`PreloadStudyError` naming it."""
    if isinstance(exclude, str | bytes) or not hasattr(exclude, "__iter__"):
        raise PreloadStudyError(f"exclude = {exclude!r}: expected a list of (start_deg, end_deg) pairs, e.g. "
                                "[(180, 200)], or of \"START:END\" texts, e.g. [\"180:200\"]")
    out = []
    for w in exclude:
        if isinstance(w, str):
            out.append(parse_window(w))
            continue
        try:
            a, b = (float(v) for v in w)
        except (TypeError, ValueError):
            raise PreloadStudyError(f"exclude = {list(exclude)!r}: {w!r} is not a (start_deg, end_deg) pair of "
                                    "numbers, e.g. (180, 200)") from None
        out.append(check_window(a, b, f"({a:g}, {b:g})"))
    if len(out) > MAX_WINDOWS:
        raise PreloadStudyError(f"exclude = {out}: {len(out)} windows; allowed: at most {MAX_WINDOWS}")
    return tuple(out)


@dataclass(eq=False)
class Periodic:
    """Periodic revolutions of the simulator at several preloads (full simulations from the scene's start)."""

    deltas: np.ndarray  # (n,) m
    thetas: np.ndarray  # (samples,) crank angle of each sample of the last revolution (absolute, rad)
    z: np.ndarray  # (n, n_z, samples + 1) hybrid states of the last revolution, its start included
    change: np.ndarray  # (n,) max change of the scaled state between the starts of the last two revolutions
    measure: np.ndarray  # (n, samples) tip contact measure at the samples
    friction_power: np.ndarray  # (n,) mean friction power over the last revolution (W)


@dataclass(eq=False)
class PreloadSetup:
    """The study's model, grid and checks for one scene (see the module docstring)."""

    scene: object
    functions: object
    min_force: float
    exclude: tuple[tuple[float, float], ...] = ()
    samples: int | None = None  # per revolution; None: the scene's
    rtol: float | None = None  # None: the scene's
    revolutions: int = 3  # of every full simulation (the last one is the periodic revolution)
    flags: str = "quick"
    max_groove_force: float | None = None  # N: bound on every seal-groove contact force (None: no bound)
    pmap: PreloadMap = field(init=False)
    layout: HybridLayout = field(init=False)  # of the hybrid states the study integrates (generated/layout.py)
    measure_fn: ca.Function = field(init=False)
    compile_s: float = field(init=False, default=0.0)

    def __post_init__(self) -> None:
        if self.functions is not None:  # the study builds CasADi expressions: the SX set (of a compiled one too)
            self.functions = self.functions.sx()
        check_request(self.scene, self.min_force, self.samples, self.revolutions, self.max_groove_force)
        self.pmap = preload_parameters(self.scene)
        if self.functions is None:
            raise PreloadStudyError("functions = None: the study needs the scene's model; allowed: "
                                    "model_functions(scene)")
        names = tuple(self.functions.parameter_names)
        if names != self.pmap.names:  # the vectors of models of other effects differ: slots would be misread
            raise PreloadStudyError(f"functions: a model of other effects than the scene's (its parameters "
                                    f"{', '.join(sorted(set(names) ^ set(self.pmap.names)))} are not the scene's); "
                                    "allowed: the scene's own, model_functions(scene)")
        self.layout = HybridLayout.of(self.functions)
        self.measure_fn = contact_measure(self.functions)
        self.samples = int(self.samples or self.scene.solver.samples_per_revolution)
        if self.rtol is None:
            self.rtol = self.scene.solver.rtol
        self.settings()  # rtol and flags checked as a run checks them (a SettingsError names the field and range)
        if coarse := coarse_pressure(self.scene, self.samples):
            from ....stacklevel import user_stacklevel

            warnings.warn(coarse, UserWarning, stacklevel=user_stacklevel())
        self.rtol = float(self.rtol)
        self._engine = None
        self._mapped: dict[int, ca.Function] = {}

    # -- grid ---------------------------------------------------------------
    @property
    def theta_start(self) -> float:
        return float(self.scene.operation.start_angle)

    @property
    def dth(self) -> float:
        return 2 * np.pi / self.samples

    @property
    def profile(self) -> str:
        """The scene's pressure profile (``solver.pressure``): "steps" or "linear"."""
        return self.scene.solver.pressure

    def engine_pressures(self, edges: np.ndarray) -> np.ndarray:
        """The chamber pressures as the simulator's engines take them over the intervals between ``edges``:
        (2, n) interval means ("steps") or (2, n + 1) values at the edges ("linear"); zeros without them."""
        linear = self.profile == "linear"
        if not self.scene.effects.chamber_pressure:
            return np.zeros((2, edges.size - 1 + linear))
        return np.asarray(self.scene.pressure(edges) if linear else self.scene.pressure.interval_means(edges), float)

    def pressures(self, edges: np.ndarray) -> np.ndarray:
        """The chamber pressures at the samples ``edges[1:]`` as the run's outputs see them: the mean of the
        interval a sample ends ("steps") or the value at it ("linear"); (2, n)."""
        P = self.engine_pressures(edges)
        return P if self.profile == "steps" else P[:, 1:]

    def controls(self, edges: np.ndarray, per_call: int) -> np.ndarray:
        """The study integrators' controls over the n intervals between ``edges``, for calls of ``per_call``
        intervals from ``edges[0]``: (4, n), the pressures at each call's tau = 0 along the interval's line and
        their slopes (zero for "steps"; generated/hybrid.py). Column j's first two rows at the first
        interval of a call are the pressures at the call's start."""
        P = self.engine_pressures(edges)
        if self.profile == "steps":
            return np.vstack([P, np.zeros_like(P)])
        slope = np.diff(P, axis=1) / self.dth
        tau0 = (np.arange(P.shape[1] - 1) % per_call) * self.dth
        return np.vstack([P[:, :-1] - slope * tau0, slope])

    def settings(self):
        from ...api import settings_of

        return settings_of(self.scene, method="erk", rtol=self.rtol, samples_per_revolution=self.samples,
                           flags=self.flags)

    # -- full simulations -----------------------------------------------------
    def engine(self):
        """The simulator's compiled erk integrator over one revolution (runtime/solving/event_integrator.py)."""
        if self._engine is None:
            import time

            from ...solving.methods import make_engine

            t = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                self._engine = make_engine(self.functions, self.settings(), n_samples=self.samples)
            self.compile_s += time.perf_counter() - t
        return self._engine

    def mapped(self, n: int) -> ca.Function:
        """The compiled one-revolution integrator mapped over n preloads, a thread per core (:func:`parallel_threads`)."""
        if n not in self._mapped:
            self._mapped[n] = self.engine().function.map(n, "thread", parallel_threads(n))
        return self._mapped[n]

    def start_state(self, delta_s: float) -> np.ndarray:
        """The hybrid state at the scene's start (its initial state, contacts closed by their gaps)."""
        u0 = self.engine_pressures(self.theta_start + np.array([0.0, self.dth]))[:, 0]  # the run's start
        return self.hybrid_start(self.theta_start, self.pmap(delta_s), u0)

    def hybrid_start(self, theta: float, p: np.ndarray, u0: np.ndarray) -> np.ndarray:
        """The hybrid state of the scene's initial state (runtime/api.py ``initial_state``) at crank angle
        ``theta``, parameters ``p`` and pressures ``u0``: each contact closed by its gap, no events counted."""
        from ...api import initial_state

        lay = self.layout
        X = initial_state(self.scene, self.functions)
        act = initial_activations(self.functions, theta, X, p, u0)
        return lay.pack(to_scaled(X, self.pmap.at("omega"), lay.state_names), act)

    def state_change(self, before: np.ndarray, after: np.ndarray) -> np.ndarray:
        """The largest change of the scaled state from the hybrid state(s) ``before`` to ``after`` (one per
        column), relative to max(1, its size at ``after``)."""
        x = self.layout.x
        return np.max(np.abs(after[x] - before[x]) / np.maximum(1.0, np.abs(after[x])), axis=0)

    def periodic(self, deltas) -> Periodic:
        """Simulate ``revolutions`` revolutions from the scene's start at each preload (one mapped call per
        revolution, both cores) and return the last revolution of each."""
        deltas = np.atleast_1d(np.asarray(deltas, float))
        n, N, lay = deltas.size, self.samples, self.layout
        F = self.mapped(n)
        P = np.stack([self.pmap(d) for d in deltas], axis=1)
        z = np.stack([self.start_state(d) for d in deltas], axis=1)
        starts = [z.copy()]
        for rev in range(self.revolutions):
            edges = self.theta_start + rev * 2 * np.pi + self.dth * np.arange(N + 1)
            U = self.pressures(edges)
            engine = self.engine()
            u = engine_controls(self.engine_pressures(edges), engine.grid, self.profile, engine.hybrid.dae["u"].size1())
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                out = F(x0=z, p=np.r_[P, np.full((1, n), edges[0])], u=np.tile(u, (1, n)))
            Z = np.array(out["xf"]).reshape(z.shape[0], n, N)  # column i N + j: preload i, sample j
            z0 = z
            z = Z[:, :, -1].copy()
            z[lay.counts] = 0.0  # event counts per revolution
            starts.append(z.copy())
        if not np.isfinite(Z).all():
            bad = [f"{d / MM:.4g} mm" for d, ok in zip(deltas, np.isfinite(Z).all(axis=(0, 2)), strict=True) if not ok]
            raise RuntimeError(f"the simulation turned non-finite at delta_s = {', '.join(bad)}")
        thetas = edges[1:]
        full = np.concatenate([z0[:, :, None], Z], axis=2).transpose(1, 0, 2)  # (n, n_z, N + 1)
        full[:, lay.counts, 0] = 0.0
        change = self.state_change(starts[-2], starts[-1])
        meas = np.stack([self.measure_at(full[i, :, 1:], thetas, self.pmap(d), U) for i, d in enumerate(deltas)])
        power = np.array([self.friction_power(full[i, :, 1:], thetas, self.pmap(d), U) for i, d in enumerate(deltas)])
        return Periodic(deltas, thetas, full, change, meas, power)

    def at_samples(self, fn: ca.Function, Z: np.ndarray, thetas: np.ndarray, P: np.ndarray, U: np.ndarray) -> np.ndarray:
        """``fn(theta, X, a, p, u)`` (the model's ``outputs`` or :attr:`measure_fn`) at the samples: hybrid states
        ``Z`` (n_z, n) at crank angles ``thetas`` (n,), parameters ``P`` (n_par, n), pressures ``U`` (2, n)."""
        lay = self.layout
        X = to_physical(Z[lay.x], self.pmap.at("omega"), lay.state_names)
        return np.array(fn.map(thetas.size)(thetas[None, :], X, Z[lay.active], P, U))

    def measure_at(self, Z: np.ndarray, thetas: np.ndarray, p: np.ndarray, U: np.ndarray) -> np.ndarray:
        return self.at_samples(self.measure_fn, Z, thetas, np.repeat(p[:, None], thetas.size, 1), U).ravel()

    def friction_power(self, Z: np.ndarray, thetas: np.ndarray, p: np.ndarray, U: np.ndarray) -> float:
        Y = self.at_samples(self.functions.outputs, Z, thetas, np.repeat(p[:, None], thetas.size, 1), U)
        return float(Y[tuple(self.functions.output_names).index("Pf_total")].mean())

    def mask(self, thetas: np.ndarray) -> np.ndarray:
        return check_mask(thetas, self.exclude)

    def smallest(self, sim) -> tuple[float, float]:
        """A re-simulated revolution's (schedule.py) smallest tip contact measure at the checked samples (N) and its
        crank angle (deg, mod 360)."""
        j = smallest_checked(sim.thetas, sim.measure, self.exclude)
        return float(sim.measure[j]), float(np.degrees(sim.thetas[j]) % 360.0)


def is_integer(x) -> bool:
    """An integer (Python's or numpy's), not a bool."""
    return isinstance(x, numbers.Integral) and not isinstance(x, bool | np.bool_)


def quantity_of(name: str, value: Any, unit: str, largest: float) -> Any:
    """A study option given as a quantity ("5 N", "10 mm", a pint quantity), in the SI ``unit``, as the command line
    and the scene take it; any other value as it is (checked by the option's own test). A text that is no quantity
    of the kind is a :class:`PreloadStudyError` naming the option and its range, (0, ``largest``]."""
    from ...scenes.units import QuantityError, parse_quantity, quantity_text

    value = quantity_text(value) or value
    if not isinstance(value, str):
        return value
    try:
        return parse_quantity(value, unit)
    except QuantityError as err:
        raise PreloadStudyError(f"{name} = {value!r}: {err.reason}; allowed: > 0 and <= {largest:g} {unit}") from None


def study_quantities(min_force, max_groove_force=None, max_preload=None) -> tuple:
    """The study's quantity options (:func:`quantity_of`): ``min_force`` and ``max_groove_force`` in N (None: no
    bound), ``max_preload`` in m (None where the caller takes none)."""
    return (quantity_of("min_force", min_force, "N", MAX_FORCE),
            None if max_groove_force is None else quantity_of("max_groove_force", max_groove_force, "N", MAX_FORCE),
            None if max_preload is None else quantity_of("max_preload", max_preload, "m", MAX_PRELOAD))


def max_rate_of(max_rate) -> Any:
    """``max_rate`` of the API in m per degree: a number (m per degree, where the command line's ``--max-rate`` is in
    mm per degree) or a quantity per angle ("0.01 mm/deg"); None: no bound. A text without an angle ("0.01 mm", which
    pint would read per radian) is a :class:`PreloadStudyError`; other values as they are (checked by the study)."""
    from ...scenes.units import quantity_text

    text = quantity_text(max_rate) or max_rate
    if isinstance(text, str) and "/" not in text:
        raise PreloadStudyError(f"max_rate = {text!r}: expected a length per angle, e.g. '0.01 mm/deg' (a number: m "
                                "per degree in Python, mm per degree on the command line)")
    return quantity_of("max_rate", max_rate, "m/deg", MAX_PRELOAD)


def max_rate_problem(max_rate, knots) -> str | None:
    """What is wrong with a schedule's slope bound ``max_rate`` (m per degree, > 0; None: no bound), or None: it
    bounds a schedule's slope (a constant preload, ``knots`` = 1, has none)."""
    if max_rate is None:
        return None
    if not (isinstance(max_rate, numbers.Real) and not isinstance(max_rate, bool | np.bool_) and max_rate > 0):
        return f"max_rate = {show_repr(max_rate)}: must be > 0 m per degree, e.g. 1e-5 or '0.01 mm/deg' (or None: no bound)"
    if is_integer(knots) and knots == 1:
        return (f"max_rate = {show_repr(max_rate)}: bounds the slope of a schedule, and a constant preload (knots = 1) has "
                "none: give knots >= 2 or max_rate=None")
    return None


def max_rate_unbinding(max_rate, knots: int, max_preload: float) -> str | None:
    """Why a schedule's slope bound ``max_rate`` (m per degree, checked) can never bind, or None: it is at or above
    the steepest slope ``knots`` within 0..``max_preload`` can have (mostly a rate meant in mm per degree, as the
    command line's --max-rate takes it)."""
    if max_rate is None or knots < 2:
        return None
    steepest = max_preload / (360.0 / knots)
    if max_rate < steepest:
        return None
    return (f"max_rate = {max_rate:g} m per degree never binds ({knots} knots {360 / knots:g} deg apart within "
            f"0..max_preload = {max_preload:g} m change by at most {steepest:.3g} m per degree): the schedule is "
            "optimised without a slope bound. From Python a number is in m per degree (the command line's --max-rate "
            "is in mm per degree): give e.g. '0.01 mm/deg'")


def is_force(x) -> bool:
    """A force the study takes (N): a real number in (0, MAX_FORCE]."""
    return isinstance(x, numbers.Real) and not isinstance(x, bool | np.bool_) and 0 < x <= MAX_FORCE


def nodes_problem(nodes) -> str | None:
    """What is wrong with a study's number of shooting ``nodes`` (an integer in 2..64), or None."""
    return None if is_integer(nodes) and 2 <= nodes <= 64 else f"nodes = {nodes!r}: must be an integer in 2..64"


def max_preload_problem(max_preload) -> str | None:
    """What is wrong with a study's ``max_preload`` (a length in (0, MAX_PRELOAD] m), or None."""
    if isinstance(max_preload, numbers.Real) and not isinstance(max_preload, bool | np.bool_) \
            and 0 < max_preload <= MAX_PRELOAD:
        return None
    return f"max_preload = {show_repr(max_preload)}: must be a length > 0 and <= {MAX_PRELOAD:g} m"


#: the largest deficit_tol (N^2 rad) a study takes, from the command line and the API alike
MAX_DEFICIT_TOL = 1e3


def deficit_tol_problem(deficit_tol) -> str | None:
    """What is wrong with a study's ``deficit_tol`` (the bound of the squared force deficit, in (0, MAX_DEFICIT_TOL)
    N^2 rad), or None."""
    if isinstance(deficit_tol, numbers.Real) and not isinstance(deficit_tol, bool | np.bool_) \
            and 0 < deficit_tol < MAX_DEFICIT_TOL:
        return None
    return f"deficit_tol = {show_repr(deficit_tol)}: must be in (0, {MAX_DEFICIT_TOL:g}) N^2 rad"


#: the most knots a preload schedule takes
MAX_KNOTS = 72


def option_problems(**options) -> dict[str, str]:
    """What is wrong with each of the study options given (by name, as ``optimise_preload`` takes them, converted to N
    and m), by name: the one statement of their ranges, for the API and the command line alike
    (:func:`.study.check_option`)."""
    checks = {
        "nodes": nodes_problem,
        "knots": lambda v: None if is_integer(v) and 1 <= v <= MAX_KNOTS else
        f"knots = {v!r}: must be an integer in 1..{MAX_KNOTS} (1: a constant preload)",
        "min_force": lambda v: None if is_force(v) else
        f"min_force = {show_repr(v)}: must be a force > 0 and <= {MAX_FORCE:g} N (a number, in N)",
        "max_groove_force": lambda v: None if v is None or is_force(v) else
        f"max_groove_force = {show_repr(v)}: must be a force > 0 and <= {MAX_FORCE:g} N, or None (no bound)",
        "max_iter": lambda v: None if is_integer(v) and v >= 1 else
        f"max_iter = {v!r}: must be an integer >= 1 (IPOPT's iterations)",
        "objective": lambda v: None if v in OBJECTIVES else f"objective = {v!r}: must be one of {', '.join(OBJECTIVES)}",
        "deficit_tol": deficit_tol_problem,
        "max_rate": lambda v: max_rate_problem(v, options.get("knots")),
        "rounds": lambda v: None if is_integer(v) and 1 <= v <= 10 else f"rounds = {v!r}: must be an integer in 1..10",
        "max_preload": max_preload_problem,
        "samples": lambda v: None if v is None or is_integer(v) and 36 <= v <= 100000 else
        f"samples = {v!r}: must be an integer in 36..100000 (samples per revolution)",
    }
    return {k: p for k, v in options.items() if (p := checks[k](v))}


def coarse_pressure(scene, samples: int) -> str | None:
    """Why a study on ``samples`` output samples a revolution integrates other chamber pressures than
    ``apexseal simulate`` of the same scene, or None. The study's integrators take the pressures linear (or held
    at their mean) over each output interval; a run cuts each interval into ``pressure_substeps`` parts when the
    scene's pressure table has more rows a revolution than it has samples (runtime/solving/run.py), so that it sees
    every row. Coarser than the table, the study cuts the table's corners: its optimum, friction power and
    smallest force are those of another pressure input than a simulation of its scene.toml."""
    from ...solving.run import pressure_substeps

    if not scene.effects.chamber_pressure:
        return None
    sub = pressure_substeps(scene.pressure, samples)
    if sub == 1:
        return None
    rows = scene.pressure.rows_per_revolution()
    return (f"samples = {samples}: coarser than the scene's pressure table ({rows} rows a revolution): the study "
            f"takes the chamber pressures {scene.solver.pressure} over each of its {samples} intervals and cuts "
            f"the table's corners, while apexseal simulate of the same scene (the report's scene.toml) cuts each "
            f"interval into {sub} to see every row, so its numbers differ from the study's (the transients after "
            f"the chamber switches most); allowed for the same pressures: samples >= {rows}")


def check_request(scene, min_force, samples, revolutions, max_groove_force=None) -> None:
    """Reject what the study cannot answer, naming the option, its value and the allowed range."""
    found = option_problems(max_groove_force=max_groove_force, min_force=min_force, samples=samples)
    problems = list(found.values())
    if max_groove_force is not None and "max_groove_force" not in found and not scene.effects.groove_contact:
        problems.append(f"max_groove_force = {max_groove_force!r}: the scene's groove contacts are off "
                        "(effects.groove_contact); there is no groove force to bound")
    if not (is_integer(revolutions) and 2 <= revolutions <= 50):
        problems.append(f"revolutions = {revolutions!r}: must be an integer in 2..50")
    eff = scene.effects
    if not (eff.spring and eff.housing_contact):
        off = " and ".join(f"effects.{n} = false" for n in ("spring", "housing_contact") if not getattr(eff, n))
        problems.append(f"{off}: the preload study needs both 'spring' and 'housing_contact' on (the spring presses "
                        "the tip on the housing)")
    if scene.schedule is not None:
        problems.append("spring.schedule: the preload study designs the preload along the revolution itself, from "
                        "one constant preload (its start, and the design its schedule is compared with): give the "
                        "scene spring.delta_s instead of [spring.schedule]")
    source = scene.pressure.to_dict()["source"]
    if source in GAS_SOURCES:
        problems.append(f"pressure.source = {source!r}: the preload study takes the chamber pressures as the run's "
                        "inputs (allowed: \"table\", \"constant\", \"none\"), not as states of the gas model")
    if problems:
        raise PreloadStudyError("; ".join(problems))


__all__ = ["LENGTH", "MM", "Periodic", "PreloadMap", "PreloadSetup", "PreloadStudyError", "check_mask",
           "contact_measure", "parse_window", "preload_parameters"]
