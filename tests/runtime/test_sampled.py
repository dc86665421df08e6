"""The outputs and guards at many samples (runtime/results/sampled.py): the library's loop gives CasADi's numbers.

The loop calls the compiled Functions the CasADi externals call, so the two ways must agree to the bit; the
interpreted (SX) Functions, which have no library, take CasADi's map and agree to round-off.
"""

from __future__ import annotations

import numpy as np
import pytest

from apexseal.runtime.api import model_functions
from apexseal.runtime.results.sampled import guards_at, mapped, outputs_at
from apexseal.runtime.scenes.scene import embedded_scene_path, load_scene


def _samples(f, n: int, seed: int):
    rng = np.random.default_rng(seed)
    theta = rng.uniform(0.0, 2 * np.pi, n)
    spread = np.ones(len(f.state_names))
    spread[:6] = [1e-6, 3e-5, 5e-3, 1e-3, 0.1, 1.0]
    X = rng.normal(size=(len(f.state_names), n)) * spread[:, None]
    if len(f.state_names) > 6:  # the chamber gas states (pressures and temperatures): positive
        X[6:] = rng.uniform(1e5, 5e5, (len(f.state_names) - 6, n))
    closed = rng.integers(0, 2, (len(f.guard_names), n)).astype(bool)
    U = rng.uniform(1e5, 8e5, (f.outputs.size1_in(4), n))
    return theta, X, closed, U


@pytest.mark.parametrize("scene_name", [None, "expander-gas.toml"])
def test_the_library_loop_gives_casadis_map_to_the_bit(scene_name):
    sc = load_scene(scene_name and embedded_scene_path(scene_name))
    f = model_functions(sc)
    if f.library is None:
        pytest.skip("no compiled model library (no C compiler)")
    P = sc.parameter_vector()
    theta, X, closed, U = _samples(f, 257, 3)
    Y, g = outputs_at(f, theta, X, closed, P, U)
    n = theta.size
    Y_map = mapped(f.outputs, n)(theta[None, :], X, closed.astype(float), P, U).full()
    g_map = mapped(f.guards, n)(theta[None, :], X, P, U).full()
    assert Y.shape == (len(f.output_names), n) and g.shape == (len(f.guard_names), n)
    np.testing.assert_array_equal(Y, Y_map)
    np.testing.assert_array_equal(g, g_map)
    np.testing.assert_array_equal(guards_at(f, theta, X, P, U), g_map)
    assert np.isfinite(Y).all() and np.ptp(Y, axis=1).max() > 0  # the samples differ, and so do their outputs


def test_without_a_library_the_map_of_the_sx_functions_agrees():
    sc = load_scene()
    c, sx = model_functions(sc), model_functions(sc, compiled=False)
    assert sx.library is None
    P = sc.parameter_vector()
    theta, X, closed, U = _samples(sx, 64, 5)
    Y, g = outputs_at(sx, theta, X, closed, P, U)
    if c.library is not None:
        Yc, gc = outputs_at(c, theta, X, closed, P, U)
        np.testing.assert_allclose(Y, Yc, rtol=1e-12, atol=1e-12 * np.abs(Yc).max())
        np.testing.assert_allclose(g, gc, rtol=1e-12, atol=1e-18)


def test_a_library_without_the_loop_falls_back_to_the_map(monkeypatch):
    """A model library compiled before the loop existed has no ``apexseal_outputs_block``: the map serves."""
    from apexseal.runtime.results import sampled

    sc = load_scene()
    f = model_functions(sc)
    if f.library is None:
        pytest.skip("no compiled model library (no C compiler)")
    P = sc.parameter_vector()
    theta, X, closed, U = _samples(f, 32, 7)
    calls = []
    monkeypatch.setattr(sampled, "_block", lambda library: calls.append(library))
    monkeypatch.setattr(sampled, "looped_outputs", lambda *a: pytest.fail("the loop was called"))
    Y, g = outputs_at(f, theta, X, closed, P, U)
    assert calls and Y.shape == (len(f.output_names), theta.size)
    np.testing.assert_array_equal(g, mapped(f.guards, theta.size)(theta[None, :], X, P, U).full())


def test_the_cost_command_times_both_ways(capsys):
    from apexseal.runtime.bench import sample_cost

    if model_functions(load_scene()).library is None:
        pytest.skip("no compiled model library (no C compiler)")
    sample_cost.main(["64"])
    lines = capsys.readouterr().out.splitlines()
    assert [line.split(":")[0] for line in lines] == ["library loop", "CasADi map"]
    assert all("for 64 samples" in line and float(line.split()[2]) > 0 for line in lines)
