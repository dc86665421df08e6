"""The layout of the hybrid state that every engine integrates, in one place.

``z = [scaled continuous state (n_x), activation of each guard (n_g), event count of each guard (n_g)]``:
an activation is 1 while its contact is closed; a count goes up by one at each switch. Engines, the run loop,
the studies and the benchmark read and build ``z`` through a :class:`HybridLayout`, never by index arithmetic,
so a submodel that adds continuous states (or a new guard) changes nothing here.

Works on a single state (1-D numpy array, CasADi SX/MX column) and on a block of samples (2-D array, one
column per sample): the layout slices the first axis.

The controls u of the hybrid DAE are the chamber pressures over an output interval, in one of
:data:`PRESSURE_PROFILES` (:func:`.hybrid.controls` builds them), and, for a scene that schedules a parameter along
the revolution, the parameter vector's line over the interval (:data:`PARAMETER_PROFILES`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..derive.modes import Mode

#: how the chamber pressures vary over an output interval (:mod:`.hybrid`): "steps" = held at the interval's
#: mean; "linear" = linear between the values at the interval's ends (continuous: the default; every engine
#: of apexseal's, a user's engine lists what it takes in ``pressure_profiles``)
PRESSURE_PROFILES = ("steps", "linear")
#: how the physical parameters vary over an output interval: "constant" = the parameter vector of the call;
#: "linear" = linear between its values at the interval's ends (a scene's schedule, runtime/scenes/schedule.py),
#: carried in the controls after the pressures (:func:`.hybrid.parameter_controls`). An engine lists what it
#: takes in ``parameter_profiles``
PARAMETER_PROFILES = ("constant", "linear")


@dataclass(frozen=True)
class HybridLayout:
    """Where each part of the hybrid state lives (see the module docstring)."""

    state_names: tuple[str, ...]
    guard_names: tuple[str, ...]

    @classmethod
    def of(cls, functions) -> HybridLayout:
        """The layout of a set of model Functions (anything with ``state_names`` and ``guard_names``)."""
        return cls(tuple(functions.state_names), tuple(functions.guard_names))

    @classmethod
    def sized(cls, n_x: int, n_g: int) -> HybridLayout:
        """A layout of anonymous states and guards (for engines, which need sizes, not names)."""
        return cls(tuple(f"x{i}" for i in range(n_x)), tuple(f"g{i}" for i in range(n_g)))

    @classmethod
    def of_functions(cls, rhs, guards) -> HybridLayout:
        """The sizes of a right-hand side ``rhs(theta, x, ...)`` and its ``guards``."""
        return cls.sized(rhs.size1_in(1), guards.size1_out(0))

    @property
    def n_x(self) -> int:
        return len(self.state_names)

    @property
    def n_g(self) -> int:
        return len(self.guard_names)

    @property
    def size(self) -> int:
        return self.n_x + 2 * self.n_g

    @property
    def x(self) -> slice:
        """The scaled continuous state."""
        return slice(0, self.n_x)

    @property
    def active(self) -> slice:
        """The activations (1 = contact closed)."""
        return slice(self.n_x, self.n_x + self.n_g)

    @property
    def counts(self) -> slice:
        """The event counts."""
        return slice(self.n_x + self.n_g, self.size)

    def pack(self, x, active, counts=None) -> np.ndarray:
        """A hybrid state from its parts (counts default to zero)."""
        counts = np.zeros(self.n_g) if counts is None else counts
        return np.r_[np.asarray(x, float), np.asarray(active, float), np.asarray(counts, float)]

    def empty(self, n: int = 0) -> np.ndarray:
        """An empty block of ``n`` samples."""
        return np.zeros((self.size, n))

    def closed(self, z) -> np.ndarray:
        """The activations of z as booleans."""
        return np.asarray(z[self.active], float) > 0.5

    def mode(self, active: Sequence[float]) -> str:
        """The contact mode's label for these activations (Algorithm 3 names, see derive/modes.py)."""
        return mode_label(self.guard_names, active)


def mode_label(guard_names: Sequence[str], active: Sequence[float]) -> str:
    """The label of the mode with these activations (> 0.5 = closed), in ``guard_names`` order."""
    return Mode(tuple(bool(float(a) > 0.5) for a in active), tuple(guard_names)).label
