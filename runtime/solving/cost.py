"""What a run will cost, said before it integrates: a slow rotor against the seal's fastest ringing.

erk, the default method, is explicit: its step h stays within its stability region on the fastest ringing w of the
seal on its contacts (runtime/solving/ringing.py), h w <= 2.70 for the Dormand-Prince pair at that mode's damping
ratio (0.105 on the default scene; the bound of 1 + z + z^2/2 + z^3/6 + z^4/24 + z^5/120 + z^6/600 on the ray of
its eigenvalue, runtime/solving/contact_stability.py, ``eigenvalues``). A revolution lasts 2 pi / omega, so its
steps grow like w x 2 pi / omega, the radians the ringing turns through in one revolution
(:func:`ringing_per_revolution`): at 1 rpm 1500 times the default scene's at 1500 rpm. Measured on the default scene
(``apexseal simulate --set operation.rpm=60 -n 1 --max-wall-time 100``, interpreted with ``--set
solver.interpreted=true`` for its step count in result.json): 294568 steps over 5.07e5 rad of ringing,
:data:`STEPS_PER_RINGING_RAD` (rejected steps, events and the step controller's margin keep it above 1/2.70); wall
0.74 s compiled and 7.28 s interpreted. At 1 rpm (``apexseal simulate --set operation.rpm=1 -n 1``) the same
constant gives 1.76e7 steps, which took 52.1 s compiled: :data:`SECONDS_PER_STEP`.

Above :data:`SLOW_FACTOR` times the default scene's ringing per revolution, the run is announced with
:class:`SlowRunWarning` before its first step (:func:`slow_rotor_note`): the estimate, and what makes it cheaper.
Nothing is refused: a slow rotor is a valid scene, only an expensive one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..scenes.schema import rpm_of_omega

__all__ = ["DEFAULT_RINGING_PER_REVOLUTION", "SLOW_FACTOR", "Cost", "SlowRunWarning", "estimate", "slow_rotor_note"]

#: rad of the fastest ringing per revolution on the default scene: 5.07e5 rad/s (mode q3_h_s) x 2 pi / 157.08 rad/s
#: (1500 rpm); tests/runtime/test_cost.py checks it against the default scene
DEFAULT_RINGING_PER_REVOLUTION = 2.028e4
#: a run whose ringing per revolution is this many times the default scene's is announced before it starts: erk's
#: revolution then takes about 1.2e6 steps, 4 s compiled (0.08 s on the default scene) and half a minute interpreted:
#: long enough that a silent bar looks like a hang; below it a
#: revolution takes seconds at most. On the default seal: below 15 rpm.
SLOW_FACTOR = 100.0
#: erk's steps per rad of the fastest ringing (module docstring: 294568 steps / 5.07e5 rad at 60 rpm)
STEPS_PER_RINGING_RAD = 0.58
#: seconds per erk step on the default model, compiled and interpreted (module docstring: 52.1 s for 1.76e7 steps,
#: 7.28 s for 294568); a rough machine-dependent figure, for an order of magnitude
SECONDS_PER_STEP = {True: 3.0e-6, False: 2.5e-5}
#: the methods whose step follows the ringing: explicit and adaptive (the fixed-step ones take the steps they are
#: given, checked by the preflight; the implicit ones step over the ringing)
FOLLOWS_RINGING = ("erk",)
#: how many times faster rosenbrock ran the default scene at 1 rpm than erk (``apexseal simulate --set
#: operation.rpm=1 -n 1 --method rosenbrock``, its integrator compiled already: 1.23 s against 52.1 s), for the advice
ROSENBROCK_SPEEDUP = 40


class SlowRunWarning(UserWarning):
    """A run far costlier than the default scene's, said before it starts (:func:`slow_rotor_note`)."""


def ringing_per_revolution(ring_rad_s: float, omega: float) -> float:
    """The radians the seal's fastest ringing (rad/s) turns through in one revolution at ``omega`` rad/s."""
    return ring_rad_s * 2 * math.pi / omega


@dataclass(frozen=True)
class Cost:
    """What a run of ``revolutions`` (those still to run: a resumed run's left) is estimated to cost against the
    default scene's revolution."""

    factor: float  # ringing per revolution over the default scene's
    steps_per_revolution: float  # erk's
    revolutions: int  # still to run
    compiled: bool
    done: int = 0  # revolutions already run (a resumed run's)

    @property
    def seconds(self) -> float:
        """Integration time of the whole run, rough (:data:`SECONDS_PER_STEP`)."""
        return self.steps_per_revolution * self.revolutions * SECONDS_PER_STEP[self.compiled]

    def record(self) -> dict:
        """For the run's info (result.json)."""
        return {"factor_vs_default": self.factor, "steps_per_revolution": self.steps_per_revolution,
                "seconds": self.seconds, "compiled": self.compiled}


def estimate(ring, omega: float, settings, done: int = 0) -> Cost | None:
    """The cost of a run of ``settings`` (a ``RunSettings``) at ``omega`` rad/s whose fastest ringing is ``ring``
    (runtime/solving/ringing.py, ``Ringing``), of the revolutions left after ``done`` (a resumed run's); None where
    it does not follow the ringing (no contact, or a method other than :data:`FOLLOWS_RINGING`)."""
    if ring is None or not omega > 0 or settings.method not in FOLLOWS_RINGING:
        return None
    per_rev = ringing_per_revolution(ring.rad_s, omega)
    return Cost(per_rev / DEFAULT_RINGING_PER_REVOLUTION, per_rev * STEPS_PER_RINGING_RAD,
                max(settings.revolutions - done, 0), bool(settings.compile_c), done)


def _duration(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.2g} s"
    return f"{seconds / 60:.2g} min" if seconds < 7200 else f"{seconds / 3600:.2g} h"


def slow_rotor_note(cost: Cost | None, ring, omega: float) -> str | None:
    """The note of a run :data:`SLOW_FACTOR` times costlier than the default scene's, or None."""
    if cost is None or cost.factor < SLOW_FACTOR:
        return None
    rpm = rpm_of_omega(omega)
    other = _duration(cost.seconds * SECONDS_PER_STEP[not cost.compiled] / SECONDS_PER_STEP[cost.compiled])
    return (f"a slow run: at operation.rpm = {rpm:.3g} rpm the seal's fastest ringing ({ring.rad_s:.3g} rad/s, mode "
            f"{ring.mode}) takes erk about {cost.steps_per_revolution:.2g} steps per revolution, {cost.factor:.3g} "
            f"times the default scene's; {cost.revolutions} revolution(s)"
            + (f" left (of {cost.revolutions + cost.done})" if cost.done else "")
            + f": about {_duration(cost.seconds)} "
            f"{'compiled' if cost.compiled else 'interpreted'} ({other} {'interpreted' if cost.compiled else 'compiled'}"
            f"), on a machine like the one measured. Cheaper: a higher operation.rpm (the "
            f"cost falls in proportion), --method rosenbrock (implicit: its step does not follow the ringing; "
            f"{ROSENBROCK_SPEEDUP} times faster than erk on the default scene at 1 rpm), or fewer revolutions")
