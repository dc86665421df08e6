"""sympy.cse before lowering (generated/functions.py, an option measured in docs/bench/levers.md): the same right-hand
side to round-off, in fewer instructions."""

from __future__ import annotations

import math

import numpy as np

from apexseal.derive.cache import cached_model
from apexseal.generated.functions import build_functions
from apexseal.generated.load import load_functions
from apexseal.runtime.scenes.scene import load_scene


def test_sympy_cse_lowering_is_the_same_model_in_fewer_instructions():
    scene = load_scene()
    without = load_functions(scene.effects, scene.assumptions, compiled=False).sx  # the project's lowering
    with_cse = build_functions(cached_model(scene.effects, scene.assumptions), sympy_cse=True)
    assert with_cse.rhs.n_instructions() < without.rhs.n_instructions()
    assert with_cse.rhs_switched.n_instructions() < without.rhs_switched.n_instructions()
    p = scene.parameter_vector()
    rng = np.random.default_rng(7)
    spread = np.array([5e-6, 300e-6, 15e-3, 5e-3, 0.3, 20.0])
    for _ in range(30):
        th, X = rng.uniform(0, 2 * math.pi), rng.normal(size=6) * spread
        a, u = rng.integers(0, 2, len(with_cse.guard_names)).astype(float), rng.uniform(0, 2e6, 2)
        for name in ("rhs", "outputs"):
            f, g = getattr(with_cse, name), getattr(without, name)
            y, y0 = np.array(f(th, X, a, p, u)).ravel(), np.array(g(th, X, a, p, u)).ravel()
            np.testing.assert_allclose(y, y0, rtol=1e-9, atol=1e-9 * np.abs(y0).max(), err_msg=name)
        gap, gap0 = np.array(with_cse.guards(th, X, p, u)).ravel(), np.array(without.guards(th, X, p, u)).ravel()
        np.testing.assert_allclose(gap, gap0, rtol=1e-9, atol=1e-15)
