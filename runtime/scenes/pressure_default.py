"""The default scene's pressure table: an ESTIMATE of a gas expander's chamber pressures.

The paper's Fig. 11 plots the two chamber pressures of its case study against
crank angle ("alike in shape and π out of phase") from the authors'
thermodynamic model, but tabulates nothing. This script writes a stand-in with
the same character; it is not the paper's data. Regenerate the table with::

    python -m apexseal.runtime.scenes.pressure_default runtime/scenes/expander-pressure.csv

Model of chamber a (the seal's +Ys side, Eq. 75), an ideal expander:

* volume from the limaçon housing's area on chamber a's side of the chord,
  :func:`apexseal.derive.chambers.housing_area` (Eqs. 1-2; no lobe area, and the
  depth H cancels): ``A_a = π r² + π L²/2 + 4 r L cos θ``, smallest at θ = π,
  largest at θ = 0;
* admission at the supply pressure from the smallest volume for the inlet port's
  angular width (22°, Table 1), so the inlet cut-off is at θ = π + 22°;
* isentropic expansion, ``P = P_supply (A(cut-off) / A(θ))^γ``, to the largest volume;
* exhaust at the exhaust pressure from the largest volume back to the smallest;
* smooth (half-cosine) ramps of ``ramp_deg`` where a port opens: at the inlet
  (exhaust pressure up to supply) and at the outlet (blow-down to exhaust).

Chamber b is the same shifted by π: ``Pb(θ) = Pa(θ + π)``. At θ = 0, where the
rotor starts, chamber b is at its smallest volume and its inlet is opening.

Table 1 does not say what its port angles (inlet −25°, outlet 140°) are measured
from, and read as housing angles both ports would open into one chamber for tens
of degrees per turn; so the timing above is set by the chamber volume, not by
the port positions. Values ([estimate], as in the default scene): r = 10 mm, L = 50 mm,
supply 6.0e5 Pa, exhaust 1.013e5 Pa, air with γ = 1.4.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from functools import lru_cache
from pathlib import Path

import numpy as np

R_BASE = 0.010  # m, base circle radius r [estimate]
L_HALF = 0.050  # m, half chord L [estimate]
P_SUPPLY = 6.0e5  # Pa [estimate]
P_EXHAUST = 1.013e5  # Pa [estimate]
GAMMA = 1.4  # air [estimate]
CUTOFF_DEG = 22.0  # admission after the smallest volume, deg: the inlet's width in Table 1 [paper]
RAMP_DEG = 5.0  # port-opening ramp, deg [estimate]
STEP_DEG = 0.5  # table step: 720 rows

HEADER_LINES = (
    "# Chamber pressures of a limacon gas expander at 1500 rpm: an ESTIMATE, not the paper's data.",
    "# The paper's Fig. 11 is not tabulated; this table comes from apexseal.runtime.scenes.pressure_default",
    "# (ideal expander: admission at 6.0e5 Pa for 22 deg after the smallest volume, isentropic expansion,",
    "# gamma 1.4, exhaust at 1.013e5 Pa, 5 deg port-opening ramps; chamber b = chamber a shifted by pi).",
    "# Columns: crank angle theta in degrees; absolute pressures of chambers a (+Ys) and b (-Ys) in Pa.",
)


@lru_cache(maxsize=8)
def _area_function(r: float, L: float) -> Callable[[np.ndarray], np.ndarray]:
    import sympy as sp

    from apexseal.derive import chambers
    from apexseal.derive.symbols import P, theta

    area_a = chambers.housing_area(1, theta, r=P["r"], L=P["L"], housing_circle=0, ops=chambers.symbolic())
    return sp.lambdify(theta, area_a.subs({P["r"]: r, P["L"]: L}), "numpy")


def chamber_a_area(theta: np.ndarray, r: float = R_BASE, L: float = L_HALF) -> np.ndarray:
    """Area of chamber a at crank angle ``theta``: the limaçon housing's (derive.chambers.housing_area), no lobe."""
    t = np.asarray(theta, dtype=float)
    return np.broadcast_to(_area_function(r, L)(t), t.shape).astype(float)


def _smoothstep(u: np.ndarray) -> np.ndarray:
    u = np.clip(u, 0.0, 1.0)
    return 0.5 * (1.0 - np.cos(math.pi * u))


def chamber_a_pressure(
    theta: np.ndarray,
    *,
    r: float = R_BASE,
    L: float = L_HALF,
    p_supply: float = P_SUPPLY,
    p_exhaust: float = P_EXHAUST,
    gamma: float = GAMMA,
    cutoff_deg: float = CUTOFF_DEG,
    ramp_deg: float = RAMP_DEG,
) -> np.ndarray:
    """Absolute pressure of chamber a (Pa) at crank angles ``theta`` (rad); see the module docstring."""
    phase = np.mod(np.asarray(theta, dtype=float) - math.pi, 2 * math.pi)  # 0 at chamber a's smallest volume
    cutoff, ramp = math.radians(cutoff_deg), math.radians(ramp_deg)
    v_cut = chamber_a_area(np.array([math.pi + cutoff]), r, L)[0]
    v = chamber_a_area(phase + math.pi, r, L)
    p_expand = np.where(phase <= cutoff, p_supply, p_supply * (v_cut / v) ** gamma)
    p_end = p_supply * (v_cut / chamber_a_area(np.array([0.0]), r, L)[0]) ** gamma
    admission = p_exhaust + (p_expand - p_exhaust) * _smoothstep(phase / ramp)
    blowdown = p_end + (p_exhaust - p_end) * _smoothstep((phase - math.pi) / ramp)
    return np.where(phase < math.pi, admission, blowdown)


def default_table() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(theta_deg, Pa, Pb) of the default table: 0 to 359.5 deg in 0.5 deg steps."""
    theta_deg = np.arange(0.0, 360.0, STEP_DEG)
    theta = np.radians(theta_deg)
    return theta_deg, chamber_a_pressure(theta), chamber_a_pressure(theta + math.pi)


def write_default_table(path: str | Path) -> Path:
    """Write the default expander pressure table (CSV ``theta_deg,Pa,Pb`` with comment header) to ``path``."""
    theta_deg, pa, pb = default_table()
    lines = [*HEADER_LINES, "theta_deg,Pa,Pb"]
    lines += [f"{t:.1f},{a:.1f},{b:.1f}" for t, a, b in zip(theta_deg, pa, pb, strict=True)]
    out = Path(path)
    out.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return out


if __name__ == "__main__":  # pragma: no cover
    target = sys.argv[1] if len(sys.argv) > 1 else "expander-pressure.csv"
    print(write_default_table(target))
