"""The paper's method: explicit Euler on the switched right-hand side, fixed step, and its stability on the contacts.

The engine is :class:`~.fixed_step.FixedStepIntegrator` with the Euler rule (z_{n+1} = z_n + h f(theta_n, z_n)).
How many steps per revolution keep it stable on each contact (:func:`contact_growth`) holds for every explicit
fixed-step method through its stability function, and lives in :mod:`.contact_stability`; it is named here too,
where it was first written for explicit Euler.
"""

from __future__ import annotations

from .contact_stability import MAX_GROWTH, ContactGrowth, contact_frequencies, contact_growth
from .fixed_step import EulerIntegrator

__all__ = ["MAX_GROWTH", "ContactGrowth", "EulerIntegrator", "contact_frequencies", "contact_growth"]
