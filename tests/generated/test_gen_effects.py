"""An effect that is off costs nothing and equals the full model with its coefficients at zero (which also checks
the laws at the zero their "positive" parameters admit: derive/parameters.py)."""

from __future__ import annotations

import numpy as np
import pytest
from gen_helpers import parameter_vector, random_point

from apexseal.derive import Effects, cached_model
from apexseal.derive.submodels.registry import needing, parameters
from apexseal.generated.functions import build_functions

#: effect switched off -> (parameter changes, pressures forced to zero) that give the same right-hand side
EQUIVALENT = {
    "groove_friction": ({"mu2": 0.0}, False),
    "housing_friction": ({"mu1": 0.0}, False),
    "housing_damping": ({"cw": 0.0}, False),
    "groove_damping": ({"cr": 0.0}, False),
    "spring_damping": ({"cs": 0.0}, False),
    "spring_friction": ({"mus": 0.0}, False),
    "chamber_pressure": ({}, True),
}


#: each effect compiles a model of its own (4-5 s on a fresh clone): the first in the default suite, the others slow
@pytest.mark.parametrize("effect", [e if i == 0 else pytest.param(e, marks=pytest.mark.slow)
                                    for i, e in enumerate(EQUIVALENT)])
def test_effect_off_is_cheaper_and_equal_to_zero_coefficient(loaded, effect, rng):
    full = loaded.sx
    off = build_functions(cached_model(Effects.from_mapping({effect: False})))
    assert off.guard_names == full.guard_names
    assert off.n_instructions["rhs"] < full.n_instructions["rhs"]
    assert off.n_instructions["rhs_switched"] < full.n_instructions["rhs_switched"]
    assert off.n_instructions["jac_rhs"] < full.n_instructions["jac_rhs"]  # was: the per-mode functions' sum

    changes, zero_pressure = EQUIVALENT[effect]
    # what the effect alone reads has no slot once it is off: not even its index enters the generated C
    unread = [q.name for q in parameters() if needing(q) == effect]
    assert effect == "chamber_pressure" or unread
    assert set(off.parameter_names) == set(full.parameter_names) - set(unread)
    p = parameter_vector(off.parameter_names)
    p0 = parameter_vector(**changes)
    for _ in range(8):
        theta, x, u = random_point(rng)
        a = rng.integers(0, 2, len(full.guard_names)).astype(float)
        got = np.array(off.rhs(theta, x, a, p, u)).ravel()
        want = np.array(full.rhs(theta, x, a, p0, np.zeros(2) if zero_pressure else u)).ravel()
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * np.abs(want).max())
        label = full.mode_labels[int(rng.integers(len(full.mode_labels)))]
        got = np.array(off.mode_rhs(label)(theta, x, p, u)).ravel()
        want = np.array(full.mode_rhs(label)(theta, x, p0, np.zeros(2) if zero_pressure else u)).ravel()
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * np.abs(want).max())


def test_a_parameter_every_friction_law_reads_leaves_the_model_with_the_last_of_them():
    """friction.v_eps is read by the three friction laws: it keeps its slot while any of them is on, and has none
    (not even an index in the generated C) once all three are off; it stayed in the model before."""
    from apexseal.derive.choices import Options
    from apexseal.derive.submodels.registry import parameter_names

    frictions = ("housing_friction", "groove_friction", "spring_friction")
    for on in frictions:
        assert "v_eps" in parameter_names(opts=Options({f: "none" for f in frictions if f != on}))
    assert "v_eps" not in parameter_names(opts=Options(dict.fromkeys(frictions, "none")))
