"""Plain numeric formulas of the model that scenes need without sympy (the symbolic forms live beside them).

* :func:`tip_half_angle` - beta_o, Eq. 24 (a derived parameter: no derivative passes through asin at ro = Ws/2);
* :func:`machine_numbers` - aspect ratio and groove truncation, Eqs. 4-8;
* :func:`initial_wall_deflection` - delta_w from the rest balance Fs = kw delta_w, Eq. 9, Fs the spring's force at
  rest (``SpringContact.rest_force``, Eq. 39; also the symbolic form: ``derive.geometry.initial_wall_deflection``
  calls it with the parameters' symbols);
* :func:`damping_of_ratio` - a contact's damping coefficient from its damping ratio, c = 2 zeta sqrt(k ms), and
  :func:`ratio_of_damping`, the ratio of a coefficient;
* :func:`housing_radius` - the housing's distance from the pole, Eq. 2 or the circolimaçon's circle (the ports' areas);
* :func:`smallest_chamber_volume`, :func:`smallest_lobe_offset` - the smallest chamber volume over a revolution and
  the circular lobes' bound on k, from the chamber volumes of Eqs. 1-8 (``derive.chambers``, evaluated on floats).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .chambers import chamber_volume, lobe_area


def tip_half_angle(Ws: float, ro: float) -> float:
    """The value of beta_o, Eq. 24: asin(Ws / (2 ro)) (pi/2 at the edge ro = Ws/2)."""
    return math.asin(min(1.0, Ws / (2 * ro)))


def outline_mass(density: float, *, Ws: float, ds1: float, ds2: float, Bs: float) -> float:
    """Eq. 80: the mass of the seal's outline, a rectangle Ws by ds1 + ds2, Bs long, of ``density``: the seal's
    mass when the scene gives its density, and the heaviest seal at the densest material's."""
    return density * Ws * (ds1 + ds2) * Bs


def tip_arc_start(*, ds1: float, ro: float, beta_o: float) -> float:
    """ds0 = ds1 - ro (1 - cos beta_o), Eq. 24: where the seal's tip arc starts along its axis (its ends c1, c3)."""
    return ds1 - ro * (1 - math.cos(beta_o))


def initial_wall_deflection(*, spring_force, kw):
    """Eq. 9: delta_w = Fs / kw, the housing's groove-axis force kw delta_w balancing the spring's force at rest Fs
    (ks delta_s under the paper's law, Eq. 39: ``SpringContact.rest_force``). Works on numbers and on CasADi and
    sympy symbols alike."""
    return spring_force / kw


def initial_wall_deflection_normal(*, spring_force, kw, r, L, mu1=0.0):
    """delta_w where kw acts on the normal penetration xs5 cos(lambda) (``assumptions.housing_stiffness =
    "normal"``): the X balance of Eq. 9 at rest at theta = 0, Fs = kw delta_w cos(lambda0) (cos(lambda0) +
    mu1 sin(lambda0)), lambda0 = atan(2 r / L) (Eq. 9), Fs the spring's force at rest (Eq. 39), against the normal
    force kw delta_w cos(lambda0) with its friction (``mu1``; 0 without housing friction) that the tip's forward
    slide turns towards +X (Algorithm 2). Numbers for r, L, mu1; Fs and kw may be CasADi symbols."""
    tilted = initial_wall_deflection_tilted(spring_force=spring_force, kw=kw, r=r, L=L, mu1=mu1)
    return tilted / math.cos(math.atan(2 * r / L))  # the normal penetration is delta_w cos(lambda0)


def initial_wall_deflection_tilted(*, spring_force, kw, r, L, mu1=0.0):
    """delta_w where kw acts on the tip arc's penetration into the wall tilted by lambda (``assumptions.
    housing_stiffness = "tilted-wall"``): at rest that penetration is delta_w itself, so the X balance of Eq. 9 at
    theta = 0 is Fs = kw delta_w (cos(lambda0) + mu1 sin(lambda0)), lambda0 = atan(2 r / L) (Eq. 9), the normal
    force and its friction turned towards +X by the tip's forward slide (Algorithm 2). Numbers for r, L, mu1; Fs and
    kw may be CasADi symbols."""
    lam0 = math.atan(2 * r / L)
    return spring_force / (kw * (math.cos(lam0) + mu1 * math.sin(lam0)))


def damping_of_ratio(zeta, k, ms):
    """c = 2 zeta sqrt(k ms): zeta times the critical damping of the seal's mass on a contact of stiffness k.

    (Eqs. 55, 62, 67, 73 take the damping coefficient as given; the ratio is how a scene states it so that a
    changed stiffness keeps its damping ratio.) Works on numbers and on CasADi symbols alike.
    """
    return 2 * zeta * (k * ms) ** 0.5


def ratio_of_damping(c, k, ms):
    """zeta = c / (2 sqrt(k ms)): the damping ratio of a contact's coefficient c (the inverse of
    :func:`damping_of_ratio`)."""
    return c / (2 * (k * ms) ** 0.5)


@dataclass(frozen=True)
class MachineNumbers:
    """The machine's numbers of Eqs. 4-8: the aspect ratio b = r/L (Eq. 4) and the groove truncation z with its
    angle (Eqs. 6-8)."""

    aspect_ratio: float
    truncation: float
    truncation_angle: float | None


def machine_numbers(embodiment: str, *, r: float, L: float, Wg: float, Cr: float = 0.0, k: float = 0.0
                    ) -> MachineNumbers:
    """Numeric Eqs. 4-8 for a scene (embodiment: limacon-to-limacon, circolimacon, limacon-to-circular)."""
    if embodiment == "limacon-to-limacon":
        s = (-L + math.sqrt(L**2 + 4 * r * Wg)) / (4 * r)
        th0 = math.asin(s)
        z = L - (r * math.sin(2 * th0) + L * math.cos(th0))
        return MachineNumbers(r / L, z, th0)
    Rlc = math.sqrt((L - Cr) ** 2 + k**2)
    z = L - Cr - math.sqrt(Rlc**2 - (k + Wg / 2) ** 2)
    return MachineNumbers(r / L, z, None)


def housing_radius(psi: float, *, r: float, L: float, circle: bool) -> float:
    """Distance from the pole to the housing at polar angle psi: Eq. 2, or the circolimaçon's circle."""
    s = math.sin(psi)
    return 2 * r * s + (math.sqrt(L**2 + 4 * r**2 * s * s) if circle else L)


def smallest_chamber_volume(embodiment: str, *, r: float, L: float, H: float, Cr: float = 0.0, k: float = 0.0,
                            samples: int = 360) -> tuple[float, float, str]:
    """The smallest of Va, Vb over a revolution, the crank angle where it occurs and the chamber ("a" or "b").

    Samples :func:`.chambers.chamber_volume` (Eqs. 1-8) every 360/samples deg; the smallest volumes of the three embodiments
    lie at theta = 0 or pi (the chord along the Xo axis), which the grid contains for even ``samples``.
    """
    A = lobe_area(embodiment, r=r, L=L, Cr=Cr, k=k)
    circle = 1.0 if embodiment == "circolimacon" else 0.0
    best = (math.inf, 0.0, "a")
    for i in range(samples):
        th = 2 * math.pi * i / samples
        for side, name in ((1, "a"), (-1, "b")):
            V = chamber_volume(side, th, r=r, L=L, H=H, A_lobe=A, housing_circle=circle)
            if V < best[0]:
                best = (V, th, name)
    return best


def smallest_lobe_offset(embodiment: str, *, r: float, L: float, H: float, Cr: float = 0.0) -> float:
    """The lobe-centre offset k (Eq. 5) below which a circular lobe leaves no positive chamber volume: the lobe's
    area falls as k grows (the circle through the apices flattens), so the bound is found by bisection."""
    def positive(k: float) -> bool:
        return smallest_chamber_volume(embodiment, r=r, L=L, H=H, Cr=Cr, k=k)[0] > 0

    lo, hi = -L, L
    while positive(lo):
        lo *= 2
    while not positive(hi):
        lo, hi = hi, 2 * hi
        if hi > 1e3 * L:
            return math.inf
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if positive(mid) else (mid, hi)
    return hi
