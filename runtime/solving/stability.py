"""Stability functions of the explicit fixed-step rules: what one step does to a decaying or oscillating mode.

On the test equation y' = lambda y one step of an explicit Runge-Kutta method of length h multiplies y by
R(h lambda), a polynomial: 1 + z for explicit Euler, 1 + z + z^2/2 + z^3/6 + z^4/24 for classical RK4 (Hairer &
Wanner, Solving Ordinary Differential Equations II, Sec. IV.2). A mode the
true solution damps grows under the method where |R(h lambda)| > 1. The checks of a fixed-step method (its
``Method.stability``, runtime/solving/methods.py) evaluate R at the eigenvalue of each contact oscillator
(runtime/solving/contact_stability.py) and compare h lambda of a sticking friction law, a real eigenvalue, with
:attr:`StabilityFunction.real_bound` (runtime/solving/friction_stability.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np


@dataclass(frozen=True)
class StabilityFunction:
    """R(z) = 1 + sum_k a_k z^k of an explicit fixed-step rule, ``coefficients`` = (a_1, a_2, ...)."""

    name: str  # the rule, for messages ("explicit Euler", "classical RK4")
    coefficients: tuple[float, ...]

    def __call__(self, z: complex) -> complex:
        return 1 + self.excess_term(z)

    def excess_term(self, z: complex) -> complex:
        """R(z) - 1, summed without the 1 (its digits are lost in 1 + a small z otherwise)."""
        return sum(a * z**k for k, a in enumerate(self.coefficients, start=1))

    def growth_excess(self, z: complex) -> float:
        """|R(z)|^2 - 1 = 2 Re d + |d|^2 with d = R(z) - 1: positive where one step amplifies the mode."""
        d = self.excess_term(z)
        return 2 * d.real + abs(d) ** 2

    def log_modulus(self, z: complex) -> float:
        """ln |R(z)|: the logarithm of what one step multiplies the mode by (-inf where R(z) = 0)."""
        x = self.growth_excess(z)
        return 0.5 * math.log1p(x) if x > -1 else -math.inf

    @cached_property
    def real_bound(self) -> float:
        """The x > 0 where |R(-x)| first reaches 1: the longest step, h lambda, the rule takes on a real decaying
        mode without amplifying it (2 for explicit Euler, 2.785 for classical RK4); the smallest positive real
        root of R(-x) - 1 and R(-x) + 1."""
        roots = []
        for one in (-1.0, 1.0):
            # numpy.roots takes the highest power first: R(-x) + one = 1 + one + sum a_k (-1)^k x^k
            c = [a * (-1) ** k for k, a in enumerate(self.coefficients, start=1)][::-1] + [1.0 + one]
            roots += [r.real for r in np.roots(c) if abs(r.imag) < 1e-12 and r.real > 1e-12]
        x = min(roots)
        for _ in range(3):  # Newton on |R(-x)| - 1, where numpy.roots left a rounding error
            r = self(-x).real
            dr = -sum(k * a * (-x) ** (k - 1) for k, a in enumerate(self.coefficients, start=1))
            x -= (abs(r) - 1) / (math.copysign(1.0, r) * dr)
        return float(x)

    def beyond_real_bound(self) -> str:
        """What a step beyond :attr:`real_bound` does to a decaying mode, for messages: R(-x) passes -1 (the mode
        changes sign at every step) or +1 (it grows without changing sign)."""
        return "flips sign at every step" if self(-self.real_bound).real < 0 else "grows at every step instead of dying out"


#: z_{n+1} = z_n + h f(z_n)
EXPLICIT_EULER = StabilityFunction("explicit Euler", (1.0,))
#: the classical fourth-order Runge-Kutta method (CasADi's "rk" plugin and the "rk4" method of its "erk" plugin)
CLASSICAL_RK4 = StabilityFunction("classical RK4", (1.0, 1 / 2, 1 / 6, 1 / 24))
