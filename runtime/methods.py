"""The integration methods a scene can ask for, and their CasADi settings."""

from __future__ import annotations

import math

#: method -> (CasADi plugin, kind, one-line description)
METHODS: dict[str, tuple[str, str, str]] = {
    "erk": ("erk", "events", "adaptive RK45 (Dormand-Prince) with events located on its dense output; compiles to C"),
    "erk-rk4": ("erk", "events", "fixed-step RK4 with events on its dense output; compiles to C"),
    "rosenbrock": ("rosenbrock", "events", "L-stable Rosenbrock order 5(4) for stiff contacts, events on dense output; "
                   "compiles to C"),
    "cvodes": ("cvodes", "stepper", "SUNDIALS CVODES (BDF), mode switches located by the apexseal event loop"),
    "cvodes-adams": ("cvodes", "stepper", "SUNDIALS CVODES (Adams), mode switches located by the apexseal event loop"),
    "idas": ("idas", "stepper", "SUNDIALS IDAS, mode switches located by the apexseal event loop"),
    "rk": ("rk", "stepper", "fixed-step RK4 per output interval, mode switches located by the apexseal event loop"),
    "collocation": ("collocation", "stepper", "fixed-step Radau collocation, mode switches located by the event loop"),
    "euler": ("euler", "euler", "the paper's method: explicit Euler on the switched right-hand side, fixed step"),
}


def check_method(name: str) -> None:
    if name not in METHODS:
        import difflib

        near = difflib.get_close_matches(name, METHODS, n=1)
        hint = f"; did you mean '{near[0]}'?" if near else ""
        raise ValueError(f"solver.method = {name!r} is not a method{hint} Allowed: {', '.join(METHODS)}")


def fixed_steps(steps_per_revolution: int, dtheta: float) -> int:
    """Steps of a fixed-step method in an interval of ``dtheta`` rad of crank angle (at least 1).

    ``steps_per_revolution`` counts per revolution whatever the interval: a revolution may be cut into several
    integrator calls (a wall-time budget cuts it into 36), and each output interval gets its share.
    """
    return max(1, int(round(steps_per_revolution * dtheta / (2 * math.pi))))
