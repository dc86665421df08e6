"""Before the first step: the initial contact mode, and the refusal of runs that cannot give a meaningful result."""

from __future__ import annotations

import math

import numpy as np

from ...derive.submodels.registry import guard
from ...derive.submodels.seal import SealBody
from ...generated.layout import mode_label
from ..results.plausibility import FLANK_LENGTHS
from ..results.result import StopInfo
from ..scenes.checks import MAX_START_PENETRATION, wall_deflection_problem
from ..scenes.schema import rpm_of_omega
from ..scenes.units import show_factor
from .contact_stability import MAX_GROWTH, beyond, model_growth
from .friction_stability import friction_at_start
from .methods import method_of, run_steps
from .ringing import ringing
from .settings import RunSettings


def initial_activations(functions, theta: float, X: np.ndarray, params: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Which contacts are closed at the start: g < 0, and a guard exactly at 0 by the way it is heading.

    A guard exactly at 0 is closed if it is about to go negative: judged from a short
    second-order step (positions + h velocities + h²/2 accelerations), so that a seal
    at rest on a contact that the load presses shut counts as closing. The events then
    start from zero functions that grow, the only way CasADi's + to - events can see
    the next switch.
    """
    g = np.array(functions.guards(theta, X, params, u)).ravel()
    closed = g < 0
    on_guard = np.abs(g) <= 1e-15
    if on_guard.any():
        omega = functions.omega(params)
        xdot = np.array(functions.rhs(theta, X, closed.astype(float), params, u)).ravel()
        h = 1e-6 / omega  # 1e-6 rad of crank angle
        n_q = X.size // 2
        X2 = X + h * xdot + 0.5 * h * h * np.r_[xdot[n_q:], np.zeros(X.size - n_q)]
        g2 = np.array(functions.guards(theta + omega * h, X2, params, u)).ravel()
        closed = np.where(on_guard, g2 < 0, closed)
    return closed.astype(float)


def names_where(names, mask) -> str:
    return ", ".join(n for n, m in zip(names, mask, strict=True) if m)


#: the most contact oscillations per radian of crank angle a run can resolve (every method steps in crank angle)
MAX_OSCILLATIONS_PER_RAD = 1e8


def state_shown(i: int, value: float) -> str:
    """``operation.initial_state.<key> = <value> <unit>`` for entry ``i`` of the state, in the unit the seal's state
    declares for scenes (derive/submodels/seal.py, ``State.show``: the tilt in deg); an entry beyond the seal's (a
    chamber gas state, which no scene key sets) by its index, without a unit."""
    if i >= len(SealBody.states):
        return f"operation.initial_state.[{i}] = {value:.6g}"
    st = SealBody.states[i]
    show = st.show or st.unit
    return f"operation.initial_state.{st.name} = {value * show_factor(st.unit, show):.6g} {show}"


#: a ringing not computed yet (None is an answer: no contact)
_UNKNOWN = object()


def speed_problem(functions, params, theta: float = 0.0, X=None, ring=_UNKNOWN) -> str | None:
    """The rotor speed, if it is too slow for the seal's fastest ringing on its contacts to be followed in crank angle
    (runtime/solving/ringing.py: each contact mode's, from the model's Jacobian near the state ``X`` at crank angle
    ``theta``; default: the seal at rest in its groove's centre). ``ring``: that ringing where the caller has it
    (``ringing``'s answer, None included: no contact)."""
    p = dict(zip(functions.parameter_names, np.asarray(params, float), strict=True))
    omega = p["omega"]
    if ring is _UNKNOWN:
        X = np.zeros(len(functions.state_names)) if X is None else X
        ring = ringing(functions, params, theta, X)
    if ring is None:  # no contact in the model
        return None
    ratio = ring.per_rad(omega) if omega > 0 else math.inf
    if ratio <= MAX_OSCILLATIONS_PER_RAD:
        return None
    rpm, rpm_min = rpm_of_omega(omega), rpm_of_omega(ring.rad_s / MAX_OSCILLATIONS_PER_RAD)
    return (f"operation.rpm = {rpm:.3g} rpm is too slow to simulate in crank angle: the seal's fastest ringing on its "
            f"contacts (contact mode {ring.mode}, {ring.rad_s:.3g} rad/s) would oscillate {ratio * 2 * math.pi:.3g} "
            f"times per revolution; allowed: rpm >= {rpm_min:.3g} (at most {MAX_OSCILLATIONS_PER_RAD:g} oscillations "
            "per rad)")


def far_outside_practice(functions, params, pressure=None) -> str:
    """The scene keys whose values lie far outside engineering practice (runtime/scenes/units.py: the scene loaded
    them with a PlausibilityWarning), as a failed run's likely cause: "" when there is none. A length of 1e300 m or
    a speed of 1e300 rpm is no impossible machine, so no range refuses it, but the model's numbers overflow with
    it (a right-hand side that is not finite, a step size that falls below its minimum), and the failure alone
    names no key. A pressure table (``pressure``) in the wrong unit is named too (``pressure.unit``)."""
    from ...derive.submodels.registry import parameters
    from ..scenes.pressure import TablePressure
    from ..scenes.units import implausible, plausible_ranges, table_pressures_implausible

    keys = {p.name: p.key for p in parameters(all_inputs=True) if p.key}
    p = dict(zip(functions.parameter_names, np.asarray(params, float), strict=True))
    values = {keys[n]: (x, None) for n, x in p.items() if n in keys}
    if "omega" in p:
        values["operation.rpm"] = (rpm_of_omega(p["omega"]), None)
    ranges = plausible_ranges()
    shown = [f"{key} = {ranges[key].shown(x)} (engineering practice: {ranges[key].describe()})"
             for key, x, _ in implausible(values)]
    table = (table_pressures_implausible(pressure.pa, pressure.pb, pressure.unit)
             if isinstance(pressure, TablePressure) else None)
    if table:
        shown.append(f"pressure.unit = \"{pressure.unit}\": {table}")
    return "" if not shown else ("; values far outside engineering practice, the likely cause: " + "; ".join(shown))


def penetration_guards(guard_names) -> list[int]:
    """The indices of the guards whose depth is a penetration into a wall: every guard but those its submodel
    declares closed at rest (a preloaded spring's, whose guard is its compression)."""
    return [i for i, name in enumerate(guard_names) if not guard(name).closed_at_rest]


def start_problem(functions, params, theta, X, u) -> str | None:
    """The initial-state values, if they start the seal deep inside a wall (no meaningful contact force there)."""
    names = list(functions.guard_names)
    penalty = penetration_guards(names)
    p = dict(zip(functions.parameter_names, np.asarray(params, float), strict=True))
    limit = MAX_START_PENETRATION * p["Ws"]
    if not penalty:  # no contact to start inside
        return None

    def worst(state) -> tuple[float, int]:
        g = np.array(functions.guards(theta, state, params, u)).ravel()[penalty]
        g = np.where(np.isfinite(g), g, -np.inf)
        return float(g.min()), penalty[int(np.argmin(g))]

    depth, where = worst(X)
    if -depth <= limit:
        return None
    culprits = [i for i in range(X.size) if X[i] != 0 and -worst(np.where(np.arange(X.size) == i, 0.0, X))[0] <= limit]
    culprits = culprits or [i for i in range(3) if X[i] != 0]
    shown = ", ".join(state_shown(i, X[i]) for i in culprits)
    where_ = (f"{-depth * 1e6:.4g} µm inside a wall (guard {names[where]})" if math.isfinite(depth) else
              f"where a contact's geometry is not defined (guard {names[where]} is not finite: far outside its groove)")
    allowed = f"allowed: at most {MAX_START_PENETRATION:g} Ws = {limit * 1e6:.4g} µm of penetration at the start"
    if not shown:  # the seal at rest: the preload's wall deflection (Eq. 9), which a scene refuses on loading
        return wall_deflection_problem(p) or (f"the scene's parameters start the seal at rest {where_}; {allowed}: "
                                              "check the geometry and the contacts' stiffnesses")
    return f"{shown} starts the seal {where_}; {allowed}: check the initial state's units and sign"


def mouth_corner_lengths(functions, params, theta, X, closed, u) -> dict[str, float] | None:
    """The model's outputs l1..l4 at the state ``X``: where the groove's mouth corners g1, g3 meet the seal's
    sides, measured from the tip arc's ends c1, c3 (l1, l3) and from the back corners c2, c4 (l2, l4) along the
    seal (Eqs. 20-23; the groove submodel's outputs); all four are > 0 while both corners face the seal's flat
    sides, between its back face and its tip arc. None for a model without the groove contacts."""
    if not set(FLANK_LENGTHS) <= set(functions.output_names):
        return None
    y = np.asarray(functions.outputs(theta, X, closed, params, u), float).ravel()
    return {n: float(y[functions.output_names.index(n)]) for n in FLANK_LENGTHS}


def flank_problem(functions, params, theta, X, closed, u) -> str | None:
    """The initial-state values, if they start the seal where a groove mouth corner lies on its tip arc (sunk into
    the groove: the side contacts and faces of Eqs. 20-23 and 44-47 have no flat side to act on, the scene's
    seal.zeta0 check at rest) or past its back face (out of its groove, Eq. 17). A start too far out is also deep
    in the housing wall (:func:`start_problem`); one too far in met no check and ran until it chattered."""
    X = np.asarray(X, float)
    lengths = mouth_corner_lengths(functions, params, theta, X, closed, u)
    if lengths is None or min(lengths.values()) > 0 or not np.isfinite(X[:3]).all():
        return None
    l1, l2, l3, l4 = lengths.values()
    culprits = [i for i in range(3) if X[i] != 0] or [0]
    shown = ", ".join(state_shown(i, X[i]) for i in culprits)
    # with the seal upright at its groove's centre (y = phi = 0), l2 and l4 fall and l1 and l3 grow one for one
    # with x (Eqs. 17, 22-23): the range of x alone is where both are positive
    centred = mouth_corner_lengths(functions, params, theta, np.r_[0.0, 0.0, 0.0, X[3:]], closed, u)
    low, high = -centred["l1"], centred["l2"]
    where = ("a groove mouth corner on the seal's tip arc (sunk into its groove: l1 = "
             f"{l1 * 1e3:.6g} mm, l3 = {l3 * 1e3:.6g} mm from the arc's ends; the contact model has no flat side "
             "there, Eqs. 20-23, 44-47)" if min(l1, l3) <= 0 else
             f"its back face past the groove's mouth (out of its groove, Eq. 17: l2 = {l2 * 1e3:.6g} mm, l4 = "
             f"{l4 * 1e3:.6g} mm)")
    return (f"{shown} starts the seal with {where}; allowed: both mouth corners on the seal's flat sides, for x "
            f"alone {low * 1e3:.6g} mm < x < {high * 1e3:.6g} mm: check the initial state's units and sign")


def preflight(functions, settings: RunSettings, params, theta, X, closed, u,
              dtheta: float | None = None, ring=_UNKNOWN) -> StopInfo | None:
    """Refuse to start what cannot give a meaningful result, with the reason.

    * a rotor speed too slow for the seal's fastest ringing on its contacts (:func:`speed_problem`), an initial
      state that starts the seal deep inside a wall (:func:`start_problem`) or with its groove's mouth off its flat sides
      (:func:`flank_problem`): each names the scene value;
    * NaN/Inf in the right-hand side;
    * an explicit fixed-step method (euler, rk, erk-rk4: ``Method.stability``) with a step that amplifies the
      seal's ringing in a contact mode more than MAX_GROWTH times per revolution
      (runtime/solving/contact_stability.model_growth: each mode's frequency and damping from the model), or
      too long for the friction regularisation at the normal forces of the start, the spring's preload
      (runtime/solving/friction_stability.friction_at_start); its steps per revolution at the run's intervals of
      ``dtheta`` rad (default: its output intervals);
    * NaN/Inf in the derivative of the right-hand side, for every method whose declaration says that it
      differentiates it (``Method.needs_derivatives``: not euler, rk, composite): an infinite partial derivative
      with respect to a parameter (a function of the parameters at the edge of its domain,
      such as asin(1); beta_o = asin(Ws/(2 ro)) at ro = Ws/2 was one until it became a
      derived parameter) turns every automatic derivative into 0 * inf = NaN, although
      the right-hand side is finite.
    """
    mode = mode_label(functions.guard_names, closed)
    for problem in (speed_problem(functions, params, theta, X, ring), start_problem(functions, params, theta, X, u),
                    flank_problem(functions, params, theta, X, closed, u)):
        if problem:
            return StopInfo(0.0, mode, problem)
    xdot = np.array(functions.rhs(theta, X, closed, params, u)).ravel()
    if not np.isfinite(xdot).all():
        return StopInfo(0.0, mode, "the right-hand side is not finite at the start (NaN or Inf in "
                        f"{names_where(functions.state_names, ~np.isfinite(xdot))}): check the scene's values")
    steps = run_steps(settings, dtheta)
    if steps is not None:
        worst = beyond(model_growth(functions, params, steps, theta, X), math.log(MAX_GROWTH))
        if worst is not None:
            return StopInfo(0.0, mode, worst.describe())
        sticking = friction_at_start(functions, params, steps, theta, X, closed, u)
        if sticking is not None:
            return StopInfo(0.0, mode, sticking.describe())
    if not method_of(settings.method).needs_derivatives:
        return None
    try:  # the Jacobian Function: jac_rhs of the compiled library, or of SX Functions
        blocks = [np.array(b) for b in functions.rhs.jacobian()(theta, X, closed, params, u, xdot)]
    except (RuntimeError, NotImplementedError, TypeError):
        return None
    if all(np.isfinite(b).all() for b in blocks):  # d xdot / d (theta, x, a, p, u)
        return None
    J = blocks[3]  # d xdot / d p
    culprits = names_where(functions.parameter_names, ~np.isfinite(J).all(axis=0)) or "(none found)"
    return StopInfo(0.0, mode, f"the derivative of the right-hand side is not finite at the start although its value is "
                    f"(an infinite partial derivative with respect to {culprits}, which automatic differentiation turns "
                    f"into 0*inf = NaN); method {settings.method!r} needs derivatives. The scene sits on the edge of "
                    "the model's domain, where a function of these parameters has an infinite slope: move it off the "
                    "edge by a relative 1e-9 (nothing measurable changes) or use method 'euler'")
