"""Where the composite's evaluations go (runtime/bench/phases.py): its groups, its per-interval counts, eigenvalues.

The groups on made-up data; the counts on 20 degrees of the default scene from its initial state (the anatomy
tests' problem), in the compiled model library the composite runs in.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_bench_anatomy import tiny  # noqa: F401 - the fixture

from apexseal.generated.hybrid import controls
from apexseal.runtime.bench.phases import Group, groups, markdown, per_interval, rows, stiffest
from apexseal.runtime.solving.composite import CompositeIntegrator


def test_switches_closer_than_the_ring_make_one_cluster_followed_by_its_ring():
    switched = np.zeros(20, bool)
    switched[[2, 4, 5, 12]] = True
    assert groups(switched, 3) == [Group("quiet", 0, 2), Group("cluster", 2, 6), Group("ring", 6, 9),
                                   Group("quiet", 9, 12), Group("cluster", 12, 13), Group("ring", 13, 16),
                                   Group("quiet", 16, 20)]
    # a gap of exactly the ring still joins; a ring cut by the end of the span
    switched[:] = False
    switched[[1, 4, 18]] = True
    assert groups(switched, 3) == [Group("quiet", 0, 1), Group("cluster", 1, 5), Group("ring", 5, 8),
                                   Group("quiet", 8, 18), Group("cluster", 18, 19), Group("ring", 19, 20)]
    assert groups(np.zeros(5, bool), 3) == [Group("quiet", 0, 5)]


@pytest.fixture(scope="module")
def fns(default_functions):
    assert default_functions.library is not None, "no C compiler: the composite needs the compiled model library"
    return default_functions.c


def test_the_counts_per_interval_add_up_to_one_call(tiny, fns):  # noqa: F811 - the fixture
    p = tiny.problem
    per = per_interval(tiny, 1e-6, np.asarray(p.params, float), fns)
    assert per.shape == (p.samples, 4)
    for g in groups(tiny.switched, 3):  # a count can be off by a step at an output end, a group's is not negative
        assert (per[g.start:g.stop].sum(axis=0) >= 0).all()
    eng = CompositeIntegrator(fns, n_samples=p.samples, span=p.span, rtol=1e-6, max_steps=10**6, max_events=10**8,
                              pressure=p.pressure)
    eng.run(p.z0, p.params, p.theta0, p.pressures)
    st = eng.stats()
    assert per.sum(axis=0).tolist() == [st["n_rhs"], st["n_tight_steps"], st["n_quiet_steps"], st["n_events"]]
    assert per[tiny.switched, 3].sum() > 0  # the composite switches where the reference does


def test_the_stiffest_eigenvalue_is_that_of_a_finite_difference_jacobian(tiny, fns):  # noqa: F811 - the fixture
    p, f = tiny.problem, fns.hybrid_ode
    params = np.asarray(p.params, float)
    k = 5
    lam = stiffest(tiny, params, k)
    z, t = tiny.ref_z[:, k].copy(), (k + 1) * tiny.dtheta
    u = controls(np.asarray(p.pressures), tiny.dtheta * np.arange(1, p.samples + 1), p.pressure, f.size1_in(3))[:, k]
    par = np.r_[params, p.theta0]
    J = np.empty((6, 6))
    for j in range(6):
        d = 1e-7 * max(1.0, abs(z[j]))
        zp, zm = z.copy(), z.copy()
        zp[j] += d
        zm[j] -= d
        J[:, j] = (np.asarray(f(t, zp, par, u)).ravel()[:6] - np.asarray(f(t, zm, par, u)).ravel()[:6]) / (2 * d)
    ev = np.linalg.eigvals(J)
    ref = ev[np.argmax(np.abs(ev))]
    assert abs(lam) == pytest.approx(abs(ref), rel=1e-5) and lam.real == pytest.approx(ref.real, rel=1e-4, abs=1e-6)


def test_rows_split_every_evaluation_into_the_groups(tiny, fns):  # noqa: F811 - the fixture
    ring = math.radians(2.5)
    rs = rows(tiny, (1e-5, 1e-7), ring=ring, functions=fns, log=lambda _: None)
    kinds = {g.kind for g in groups(tiny.switched, round(ring / tiny.dtheta))}
    assert [r["rtol"] for r in rs] == [1e-5] * len(kinds) + [1e-7] * len(kinds)
    for rtol in (1e-5, 1e-7):
        mine = [r for r in rs if r["rtol"] == rtol]
        assert sum(r["share"] for r in mine) == pytest.approx(1.0)
        assert sum(r["degrees"] for r in mine) == pytest.approx(20.0)
    total = {rtol: sum(r["evaluations"] for r in rs if r["rtol"] == rtol) for rtol in (1e-5, 1e-7)}
    assert total[1e-7] > total[1e-5]
    scaled = rows(tiny, (1e-5,), {"v_eps": 10.0}, ring=ring, functions=fns, log=lambda _: None)
    assert [r["evaluations"] for r in scaled] != [r["evaluations"] for r in rs[:len(kinds)]]
    text = markdown(tiny, rs, {"v_eps": 10.0}, ring)
    assert "| 1e-05 | cluster |" in text and "v_eps x 10" in text
