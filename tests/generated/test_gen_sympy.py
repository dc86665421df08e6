"""Compiled C equals the sympy model; Jacobians equal finite differences."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy as sp
from gen_helpers import random_point

from apexseal.derive import symbols as S
from apexseal.derive.modes import case_of
from apexseal.generated.layout import mode_label

ARGS = [S.theta, *S.qs, *S.us, *[S.P[n] for n in S.PARAMETER_NAMES], S.Pa, S.Pb]


@pytest.fixture(scope="module")
def reference(model):
    """mpmath (30 digits) evaluators of solve(M, f), the guards and the outputs, activations as arguments.

    Each acceleration comes with the sum of |terms| of its forcing over the mass: the
    scale of the rounding error of a sum of terms that may cancel.
    """
    M = model.mass_matrix
    assert M.is_diagonal()
    args = [*ARGS, *model.activations.values()]
    terms = []
    for i in range(3):
        f = sp.expand(model.forcing[i], deep=False)
        terms.append([t / M[i, i] for t in (f.args if f.is_Add else (f,))])
    split = np.cumsum([len(t) for t in terms])[:-1]
    fns = {
        "acc": sp.lambdify(args, [t for ts in terms for t in ts], modules="mpmath", cse=True),
        "guards": sp.lambdify(ARGS, list(model.guards.values()), modules="mpmath", cse=True),
        "outputs": sp.lambdify(args, list(model.outputs.values()), modules="mpmath", cse=True),
    }

    def evaluate(kind, theta, x, p, u, a=()):
        with mpmath.workdps(30):
            values = fns[kind](theta, *x, *p, *u, *a)
            if kind == "acc":  # (accelerations, sum of |terms|)
                parts = np.split(np.array(values, dtype=object), split)
                return np.array([float(sum(v)) for v in parts] + [float(sum(abs(t) for t in v)) for v in parts])
            return np.array([float(v) for v in values])

    return evaluate


def test_every_mode_equals_sympy(loaded, reference, params, rng):
    """Each mode's compiled C = solve(M, f) with the mode's activations substituted, to 1e-12 relative."""
    worst = 0.0
    for mode in loaded.sx.mode_list:
        theta, x, u = random_point(rng)
        ref, scale = np.split(reference("acc", theta, x, params, u, [float(c) for c in mode.closed]), 2)
        got = np.array(loaded.c.mode_rhs(mode.label)(theta, x, params, u)).ravel()
        np.testing.assert_array_equal(got[:3], x[3:])
        rel = np.abs(got[3:] - ref) / np.maximum(np.abs(ref), scale)
        worst = max(worst, rel.max())
        assert rel.max() < 1e-12, (mode.label, rel)
    assert worst > 0  # the comparison is not vacuous


def test_rhs_guards_outputs_equal_sympy(loaded, reference, params, rng):
    names = [n for n in loaded.sx.output_names if n != "b_gap"]
    for _ in range(6):
        theta, x, u = random_point(rng)
        a = rng.integers(0, 2, len(loaded.sx.guard_names)).astype(float)
        ref, scale = np.split(reference("acc", theta, x, params, u, a), 2)
        got = np.array(loaded.c.rhs(theta, x, a, params, u)).ravel()[3:]
        assert (np.abs(got - ref) / np.maximum(np.abs(ref), scale)).max() < 1e-12
        g_ref = reference("guards", theta, x, params, u)
        np.testing.assert_allclose(np.array(loaded.c.guards(theta, x, params, u)).ravel(), g_ref, rtol=1e-12)
        y = np.array(loaded.c.outputs(theta, x, a, params, u)).ravel()
        y_ref = reference("outputs", theta, x, params, u, a)
        np.testing.assert_allclose(y[:len(names)], y_ref, rtol=1e-11, atol=1e-13 * np.abs(y_ref).max())
        b = g_ref[_groove(loaded)]  # Algorithm 4: b_gap = min(b1..b4) while all four are open, else 0
        np.testing.assert_allclose(y[-1], b.min() if (b > 0).all() else 0.0, rtol=1e-12)


def test_b_gap_when_all_groove_contacts_open(loaded, params):
    x = np.zeros(6)  # centred seal: every groove gap is the 30 um side clearance
    u = np.array([2e5, 1e5])
    g = np.array(loaded.c.guards(0.3, x, params, u)).ravel()
    assert (g[_groove(loaded)] > 0).all()
    y = np.array(loaded.c.outputs(0.3, x, (g < 0).astype(float), params, u)).ravel()
    assert y[loaded.sx.output_names.index("b_gap")] == pytest.approx(g[_groove(loaded)].min(), rel=1e-12)


def _groove(loaded) -> list[int]:
    """Where b1..b4 stand in the guard vector."""
    return [loaded.sx.guard_names.index(n) for n in ("b1", "b2", "b3", "b4")]


def test_rhs_switched_is_rhs_with_guard_activations(loaded, params, rng):
    for _ in range(20):
        theta, x, u = random_point(rng)
        g = np.array(loaded.c.guards(theta, x, params, u)).ravel()
        closed = (g < 0).astype(float)
        sw = np.array(loaded.c.rhs_switched(theta, x, params, u)).ravel()
        np.testing.assert_allclose(sw, np.array(loaded.c.rhs(theta, x, closed, params, u)).ravel(), rtol=1e-13)
        if case_of(*(g[_groove(loaded)] < 0)).startswith("x"):
            continue
        label = mode_label(loaded.sx.guard_names, g < 0)
        np.testing.assert_allclose(sw, np.array(loaded.c.mode_rhs(label)(theta, x, params, u)).ravel(), rtol=1e-13)


def central_fd(f, z: np.ndarray, steps: np.ndarray) -> np.ndarray:
    cols = []
    for i, h in enumerate(steps):
        dz = np.zeros_like(z)
        dz[i] = h
        cols.append((f(z + dz) - f(z - dz)) / (2 * h))
    return np.array(cols).T


def check_jacobian(jac_blocks, fun, theta, x, p, u):
    """Blocks d xdot/d(theta, x, p, u) of a compiled Jacobian against central differences."""
    z0 = np.r_[theta, x, p, u]
    split = np.cumsum([1, 6, len(p)])

    def f(z):
        th, xx, pp, uu = np.split(z, split)
        return np.array(fun(th[0], xx, pp, uu)).ravel()

    scale = np.r_[1e-3, 1e-5, 1e-5, 1e-3, 1e-3, 1e-3, 1e-2, np.abs(p) * 1e-3, u * 1e-3]  # typical variations
    fd = central_fd(f, z0, scale * 1e-3)
    J = np.hstack([np.array(b) for b in jac_blocks])
    for row in range(6):
        err = np.abs((J[row] - fd[row]) * scale)
        assert err.max() < 1e-5 * max(np.abs(fd[row] * scale).max(), 1e-300), (row, np.argmax(err))


def test_mode_jacobians_equal_finite_differences(loaded, params, rng):
    labels = loaded.sx.mode_labels
    for label in (labels[0], labels[7], labels[20], labels[-1]):
        theta, x, u = random_point(rng)
        f = loaded.c.mode_rhs(label)
        closed = next(m.closed for m in loaded.sx.mode_list if m.label == label)
        blocks = loaded.c.rhs_jac(theta, x, np.array(closed, float), params, u, f(theta, x, params, u))
        check_jacobian([blocks[0], blocks[1], blocks[3], blocks[4]], f, theta, x, params, u)  # the mode fixes a


def test_rhs_jacobian_is_in_the_library(loaded, params, rng):
    """casadi.external('rhs') finds jac_rhs in the same library: its Jacobian is the exact (SX) one."""
    theta, x, u = random_point(rng)
    a = np.array([1, 0, 0, 1, 1, 1], float)
    out = loaded.c.rhs(theta, x, a, params, u)
    got = loaded.c.rhs.jacobian()(theta, x, a, params, u, out)
    want = loaded.sx.rhs_jac(theta, x, a, params, u, out)
    for g, w in zip(got, want, strict=True):
        np.testing.assert_allclose(np.array(g), np.array(w), rtol=1e-14, atol=0)

    def f(th, xx, pp, uu):
        return loaded.c.rhs(th, xx, a, pp, uu)

    blocks = loaded.c.rhs_jac(theta, x, a, params, u, out)  # d/d(theta, x, a, p, u): skip the a block
    check_jacobian([blocks[0], blocks[1], blocks[3], blocks[4]], f, theta, x, params, u)
