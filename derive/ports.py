"""The open area of a port to each chamber against crank angle (Table 1).

A port is an opening in the housing wall, centred at housing polar angle ``c`` (about the pole o, from the Xo
axis counter-clockwise, the sense of theta), ``w`` wide in that angle and ``l`` long along the machine axis.
Table 1 does not say from where its angles are measured: the scene's ``machine.ports.datum`` (default 0 deg,
the Xo axis) is added to them. Chamber a covers the housing from the seal at p1 (polar angle theta) to the
next apex p2 (theta + pi), chamber b the rest; the port is open to a chamber over the part of its width that
lies in the chamber's arc, and its open area is that fraction of its full area ``A = l rho(c) w`` (rho the
housing's distance from the pole at the port's centre). The apex seals are taken as lines (their width, 3 mm,
is 1 % of a chamber's arc).

Works on sympy expressions (``Max``, ``Min``, ``floor``), so the gas model lowers it into the generated C.
"""

from __future__ import annotations

import sympy as sp

TWO_PI = 2 * sp.pi


def open_fractions(theta, centre, width):
    """(fraction open to chamber a, fraction open to chamber b) of a port ``width`` < pi wide centred at
    ``centre`` (absolute housing angle), at crank angle ``theta``; the two add up to 1."""
    start = centre - width / 2 - theta
    phi = start - TWO_PI * sp.floor(start / TWO_PI)  # the port's start from p1, in [0, 2 pi)
    in_a = sp.Max(0, sp.Min(phi + width, sp.pi) - phi) + sp.Max(0, phi + width - TWO_PI)
    in_b = sp.Max(0, sp.Min(phi + width, TWO_PI) - sp.Max(phi, sp.pi))
    return in_a / width, in_b / width
