"""How fast the seal rings on its contacts, and whether a run's output samples resolve it.

A single penalty contact of stiffness k rings at sqrt(k/ms) only if it pushes through the seal's centre of
gravity. The contacts do not: a groove corner pushes at its arm a from the centre, so it also turns the seal
(moment of inertia Icg), and its own contact rings at sqrt(k (1/ms + a^2/Icg)), 1.9 sqrt(k/ms) for a back corner
of the default seal (a = ds2 = 4 mm against sqrt(Icg/ms) = 2.5 mm); two corners and the tip closed together ring
faster still. :func:`ringing` takes it from the model itself: for each mode (Algorithm 3's groove case with the
other contacts; the modes no other mode contains, since closing one more contact adds stiffness and can only raise
the frequencies), the seal is moved from its rest state until every contact of the mode is closed (penetrated by
:data:`PENETRATION`, Newton on the contacts' gaps), and the undamped natural frequencies are the square roots of
the eigenvalues of -(d accelerations / d positions)(d position rates / d velocities) of the model's right-hand
side there, with those contacts active (the linearised equations of motion M u' = f, Eq. 80, with every contact
law).
Friction, which the rest state does not engage, and damping move the ringing by a few percent.
:func:`mode_damping` adds each mode's damping ratio from the contacts' dampers; the explicit fixed-step methods'
stability check judges every mode by the two (runtime/solving/contact_stability.py, ``model_growth``), and the
preflight's speed check by the fastest ringing (runtime/solving/preflight.py, ``speed_problem``).

The output samples resolve a ringing of w rad/s when they take at least :data:`SAMPLES_PER_PERIOD` of its periods
(:func:`sampling`, the ``sampling`` record of a run and its summary.json): Nyquist's criterion, their Nyquist
frequency (samples per revolution x omega / 2) above w, with a margin. Below it the peaks, extremes and |Fs5|
spectrum computed from the samples see the ringing aliased (docs/paper-findings.md, "The main peak and the output
sampling"); :func:`samples_resolving` is the sampling to ask for, the same criterion in whole samples per degree.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...derive.names import STATE_NAMES
from .settings import LIMITS

__all__ = [
    "PENETRATION", "SAMPLES_PER_PERIOD", "VELOCITY", "ModeRinging", "Ringing", "describe_sampling", "mode_damping",
    "mode_frequencies", "ringing", "sampling", "samples_resolving",
]

#: m: how far every contact of a mode is pressed into its wall where the mode is linearised (a contact's force is
#: k max(penetration, 0): its stiffness acts only with some penetration; a nanometre moves no arm measurably)
PENETRATION = 1e-9
#: samples per period of the ringing that resolve it (:func:`sampling`, :func:`samples_resolving`): above the Nyquist
#: criterion's 2 by a fifth, for what the estimate at rest leaves out (friction and the motion move the ringing by a
#: few percent)
SAMPLES_PER_PERIOD = 2.4
#: m/s (rad/s for the tilt): how fast the seal moves along a mode where its damping is taken, slow against the
#: friction regularisation (its part of the Jacobian cancels out: :func:`mode_damping`)
VELOCITY = 1e-9
#: the seal's positions (x, y, phi) and their rates, the first entries of every model's state
_POSITIONS = len(STATE_NAMES) // 2


@dataclass(frozen=True)
class Ringing:
    """The highest undamped natural frequency of the seal on its contacts (``rad_s``), in the mode ``mode``."""

    rad_s: float
    mode: str

    def per_rad(self, omega: float) -> float:
        """Oscillations in rad of oscillation per rad of crank angle: the frequency over the rotor speed."""
        return self.rad_s / omega


def _maximal(modes) -> list:
    """The modes whose closed contacts no other mode's include (every other mode's frequencies are at most theirs)."""
    sets = [frozenset(i for i, c in enumerate(m.closed) if c) for m in modes]
    return [m for m, s in zip(modes, sets, strict=True) if not any(s < t for t in sets)]


def _closed_state(guards, guards_jac, theta, X, closed, params, u) -> np.ndarray | None:
    """``X`` with its positions moved until every contact of ``closed`` is penetrated by at least
    :data:`PENETRATION` (least-norm Newton steps on the gaps of those less deep, towards twice that); None when
    they cannot be closed together."""
    X = np.array(X, float)
    for _ in range(30):
        g = np.asarray(guards(theta, X, params, u), float).ravel()
        if not np.isfinite(g[closed]).all():
            return None
        short = closed & (g > -PENETRATION)  # a contact already deeper is left free
        if not short.any():
            return X
        G = np.asarray(guards_jac(theta, X, params, u), float)[short][:, :_POSITIONS]
        if not np.isfinite(G).all():
            return None
        X[:_POSITIONS] -= np.linalg.lstsq(G, g[short] + 2 * PENETRATION, rcond=None)[0]
    return None


def _linearised(functions, params, theta: float, X, modes=None):
    """For each mode of ``modes`` (default: every mode of the model) whose contacts close together near the state
    ``X`` at crank angle ``theta``, with a finite Jacobian there: the mode, the state where they are closed
    (velocities zero: the seal at rest there), the Jacobian of the right-hand side there with those contacts active,
    and a function J(state, params) of the same Jacobian at another state or parameter vector (module docstring)."""
    import casadi as ca

    sx = functions.sx()
    x = ca.SX.sym("x", sx.guards.size1_in(1))
    theta_, p, u_ = ca.SX.sym("theta"), ca.SX.sym("p", sx.guards.size1_in(2)), ca.SX.sym("u", sx.guards.size1_in(3))
    guards_jac = ca.Function("guards_jac", [theta_, x, p, u_], [ca.jacobian(sx.guards(theta_, x, p, u_), x)])
    u = np.zeros(sx.guards.size1_in(3))  # no chamber pressure: it does not stiffen a contact
    X = np.array(X, float)
    n = _POSITIONS
    X[n:2 * n] = 0.0
    params = np.asarray(params, float)
    for mode in functions.mode_list if modes is None else modes:
        closed = np.array(mode.closed, bool)
        at = _closed_state(functions.guards, guards_jac, theta, X, closed, params, u) if closed.any() else None
        if at is None:
            continue

        def jac(state, p_, closed=closed):
            return np.asarray(functions.rhs_jac(theta, state, closed.astype(float), p_, u, np.zeros(state.size))[1],
                              float)

        J = jac(at, params)
        if np.isfinite(J).all():  # a scene far outside practice can overflow it: no ringing to tell
            yield mode, at, J, jac


def _fastest(J) -> tuple[float, np.ndarray, np.ndarray]:
    """The highest undamped natural frequency of the linearised seal (the Jacobian ``J`` of its state), with the
    right and left eigenvectors of its mode: eigenvalues w^2 of (d position rates / d velocities)(-d accelerations /
    d positions), the stiffness seen in the positions."""
    n = _POSITIONS
    AK = -J[:n, n:2 * n] @ J[n:2 * n, :n]
    squares, right = np.linalg.eig(AK)
    i = int(np.argmax(squares.real))
    left_squares, left = np.linalg.eig(AK.T)
    j = int(np.argmin(np.abs(left_squares - squares[i])))
    return math.sqrt(max(float(squares[i].real), 0.0)), right[:, i].real, left[:, j].real


def mode_frequencies(functions, params, theta: float, X, modes=None) -> dict[str, float]:
    """The highest undamped natural frequency (rad/s) of the seal in each mode of ``modes`` (default: every mode of
    the model) whose contacts close together near the state ``X`` at crank angle ``theta`` (its velocities taken
    as zero: the seal at rest there), by the mode's label; module docstring."""
    return {mode.label: _fastest(J)[0] for mode, _, J, _ in _linearised(functions, params, theta, X, modes)}


@dataclass(frozen=True)
class ModeRinging:
    """The fastest ringing of one contact mode: its undamped frequency (``rad_s``), the damping ratio of that
    ringing from the contacts' dampers on average over a period (``zeta``), and the contacts closed in it."""

    mode: str
    rad_s: float
    zeta: float
    contacts: tuple[str, ...]


def mode_damping(functions, params, theta: float, X, dampers, undamped=(), modes=None) -> list[ModeRinging]:
    """The fastest ringing of each mode (:func:`mode_frequencies`) with its damping ratio, from the contacts'
    dampers ``dampers`` (parameter names), those of ``undamped`` counted as none.

    The damping is c max(v, 0) (Eqs. 55, 62, 67, 73): on approach only, so over a period of the ringing each damper
    acts on the half of it in which its contact closes. The ratio is that of the linearised seal, q'' + C q' + K q
    = 0 (q the positions), for the ringing of frequency w, right and left eigenvectors phi, psi of K: to first order
    in the damping, its eigenvalue is -zeta w +- i w with zeta = psi^T C phi / (2 w psi^T phi) (the modal damping
    ratio; exact for a single contact, where it is c / (2 sqrt(k ms))). C is the mean of the dampers' part of the
    Jacobian moving along +phi and along -phi (each damper acts in one of them): the Jacobian with the dampers less
    that without them, which leaves out friction (it damps too where the seal is at rest, but is no contact's
    ringing: runtime/solving/friction_stability.py). A damper that pushes at an arm from the centre of gravity damps
    the turning too: a mode that rings faster than one contact's sqrt(k/ms) because it turns the seal is damped
    more, in proportion (the ratio of a contact of stiffness k and damper c, c / (2 sqrt(k ms)), grows with its
    frequency as c w / (2 k)); on the default scene 0.105 at 5.07e5 rad/s against 0.05 at sqrt(kw/ms)."""
    n = _POSITIONS
    names = list(functions.parameter_names)
    params = np.asarray(params, float)
    damped, bare = params.copy(), params.copy()
    for c in dampers:
        bare[names.index(c)] = 0.0
        if c in undamped:
            damped[names.index(c)] = 0.0
    out = []
    for mode, at, J, jac in _linearised(functions, params, theta, X, modes):
        w, phi, psi = _fastest(J)
        A = J[:n, n:2 * n]  # position rates per velocity
        v = np.linalg.solve(A, phi / np.abs(phi).max()) * VELOCITY
        C = np.zeros((n, n))
        for sign in (1.0, -1.0):
            state = at.copy()
            state[n:2 * n] = sign * v
            C -= (jac(state, damped) - jac(state, bare))[n:2 * n, n:2 * n] / 2
        C = A @ C @ np.linalg.inv(A)  # in the positions' rates
        zeta = float(psi @ C @ phi) / (2 * w * float(psi @ phi)) if w > 0 else 0.0
        # dampers only take energy: below 0 is round-off (no damper at all: -1e-7); not finite, none is counted
        zeta = max(zeta, 0.0) + 0.0 if math.isfinite(zeta) else 0.0  # + 0.0: no -0.0 (max keeps it), printed "-0"
        guards = functions.guard_names
        out.append(ModeRinging(mode.label, w, zeta, tuple(g for g, c in zip(guards, mode.closed, strict=True) if c)))
    return out


def ringing(functions, params, theta: float, X) -> Ringing | None:
    """The fastest ringing of the seal on its contacts (:func:`mode_frequencies` of the modes that no other mode
    contains: closing one more contact adds stiffness, which cannot lower a natural frequency), linearised near the
    state ``X`` at crank angle ``theta``. None for a model whose contacts close in no mode (no contact at all)."""
    frequencies = mode_frequencies(functions, params, theta, X, _maximal(functions.mode_list))
    if not frequencies:
        return None
    mode = max(frequencies, key=frequencies.get)
    return Ringing(frequencies[mode], mode)


def samples_resolving(rad_s: float, omega: float) -> int:
    """The output samples per revolution that resolve a ringing of ``rad_s`` (:data:`SAMPLES_PER_PERIOD` per period of
    it, Nyquist's 2 with a margin), rounded up to a multiple of 360 (whole samples per degree): a run at this
    sampling has its ``sampling`` record's ``resolved`` true."""
    return 360 * math.ceil(SAMPLES_PER_PERIOD * rad_s / omega / 360)


def sampling(functions, params, ring: Ringing | None, samples_per_revolution: int) -> dict | None:
    """Whether ``samples_per_revolution`` output samples resolve the seal's fastest ringing ``ring``
    (:func:`ringing`): the record a run keeps (``info["sampling"]``, summary.json's ``sampling``); None for a model
    without contacts. ``resolved``: at least :data:`SAMPLES_PER_PERIOD` samples per period of the ringing
    (``samples_per_period``), the criterion :func:`samples_resolving` rounds up to whole samples per degree, so a
    run at ``samples_per_revolution_resolving`` is resolved and one with fewer samples per degree is not; the
    Nyquist frequency (``nyquist_rad_s``) above the ringing is the criterion without the margin."""
    omega = functions.omega(params)
    if ring is None:
        return None
    per_period = samples_per_revolution * omega / ring.rad_s if ring.rad_s > 0 else math.inf
    return {"ringing_rad_s": ring.rad_s, "ringing_mode": ring.mode,
            "nyquist_rad_s": samples_per_revolution * omega / 2, "samples_per_period": per_period,
            "resolved": bool(per_period >= SAMPLES_PER_PERIOD), "samples_per_revolution": int(samples_per_revolution),
            "samples_per_revolution_resolving": samples_resolving(ring.rad_s, omega)}


def describe_sampling(record: dict) -> str:
    """What a run's ``sampling`` record says, on one line: the ringing, the Nyquist frequency of its samples and
    how many of them a period of the ringing takes, and, where they do not resolve it, the setting that would."""
    head = (f"the contacts ring at up to {record['ringing_rad_s']:.3g} rad/s (mode {record['ringing_mode']}), the "
            f"Nyquist frequency of {record['samples_per_revolution']} output samples per revolution is "
            f"{record['nyquist_rad_s']:.3g} rad/s")
    per_period = record.get("samples_per_period")  # absent from the summaries written before it was recorded
    if per_period is not None:
        head += f" ({per_period:.3g} samples per period of the ringing; {SAMPLES_PER_PERIOD:g} resolve it)"
    if record["resolved"]:
        return head + ": the samples resolve the ringing"
    aliased = head + ": peaks, extremes and the |Fs5| spectrum computed from the samples see the ringing aliased; "
    needed, most = record["samples_per_revolution_resolving"], LIMITS["samples_per_revolution"][1].le
    if needed > most:  # slow rotors and stiff contacts: no allowed sampling resolves it
        return (aliased + f"resolving it would take {needed} samples per revolution, above the {most} allowed: read "
                "the peaks as lower bounds, and the spectrum only below the Nyquist frequency")
    return aliased + f"--set solver.samples_per_revolution={needed} resolves it"
