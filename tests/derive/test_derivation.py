"""The derivation itself: effect pruning, Eq. 80's mass matrix, the rest state of Eq. 9, the cache, timing."""

from __future__ import annotations

import time

import pytest
import sympy as sp

from apexseal.derive import cached_model, derive_model, geometry
from apexseal.derive.effects import Effects
from apexseal.derive.submodels.registry import activation_symbols
from apexseal.derive.symbols import P, Pa, Pb, qs, theta, us


@pytest.fixture(scope="module")
def timed_default():
    """The default (paper) model, derived cold, and how long that took."""
    t0 = time.perf_counter()
    model = derive_model()
    return model, time.perf_counter() - t0


def variant(**values: bool):
    return cached_model(Effects.from_mapping(values))


def symbols_of(model) -> set[sp.Symbol]:
    exprs = list(model.forcing) + list(model.outputs.values())
    return set().union(*(sp.sympify(e).free_symbols for e in exprs))


def test_cold_derivation_is_fast(timed_default):
    _, seconds = timed_default
    assert seconds < 60


def test_mass_matrix_is_diag_ms_ms_icg(timed_default):
    expected = sp.diag(P["ms"], P["ms"], P["Icg"])
    assert timed_default[0].mass_matrix == expected
    assert variant(inertia=False).mass_matrix == expected


def test_default_model_has_every_effect(timed_default):
    model, _ = timed_default
    syms = symbols_of(model)
    for name in ("mu1", "mu2", "mus", "kw", "cw", "ks", "cs", "kg1", "cr", "omega"):
        assert P[name] in syms, name
    assert {Pa, Pb} <= syms
    assert set(model.guards) == {"b1", "b2", "b3", "b4", "xs5", "spring"}


def test_groove_friction_off_removes_mu2():
    model = variant(groove_friction=False)
    assert P["mu2"] not in symbols_of(model)
    assert not any(name.endswith("_slide") and name[2:4] in ("i1", "c2", "i2", "c4") for name in model.velocity_guards)
    assert P["kg1"] in symbols_of(model)  # the elastic contact stays


def test_housing_contact_off_removes_the_housing():
    model = variant(housing_contact=False)
    syms = symbols_of(model)
    for name in ("kw", "cw", "mu1"):
        assert P[name] not in syms, name
    assert "xs5" not in model.guards and "xs5" not in model.activations
    assert activation_symbols()["s_h"] not in syms
    assert not any(name.startswith("F_housing") for name in model.outputs)


def test_chamber_pressure_off_removes_the_pressures():
    model = variant(chamber_pressure=False)
    assert not {Pa, Pb} & symbols_of(model)
    assert not any(name.startswith("F_pressure") for name in model.outputs)


def _at_rest_without_contacts(model) -> list[sp.Expr]:
    """Forcing at the zero state with every contact open and no pressure."""
    zero = {s: 0 for s in (*qs, *us)} | {a: 0 for a in activation_symbols().values()} | {Pa: 0, Pb: 0}
    return [sp.simplify(e.xreplace(zero)) for e in model.forcing]


def test_inertia_off_leaves_no_rotor_terms():
    forcing = _at_rest_without_contacts(variant(inertia=False))
    assert all(P["omega"] not in e.free_symbols and theta not in e.free_symbols for e in forcing)
    assert forcing == [0, 0, 0]


def test_inertia_on_brings_the_rotor_terms(timed_default):
    forcing = _at_rest_without_contacts(timed_default[0])
    assert P["omega"] in forcing[0].free_symbols  # centrifugal ms ω² (2 r sin θ + Li) along X
    expected = P["ms"] * P["omega"] ** 2 * (4 * P["r"] * sp.sin(theta) + P["Li"])  # Eq. 15: 4 r ω² sin θ + ω² Li
    assert sp.simplify(forcing[0] - expected) == 0


def test_static_equilibrium_at_rest():
    """Eq. 9: at rest, with the groove contacts open and no pressure or inertia, the spring preload balances the housing."""
    model = variant(inertia=False, chamber_pressure=False, groove_contact=False)
    rest = {s: 0 for s in (*qs, *us)} | {activation_symbols()["s_h"]: 1, activation_symbols()["s_sp"]: 1}
    ks, kw, delta_s, delta_w = P["ks"], P["kw"], P["delta_s"], P["delta_w"]
    expected = ks * sp.Max(delta_s, 0) - kw * sp.Max(delta_w, 0)
    raw = model.forcing[0].xreplace(rest)
    # an identity checked at three points of distinct values (to 30 digits), not by sp.simplify of the whole
    # forcing, which ran for over 15 minutes on a mutation of the friction law instead of failing
    names = sorted(raw.free_symbols | expected.free_symbols, key=str)
    for shift in (0, 7, 19):
        point = {q: sp.Rational(11 + (i + shift) % 23, 10) for i, q in enumerate(names)}
        assert abs(float((raw - expected).xreplace(point).evalf(30))) < 1e-20
    assert sp.simplify(expected.subs(delta_w, geometry.initial_wall_deflection()).subs(delta_s, sp.Rational(1, 500))) == 0
    assert sp.simplify(geometry.initial_wall_deflection() - ks * delta_s / kw) == 0


def test_cached_model_equals_derive_model(timed_default):
    """A cache hit (stored by this or an earlier session with the same sources) equals a fresh derivation."""
    cached_model()  # stores the model if the cache is cold
    t0 = time.perf_counter()
    warm = cached_model()
    assert time.perf_counter() - t0 < 1.0
    fresh, _ = timed_default
    assert warm.mass_matrix == fresh.mass_matrix
    assert list(warm.forcing) == list(fresh.forcing)
    assert warm.guards == fresh.guards
    assert warm.activations == fresh.activations
    assert warm.velocity_guards == fresh.velocity_guards
    assert warm.outputs == fresh.outputs
    assert warm.quantities == fresh.quantities


def test_cache_stores_atomically_in_its_folder(tmp_path, monkeypatch):
    """A cold cache derives once and stores one pickle under $APEXSEAL_CACHE/derive, beside the lock its derivation
    took, no temporary files left."""
    monkeypatch.setenv("APEXSEAL_CACHE", str(tmp_path))
    effects = Effects.only("spring")  # small: a quick cold derivation
    model = cached_model(effects)
    assert sorted(p.suffix for p in (tmp_path / "derive").iterdir()) == [".lock", ".pkl"]
    assert cached_model(effects).forcing == model.forcing


def test_gap_width_numpy_and_casadi():
    """Algorithm 4: min(b1..b4) while all four groove contacts are open, else 0, for arrays and for SX."""
    import casadi as ca
    import numpy as np

    from apexseal.derive.modes import gap_width
    from apexseal.generated.functions import CASADI_OPS

    b = np.array([[1e-6, -1e-9], [2e-6, 2e-6], [3e-6, 3e-6], [0.5e-6, 4e-6]])
    np.testing.assert_array_equal(gap_width(list(b)), [0.5e-6, 0.0])
    s = ca.SX.sym("b", 4)
    f = ca.Function("b_gap", [s], [gap_width([s[i] for i in range(4)], CASADI_OPS)])
    assert [float(f(b[:, j])) for j in range(2)] == [0.5e-6, 0.0]
