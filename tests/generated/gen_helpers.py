"""Helpers of the code-generation tests: the case-study parameters and random states near the operating point."""

from __future__ import annotations

import numpy as np

from apexseal.derive.seal_shape import tip_half_angle
from apexseal.derive.symbols import PARAMETER_NAMES


def default_parameters() -> dict[str, float]:
    """The default scene's values for the paper's case study (Section 4.5; derived entries computed)."""
    Ws, ds1, ds2, Bs, ks, delta_s, kw = 3e-3, 4e-3, 4e-3, 0.0999, 5e3, 2e-3, 6.2e7
    ms = 7200 * Ws * (ds1 + ds2) * Bs
    return dict(omega=157.08, r=0.01, L=0.05, Li=0.046, zeta0=7.1e-4, delta_w=ks * delta_s / kw, Ws=Ws, Wg=3.06e-3,
                ds1=ds1, ds2=ds2, ro=3e-3, Bs=Bs, ms=ms, Icg=ms * (Ws**2 + (ds1 + ds2) ** 2) / 12, ks=ks,
                delta_s=delta_s, kw=kw, kg1=1.05e6, kg2=1.05e6, kg3=1.05e6, kg4=1.05e6, cw=207.0, cr=27.0, cs=1.9,
                mu1=0.1, mu2=0.12, mus=0.1, v_eps=1e-3, beta_o=tip_half_angle(Ws, 3e-3))


def parameter_vector(names=PARAMETER_NAMES, **changes: float) -> np.ndarray:
    """The case study's parameters in the order of ``names`` (default: the default effects' vector)."""
    values = default_parameters() | changes
    if "beta_o" not in changes:  # derived from Ws and ro, as the scene does
        values["beta_o"] = tip_half_angle(values["Ws"], values["ro"])
    return np.array([values[n] for n in names], float)


def random_point(rng: np.random.Generator) -> tuple[float, np.ndarray, np.ndarray]:
    """(theta, state, pressures) near the default operating point."""
    x = np.r_[rng.uniform(-20e-6, 20e-6, 2), rng.uniform(-5e-3, 5e-3), rng.uniform(-0.05, 0.05, 2), rng.uniform(-10, 10)]
    return float(rng.uniform(0, 2 * np.pi)), x, rng.uniform(1e5, 6e5, 2)
