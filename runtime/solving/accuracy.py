"""What a run's numerical settings leave of its accuracy: loose tolerances, and methods that control no error.

The ranges of ``solver.rtol`` and ``solver.atol`` (runtime/solving/settings.py, :data:`~.settings.LIMITS`) refuse
what no run can use; inside them, a tolerance can still be too loose for the peaks a designer reads. Measured on
the default scene, one revolution at 3600 samples per revolution, against rtol 1e-8 (``apexseal simulate -n 1
--rtol R`` and ``--set solver.atol=A``, then ``apexseal compare`` of the folders; docs/hard-cases.md, "Loose
tolerances and fixed steps"): the means (friction power, mean housing force) stay within 0.2 % up to rtol 1e-2,
but the peaks (largest housing force, deepest penetrations, x extremes) move by up to 2 % at rtol 1e-5 and by up to
34 % (rtol 1e-4), 43 % (1e-3) and 80 % (1e-2); with atol alone, by up to 2 % at atol 1e-3 and 24 % at 1e-2 (atol is in the
integrator's scaled state: µm and mrad for the seal's positions, generated/scaling.py). A run looser than
:data:`LOOSE_RTOL` or :data:`LOOSE_ATOL` warns with :class:`AccuracyWarning`.

A fixed-step method (``Method.fixed_step``: euler, rk, erk-rk4, collocation) has no tolerance and estimates no
error: it completes whatever its error. Its run says so in a note (summary.json's ``accuracy``, a note of
``apexseal simulate``) and how to check it at the cost of a run: the same scene with erk, compared with ``apexseal
compare``. Half the step is a weaker check: on the default scene explicit Euler's largest housing force is 1.6
times erk's at 200000 and at 400000 steps per revolution. Nothing is added to the run itself. A tolerance given to
such a method (``--rtol``, ``simulate(scene, method="euler", rtol=...)``) warns with :class:`UnusedToleranceWarning`
that it has no effect, as scipy's ``solve_ivp`` does with options its method does not read.
"""

from __future__ import annotations

from .methods import method_of

__all__ = ["LOOSE_ATOL", "LOOSE_RTOL", "AccuracyWarning", "UnusedToleranceWarning", "accuracy", "loose_tolerances",
           "unused_tolerances"]

#: the loosest rtol whose peaks stay within 2 % of a tight run's on the default scene (rtol 1e-4 moved one by 34 %)
LOOSE_RTOL = 1e-5
#: the loosest atol (scaled state: µm, mrad) whose peaks stay within 2 % on the default scene (1e-2 moved one by 24 %)
LOOSE_ATOL = 1e-3


class AccuracyWarning(UserWarning):
    """A run whose tolerances are looser than its peaks bear (:func:`loose_tolerances`)."""


def _method_name(settings) -> str:
    """The run's method as its messages name it: its name, or the name of an engine class passed directly."""
    return settings.method if isinstance(settings.method, str) else getattr(settings.method, "__name__", "?")


class UnusedToleranceWarning(UserWarning):
    """A tolerance given to a fixed-step method, which reads none (:func:`unused_tolerances`)."""


def unused_tolerances(settings, given: dict) -> str | None:
    """What the tolerances ``given`` to a run (name -> value, None: not given) leave unused: a message when its
    method takes fixed steps and reads no rtol or atol, else None."""
    named = [f"{name} = {value:g}" for name, value in given.items() if value is not None]
    if not named or not method_of(settings.method).fixed_step:
        return None
    method = _method_name(settings)
    return (f"{' and '.join(named)} {'have' if len(named) > 1 else 'has'} no effect: method {method!r} takes fixed "
            f"steps (solver.euler_steps_per_revolution = {settings.steps_per_revolution}) and controls no error; "
            "an adaptive method reads it (erk, composite, rosenbrock, cvodes)")


def loose_tolerances(settings) -> str | None:
    """What a run's loose ``rtol``/``atol`` cost, for a warning; None when they are tight enough, or for a
    fixed-step method, which reads neither (an atol not given is the rtol, and is judged with it)."""
    if method_of(settings.method).fixed_step:
        return None
    loose = []
    if settings.rtol > LOOSE_RTOL:
        follows = " and the atol that follows it" if settings.atol is None else ""
        loose.append(f"solver.rtol = {settings.rtol:g}{follows} (peaks within 2 % need at most {LOOSE_RTOL:g})")
    if settings.atol is not None and settings.atol > LOOSE_ATOL:
        loose.append(f"solver.atol = {settings.atol:g} (peaks within 2 % need at most {LOOSE_ATOL:g}, in µm and "
                     "mrad)")
    if not loose:
        return None
    return (f"loose tolerance: {'; '.join(loose)}: the means (friction power, mean forces) hold, but the peaks "
            "(largest forces, deepest penetrations, extremes of x) move by tens of per cent (on the default scene "
            "rtol 1e-4 moved one by 34 %, rtol 1e-2 by 80 %, atol 1e-2 by 24 %; docs/hard-cases.md, \"Loose tolerances "
            "and fixed steps\"); for peaks, run at rtol 1e-6 (the default) without an atol, or tighter")


def accuracy(settings) -> dict:
    """The record of a run's error control, as summary.json carries it: ``error_control`` (False for a fixed-step
    method), and ``note``, what its results can be trusted for and how to check them (None: nothing to say)."""
    method = _method_name(settings)
    if not method_of(settings.method).fixed_step:
        return {"error_control": True, "note": loose_tolerances(settings)}
    steps = settings.steps_per_revolution
    # the measured example is explicit Euler's (docs/hard-cases.md); another fixed-step method is not said to match it
    euler = method == "euler"
    example = (" (on the default scene explicit Euler's largest housing force is 1.6 times erk's; docs/hard-cases.md, "
               "\"Loose tolerances and fixed steps\")") if euler else ""
    halved = (": on the default scene it moved that force by 0.4 %") if euler else ""
    return {"error_control": False, "note": (
        f"method {method!r} takes fixed steps (solver.euler_steps_per_revolution = {steps}) and estimates no "
        "error: it completes whatever its error, and its peaks (largest forces, deepest penetrations) can be "
        f"far off while the means hold{example}; to check, run the scene again with "
        "--method erk and apexseal compare the two folders (half the step, --set "
        f"solver.euler_steps_per_revolution={2 * steps}, shows part of the error only{halved})")}
