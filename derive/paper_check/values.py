"""The values the paper check evaluates at: the default scene's parameters (the paper's case study, Section 4.5),
the state of the numeric examples, the ranges of the random states, and how each row is evaluated."""

from __future__ import annotations

import functools
import math

from .. import paper
from .. import seal_shape as shape
from ..assumptions import Assumptions
from ..submodels.pressure import groove_bottom_pressure as _pend
from ..submodels.registry import activation_symbols
from ..symbols import Pa, Pb, qs, us

I = paper.INTERMEDIATES  # noqa: E741
x, y, phi = qs
xd, yd, phid = us
SEED = 20180526  # the paper's online date
N_SAMPLES = 12
REL_TOL = 1e-9
SYMBOLIC_MAX_OPS = 160
SIMPLIFY_MAX_OPS = 28  # simplify is slow with asin and sqrt terms; larger ones are checked numerically

#: the values the default scene states (runtime/scenes/default.toml; v_eps is needed only by the check); a parameter
#: not here takes the default its submodel declares (``Parameter(..., default=...)``)
STATED: dict[str, float] = {
    "r": 0.010, "L": 0.050, "zeta0": 7.1e-4, "Ws": 3.0e-3, "Wg": 3.06e-3, "ds1": 4.0e-3, "ds2": 4.0e-3, "ro": 3.0e-3,
    "Bs": 0.0999, "density": 7200.0, "ks": 5.0e3, "delta_s": 2.0e-3, "kw": 1e9, "kg1": 1e9, "kg2": 1e9, "kg3": 1e9,
    "kg4": 1e9, "zeta_w": 0.1, "zeta_g": 0.1, "zeta_s": 0.1, "mu1": 0.10, "mu2": 0.12, "mus": 0.10, "v_eps": 1.0e-3,
}
RPM = 1500.0


class MissingValue(LookupError):
    """A parameter of the default model with neither a stated value nor a declared default."""

    def __str__(self) -> str:
        return str(self.args[0])


def _declared_values(options) -> dict[str, float | None]:
    """The defaults the submodels declare for the parameters of the model of ``options``, then STATED over them.

    A parameter of that model's vector with a scene key, no default and no stated value is a :class:`MissingValue`
    naming it."""
    from ..submodels.registry import parameters, submodels

    vector = parameters(opts=options)  # not the scene inputs outside it (Cr, k: the check samples their ranges)
    values: dict[str, float | None] = {p.name: p.default for p in vector if p.default is not None}
    values.update(STATED)
    missing = [p for p in vector if p.key is not None and not p.optional and p.name not in values]
    if missing:
        owner = {p.name: cls for cls in submodels() for p in cls.parameters}
        names = "; ".join(f"{p.name} ({p.key}, declared by the submodel {owner[p.name].name!r} in "
                          f"{owner[p.name].__module__})" for p in missing)
        raise MissingValue(f"the paper check has no value for the parameter(s) {names}: give each a default in its "
                           "Parameter(..., default=...) declaration, or a value in STATED of "
                           "derive/paper_check/values.py")
    return values


@functools.lru_cache(maxsize=1)
def _default_options():
    """The options of the default model (the default effects and assumptions)."""
    from ..choices import options_of
    from ..effects import Effects

    return options_of(Effects(), Assumptions())


def _default_values() -> dict[str, float]:
    """The default scene's parameters: the stated values (and the declared defaults of the others) and what the
    submodels derive from them (omega, ms, Icg, beta_o, delta_w of Eq. 9, Li of Eq. 12, the damping coefficients of
    the ratios), as the scene computes them."""
    from types import SimpleNamespace

    from ..submodels.registry import submodels

    options = _default_options()
    values = {**_declared_values(options), "ms": None, "Icg": None, "cw": None, "cr": None, "cs": None}
    inputs = {"operation": SimpleNamespace(omega=RPM * 2 * math.pi / 60)}
    for cls in submodels():
        if cls.active(options):
            values.update(cls.derived(values, inputs, options))
    return {n: float(v) for n, v in values.items() if v is not None}


def rest_deflection(values: dict[str, float]) -> float:
    """delta_w of Eq. 9 (the housing's groove-axis force balancing the spring's force at rest, Eq. 39) at
    ``values``, the defaults for what they leave out: the scene's own rule (``SealBody.rest_wall_deflection``) under
    the default effects and assumptions."""
    from ..submodels.seal import SealBody

    return SealBody.rest_wall_deflection(DEFAULTS | values, _default_options())


#: the default scene's parameter values, to full precision (tests/derive/test_paper_check.py compares them)
DEFAULTS: dict[str, float] = _default_values()
assert DEFAULTS["delta_w"] == rest_deflection(DEFAULTS)
assert DEFAULTS["beta_o"] == shape.tip_half_angle(DEFAULTS["Ws"], DEFAULTS["ro"])
EXTRA_DEFAULTS = {"Cr": 1.0e-4, "k": 0.02, "b": 0.2, "theta0": 0.03}

#: the stated state of the numeric examples (SI units)
EXAMPLE_STATE: dict[str, float] = {
    "theta": math.pi / 3, "x": 1.0e-6, "y": -1.0e-5, "phi": 2.0e-3, "xd": 0.02, "yd": -0.01, "phid": 5.0,
    "xdd": 10.0, "ydd": -10.0, "phidd": 1000.0, "Pa": 3.0e5, "Pb": 2.0e5, "beta": 0.1,
}
#: ranges of the random states (wide, so that second-order differences are not lost in rounding)
STATE_RANGES: dict[str, tuple[float, float]] = {
    "theta": (0.0, 2 * math.pi), "x": (-1e-3, 1e-3), "y": (-2e-4, 2e-4), "phi": (-0.15, 0.15), "xd": (-1.0, 1.0),
    "yd": (-1.0, 1.0), "phid": (-100.0, 100.0), "xdd": (-1e3, 1e3), "ydd": (-1e3, 1e3), "phidd": (-1e5, 1e5),
    "beta": (-0.4, 0.4), "Pa": (1e5, 6e5), "Pb": (1e5, 6e5), "theta0": (0.0, 0.2), "b": (0.1, 0.25),
    "Cr": (5e-5, 2e-4), "k": (0.0, 0.02),
}

#: the activation symbols of the contacts (1 = closed), by name
ACTIVATIONS = activation_symbols()


def groove_bottom_pressure():
    """Pend of the default pend_rule (Eq. 75)."""
    return _pend(Pa, Pb, Assumptions().pend_rule)


#: how a row is evaluated: contact activations ("one": closed, "guard": by the gap, "keep": sampled 0/1)
#: and the friction sign ("sign": tanh(v/v_eps) -> sign(v); "forward": the tip slides forward, sign = +1)
SETTINGS: dict[str, tuple[str, str]] = {
    "34": ("guard", "sign"), "39": ("guard", "sign"), "A1.elastic": ("guard", "sign"), "A1.friction": ("guard", "sign"),
    "63": ("guard", "sign"), "80.f": ("keep", "sign"), "9.F": ("one", "forward"), "A2": ("one", "forward"),
}

#: state ranges of rows that need the tip pressed into the housing (xs5 > 0)
ROW_RANGES: dict[str, dict[str, tuple[float, float]]] = {
    "9.F": {"x": (5e-4, 1e-3)}, "A2": {"x": (5e-4, 1e-3)}, "68": {"x": (5e-4, 1e-3)},
}


def fmt(v: float) -> str:
    return f"{v + 0.0:.6g}"  # + 0.0: no "-0"


def fmt_vec(vals) -> str:
    vals = [fmt(v) for v in vals]
    return vals[0] if len(vals) == 1 else "(" + ", ".join(vals) + ")"
