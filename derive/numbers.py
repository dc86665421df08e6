"""Plain numeric formulas of the model that scenes need without sympy (the symbolic forms live beside them).

* :func:`tip_half_angle` - beta_o, Eq. 24 (a derived parameter: no derivative passes through asin at ro = Ws/2);
* :func:`machine_numbers` - aspect ratio and groove truncation, Eqs. 4-8;
* :func:`initial_wall_deflection` - delta_w from the rest balance ks delta_s = kw delta_w, Eq. 9 (the symbolic
  form, checked against this one by the tests, is ``derive.geometry.initial_wall_deflection``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass


def tip_half_angle(Ws: float, ro: float) -> float:
    """The value of beta_o, Eq. 24: asin(Ws / (2 ro)) (pi/2 at the edge ro = Ws/2)."""
    return math.asin(min(1.0, Ws / (2 * ro)))


def initial_wall_deflection(ks, delta_s, kw):
    """Eq. 9: delta_w = ks delta_s / kw (works on numbers and on CasADi symbols alike)."""
    return ks * delta_s / kw


@dataclass(frozen=True)
class MachineNumbers:
    aspect_ratio: float
    truncation: float
    truncation_angle: float | None


def machine_numbers(embodiment: str, r_: float, L_: float, Wg_: float, Cr_: float = 0.0, k_: float = 0.0) -> MachineNumbers:
    """Numeric Eqs. 4-8 for a scene (embodiment: limacon-to-limacon, circolimacon, limacon-to-circular)."""
    if embodiment == "limacon-to-limacon":
        s = (-L_ + math.sqrt(L_**2 + 4 * r_ * Wg_)) / (4 * r_)
        th0 = math.asin(s)
        z = L_ - (r_ * math.sin(2 * th0) + L_ * math.cos(th0))
        return MachineNumbers(r_ / L_, z, th0)
    Rlc = math.sqrt((L_ - Cr_) ** 2 + k_**2)
    z = L_ - Cr_ - math.sqrt(Rlc**2 - (k_ + Wg_ / 2) ** 2)
    return MachineNumbers(r_ / L_, z, None)
