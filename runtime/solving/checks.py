"""What is checked after every integrator call: finite states within the model's geometry, an explicit fixed-step
method's steps on the friction regularisation, chattering, missed events, the event budget."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ...generated.layout import HybridLayout
from ...generated.scaling import LENGTH, to_physical
from ..results.result import StopInfo
from ..results.sampled import guards_at, outputs_at
from ..scenes.damping import MAX_DAMPING_RATIO, guard_damping
from .contact_stability import beyond, model_growth
from .friction_stability import FrictionWatch
from .methods import method_of, run_steps
from .settings import MAX_TILT, RunSettings

#: a contact left open while its gap is below this (µm) is a missed event, not event-location noise
MISSED_EVENT_UM = 1e-3
#: what to try when contacts chatter, besides the contact's damping (in the chattering message)
OTHER_REMEDIES = ("a larger friction.v_eps, or method 'euler' (the switches inside the right-hand side, no events); or "
                  "raise solver.chatter_events / max_events_per_revolution if the switches are physical")
#: a damping ratio this close to its default (relative) is the default: scenes state coefficients rounded (207 N*s/m
#: for 10 % of critical on 6.2e7 N/m is a ratio of 0.09998)
NEAR_DEFAULT = 0.1
#: the advice when the chattering contact's damping is not known (an unknown guard, or its damping off)
CHATTER_ADVICE = ("regularise instead of resolving every switch: contact damping near its default ratio "
                  f"(contacts.zeta_w/zeta_g/zeta_s = 0.1; above critical, {MAX_DAMPING_RATIO:g}, damping that acts on "
                  f"approach only kicks the seal off at each touch), {OTHER_REMEDIES}")


def chatter_advice(guard: str, names: Sequence[str] | None = None, params=None) -> str:
    """What to try when ``guard`` chatters, for the cause its contact's damping points to (``names``, ``params``: the
    run's parameter names and vector; without them, or for a guard whose damping is unknown: :data:`CHATTER_ADVICE`).

    Damped above critical (:data:`~..scenes.damping.MAX_DAMPING_RATIO`), the contact's approach-only damping is the
    likely cause, and more of it makes the chatter worse: lower it, with the key and the coefficient it may reach, or
    choose the damping law "penetration" (continuous at the touch). Otherwise its damping toward the default ratio
    (an undamped contact bounces; a stiff contact under light loads is kicked off by its approach-only damping below
    critical too, unless its damper is continuous at the touch), besides the other remedies."""
    values = None if names is None else dict(zip(names, np.asarray(params, float), strict=True))
    d = guard_damping(guard, values) if values is not None else None
    if d is None:
        return CHATTER_ADVICE
    c_key, ratio_key = d.keys
    now = f"the {d.owner} contact's damping: {ratio_key} = {d.zeta:.3g}, i.e. {c_key} = {d.c:.4g} N*s/m"
    default = d.default_ratio
    if d.too_high:
        return (f"this contact is damped above critical ({now}): {d.why}; lower {ratio_key} to "
                f"{MAX_DAMPING_RATIO:g} or less ({c_key} <= {d.critical:.4g} N*s/m"
                + (f"; the default ratio is {default:g})" if default is not None else ")"))
    if default is None or math.isclose(d.zeta, default, rel_tol=NEAR_DEFAULT) or (d.continuous and d.zeta > default):
        if d.continuous:
            now += ", damped in proportion to the penetration: continuous at the touch"
        return f"regularise instead of resolving every switch ({now}): {OTHER_REMEDIES}"
    toward = ("less damping on this contact, toward the default ratio (approach-only damping kicks a stiff contact "
              "under light loads off at each touch below critical too)" if d.zeta > default else
              "more damping on this contact, toward the default ratio (an undamped contact bounces)")
    return (f"regularise instead of resolving every switch: {toward}: {now}, the default ratio {default:g}; "
            f"{OTHER_REMEDIES}")


def tilt_reason(phi: float, theta: float) -> str:
    """Why a run stops where the seal's tilt ``phi`` (rad) exceeds :data:`MAX_TILT` at crank angle ``theta`` (rad,
    from the start)."""
    return (f"the seal turned by {np.degrees(phi):.4g} deg in its groove at {np.degrees(theta):.3f} deg, beyond the "
            f"model's geometry (Eqs. 20-43 hold for tilts of a few degrees; the run stops past "
            f"{np.degrees(MAX_TILT):g} deg): check the initial state (operation.initial_state.phi, phid) and the "
            "contacts that should hold the seal")


class Chattering(RuntimeError):
    def __init__(self, guard: str, theta: float, count: int, within: str = "within one output interval",
                 advice: str = CHATTER_ADVICE):
        super().__init__(f"chattering on guard {guard}: {count} switches {within} near {np.degrees(theta):.3f} deg; "
                         + advice)
        self.guard, self.theta, self.count = guard, theta, count


class RunChecks:
    """The checks of one run (see the module docstring); each returns ``(status, StopInfo)`` or None."""

    def __init__(self, functions, settings: RunSettings, params, theta_start: float, dtheta: float | None = None,
                 state0=None, path=None):
        """``dtheta``: the run's intervals (rad; default: its output intervals), at which a fixed-step method's steps
        per revolution are judged (:func:`~.methods.explicit_steps`); ``state0``: the state at ``theta_start`` (the
        contact modes' ringing is taken near it; default: the seal at rest in its groove's centre); ``path``: the
        parameters at given crank angles where a scene schedules them (``Scene.parameter_path``), the outputs and
        guards at the samples then evaluated with those (None: ``params`` everywhere)."""
        self.functions, self.settings, self.params, self.path = functions, settings, params, path
        self.theta_start = theta_start
        self.state0 = np.zeros(len(functions.state_names)) if state0 is None else np.asarray(state0, float)
        self.layout = HybridLayout.of(functions)
        self.omega = functions.omega(params)
        #: an explicit fixed-step method's steps (None for the others)
        self.steps = run_steps(settings, dtheta)
        self.sticking = FrictionWatch(functions, params, self.steps) if self.steps is not None else None

    def params_at(self, thetas) -> np.ndarray:
        """The parameters at the samples ``thetas``: the run's vector, or one per sample along a schedule."""
        return self.params if self.path is None else self.path(thetas)

    def finite(self, Z, thetas) -> tuple[np.ndarray, tuple | None]:
        """Z up to its first non-finite sample, and the failure it means (None if all finite)."""
        ok = np.isfinite(Z).all(axis=0)
        if ok.all():
            return Z, None
        lay = self.layout
        k = int(np.argmin(ok))
        last = Z[lay.active, k - 1] if k else np.zeros(lay.n_g)
        reason = f"non-finite state (NaN or Inf) at {np.degrees(thetas[k] - self.theta_start):.3f} deg"
        cause = self.unstable(contact_first=True)
        if cause:
            reason += "; " + cause
        return Z[:, :k], ("failed", StopInfo(thetas[k] - self.theta_start, lay.mode(last), reason))

    def unstable(self, contact_first: bool = False) -> str | None:
        """An explicit fixed-step method's step beyond its stability, the likely cause of a failure: a friction law
        it has taken beyond its bound while sticking at some samples of this revolution (fewer than stop the run,
        :meth:`friction`), or else a contact mode whose ringing it amplifies (less than the preflight refuses:
        runtime/solving/contact_stability.py); with ``contact_first``, the contact first (as a non-finite state of
        explicit Euler has always been explained). None for other methods, or where neither is seen."""
        if self.steps is None:
            return None
        amplified = beyond(model_growth(self.functions, self.params, self.steps, self.theta_start, self.state0), 0.0)
        contact = amplified.describe() if amplified is not None else None
        step = self.sticking.beyond() if self.sticking is not None and self.sticking.active else None
        friction = step.describe() if step is not None else None
        return (contact or friction) if contact_first else (friction or contact)

    def explained(self, failure: tuple | None) -> tuple | None:
        """A failed integrator call (``(status, StopInfo)``, runtime/solving/diagnosis.py) with the likely cause
        that :meth:`unstable` sees, if any."""
        if failure is None or failure[0] != "failed":
            return failure
        cause = self.unstable()
        if cause:
            failure[1].reason += "; " + cause
        return failure

    def tilt(self, Z, thetas) -> tuple[np.ndarray, tuple | None]:
        """Z up to its first sample whose tilt phi exceeds :data:`MAX_TILT` (the seal turned over in its groove,
        where no contact of the model holds it), and the failure it means (None if none does)."""
        lay = self.layout
        if "phi" not in lay.state_names or not Z.shape[1]:
            return Z, None
        phi = to_physical(Z[lay.x], self.omega, lay.state_names)[lay.state_names.index("phi")]
        over = np.abs(phi) > MAX_TILT
        if not over.any():
            return Z, None
        k = int(np.argmax(over))
        last = Z[lay.active, k - 1] if k else Z[lay.active, 0]
        reason = tilt_reason(phi[k], thetas[k] - self.theta_start)
        return Z[:, :k], ("failed", StopInfo(thetas[k] - self.theta_start, lay.mode(last), reason))

    def friction(self, Z, thetas, P) -> tuple[np.ndarray, tuple | None]:
        """Explicit fixed-step methods only: Z up to its first sample at which a friction law that can stick has had
        its regularisation beyond the method's stable step over more than a share of the revolution
        (runtime/solving/friction_stability.py), and the failure it means (None if none has)."""
        watch, lay = self.sticking, self.layout
        if watch is None or not watch.active or not Z.shape[1]:
            return Z, None
        n = Z.shape[1]  # a call cut short (a wall-time budget) has fewer samples than its intervals
        thetas, X = thetas[:n], to_physical(Z[lay.x], self.omega, lay.state_names)
        Y, _ = outputs_at(self.functions, thetas, X, Z[lay.active] > 0.5, self.params_at(thetas), P[:, :n])
        dth = thetas[1] - thetas[0] if thetas.size > 1 else 2 * np.pi / self.settings.samples_per_revolution
        found = watch.check(int((thetas[0] - self.theta_start) // (2 * np.pi)), Y, dth)
        if found is None:
            return Z, None
        k, step = found
        last = Z[lay.active, k - 1] if k else Z[lay.active, 0]
        return Z[:, :k], ("failed", StopInfo(thetas[k] - self.theta_start, lay.mode(last), step.describe()))

    def events(self, Z, z_start, thetas, P, z_rev) -> tuple | None:
        """Chattering, a missed contact event, or more events in this revolution than allowed."""
        if not Z.shape[1]:
            return None
        lay, st = self.layout, self.settings
        names = self.functions.parameter_names
        chatter = chattering(Z, lay, thetas - self.theta_start, z_start[lay.counts], st, names, self.params,
                             self.omega)
        if chatter is not None:
            return "chattering", StopInfo(chatter.theta, lay.mode(Z[lay.active, -1]), str(chatter))
        if method_of(st.method).locates_events:
            missed = self.missed_event(Z, thetas, P, z_start[lay.counts])
            if missed is not None:
                return missed
        in_rev = Z[lay.counts] - z_rev[lay.counts, None]  # switches of each guard since the revolution began
        over = in_rev.sum(axis=0) > st.max_events_per_revolution
        if over.any():
            k = int(np.argmax(over))  # the sample where the budget ran out
            i = int(np.argmax(in_rev[:, k]))
            where = float(thetas[k] - self.theta_start)
            c = Chattering(lay.guard_names[i], where, int(in_rev[i, k]),
                           f"in less than one revolution (of {int(in_rev[:, k].sum())} > max_events_per_revolution = "
                           f"{st.max_events_per_revolution})", chatter_advice(lay.guard_names[i], names, self.params))
            return "chattering", StopInfo(where, lay.mode(Z[lay.active, k]), str(c))
        return None

    def missed_event(self, Z, thetas, P, counts_before=None) -> tuple | None:
        """A contact the integrator holds open while its gap is negative: a lost event (the seal would pass the wall).

        Where that contact itself switched in the output interval before (``counts_before``: the event counts at the
        start of the call), its closing fell inside the blind window that CasADi keeps after each event (10
        event_tol), as where a contact chatters at its touch (it opens where the loads press it shut at once): the
        reason says so, with the advice for its contact (:func:`chatter_advice`), instead of calling it a bug."""
        lay = self.layout
        X = to_physical(Z[lay.x], self.omega, lay.state_names)
        g = guards_at(self.functions, thetas, X, self.params_at(thetas), P)
        bad = (Z[lay.active] < 0.5) & (g / LENGTH < -MISSED_EVENT_UM)
        if not bad.any():
            return None
        i, k = (int(v[0]) for v in np.nonzero(bad))
        guard, gap, where = lay.guard_names[i], g[i, k] / LENGTH, thetas[k] - self.theta_start
        cause = self.unstable()  # a fixed-step method's step beyond its stability loses events, as expected
        counts = None if counts_before is None else np.c_[counts_before, Z[lay.counts]]
        switched = 0 if counts is None else int(counts[i, k + 1] - counts[i, k])
        if switched and not cause:  # its closing fell in the blind window after an event: a touch it chatters at
            why = (f"it switched {switched} times in the output interval before, the last opening it, and its closing "
                   "fell inside the integrator's blind window after an event (10 solver.event_tol), as where a contact "
                   "chatters at its touch, the loads pressing it shut as soon as it opens: "
                   + chatter_advice(guard, self.functions.parameter_names, self.params))
            return "failed", StopInfo(where, lay.mode(Z[lay.active, k]), f"missed contact event: guard {guard} is "
                                      f"open in the integrator's mode but its gap is {gap:.4g} µm ({why})")
        why = f"the step is beyond what the method can follow: {cause}" if cause else "a bug: please report the scene"
        return "failed", StopInfo(where, lay.mode(Z[lay.active, k]),
                                  f"missed contact event: guard {guard} is open in the "
                                  f"integrator's mode but its gap is {gap:.4g} µm ({why})")


#: rad/s (1500 rpm, the paper's speed): at this rotor speed and above, the chattering detector's window is the crank
#: angle ``solver.chatter_window``; below it, the time that angle takes at this speed (see :func:`chatter_window`)
WINDOW_SPEED = 50.0 * np.pi


def chatter_window(settings: RunSettings, omega: float | None) -> float:
    """The chattering detector's window (rad of crank angle) at the rotor speed ``omega`` (rad/s; None: as given).

    A contact rings with a period in time, not in crank angle: at 10 rpm a window of 1e-3 rad lasts 150 times as long
    as at 1500 rpm and holds 150 times the bounces of a seal settling on a wall, which stopped ordinary low-speed
    runs as chattering. Below :data:`WINDOW_SPEED` the window is therefore the time ``chatter_window`` takes at that
    speed, a smaller crank angle; at and above it, the crank angle as given."""
    if omega is None or not omega < WINDOW_SPEED:
        return settings.chatter_window
    return settings.chatter_window * float(omega) / WINDOW_SPEED


def interval_limit(settings: RunSettings, dth: float, omega: float | None = None) -> float:
    """The switches of one guard in one interval of ``dth`` rad beyond which :func:`chattering` stops a run:
    ``chatter_events`` per chatter window (:func:`chatter_window` at the rotor speed ``omega``), scaled to the
    interval where it is longer than the window."""
    return settings.chatter_events * max(1.0, dth / chatter_window(settings, omega))


def chattering(Z, layout: HybridLayout, thetas, counts_before, settings: RunSettings,
               names: Sequence[str] | None = None, params=None, omega: float | None = None) -> Chattering | None:
    """More switches of one guard in one output interval than ``chatter_events`` per chatter window
    (:func:`chatter_window` at the rotor speed ``omega``), with the advice for that guard's contact
    (:func:`chatter_advice`; ``names``, ``params``: the run's parameters)."""
    counts = np.c_[counts_before, Z[layout.counts]]
    per_interval = np.diff(counts, axis=1)
    dth = thetas[1] - thetas[0] if thetas.size > 1 else 2 * np.pi / settings.samples_per_revolution
    hot = np.argwhere(per_interval > interval_limit(settings, dth, omega))
    if hot.size == 0:
        return None
    i, k = hot[0]
    guard = layout.guard_names[i]
    return Chattering(guard, float(thetas[k]), int(per_interval[i, k]), advice=chatter_advice(guard, names, params))
