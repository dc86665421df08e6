"""What a process keeps from one run to the next: the loaded model while its files are unchanged, and, between
a study's runs (a sweep's points), the engines of the same model and settings; reused, they give the same numbers."""

from __future__ import annotations

import os

import numpy as np
import pytest

import apexseal
from apexseal.generated import load
from apexseal.runtime.solving import engine_pool, methods
from apexseal.runtime.solving import run as run_module


def test_the_loaded_model_is_kept_while_its_files_are_unchanged(artefacts, monkeypatch):
    """A second load returns the same Functions; a manifest whose stat changed is checked and loaded again; a C
    file edited together with its hash in the manifest after a load is refused at the next load, as at the first.
    (On a private copy of the committed artefacts, trusted as the station's.)"""
    import json

    from apexseal.files import sha256_file
    from apexseal.generated.manifest import StaleArtefactWarning, trust

    trust(artefacts)
    monkeypatch.setattr(load, "DEFAULT_DIR", artefacts)
    first = load.load_functions()
    assert first.source_dir == artefacts
    assert load.load_functions() is first
    assert load.load_functions(compiled=False) is not first
    manifest = artefacts / load.MANIFEST_NAME
    st = manifest.stat()
    os.utime(manifest, ns=(st.st_atime_ns, st.st_mtime_ns + 1))  # the same bytes, another stat
    again = load.load_functions()
    assert again is not first and again.manifest.input_hash == first.manifest.input_hash
    assert load.load_functions() is again
    path = artefacts / "casadi_model.c"
    path.write_text(path.read_text().replace("casadi_real", "casadi_real ", 1))
    data = json.loads(manifest.read_text())
    data["files"]["casadi_model.c"] = sha256_file(path)
    manifest.write_text(json.dumps(data, indent=2) + "\n")
    with pytest.warns(StaleArtefactWarning, match="not the one the generator recorded"):
        edited = load.load_functions()
    assert edited.source_dir != artefacts  # regenerated artefacts, never the edited ones


@pytest.fixture
def builds(monkeypatch):
    """The engines built (not taken from the pool) during a test, with an empty pool at its start."""
    engine_pool.clear()
    made = []

    def counting(*args, **kwargs):
        made.append(methods.make_engine(*args, **kwargs))
        return made[-1]

    monkeypatch.setattr(run_module, "make_engine", counting)
    monkeypatch.setattr(engine_pool, "make_engine", counting)
    yield made
    engine_pool.clear()


@pytest.mark.parametrize("method", ["erk", "composite"])
def test_a_kept_engine_gives_the_numbers_of_a_new_one(default_scene, builds, method):
    """The second run of the same model and settings takes the first run's engine, and its result is the same
    to the bit; another tolerance builds another engine."""
    scene = default_scene.with_overrides(**{"solver.method": method, "solver.samples_per_revolution": 360})
    with apexseal.reusing_engines():  # the public name of engine_pool.reusing
        first = apexseal.simulate(scene)
        assert len(builds) == 1
        second = apexseal.simulate(scene.with_overrides(**{"spring.delta_s": "0.9 mm"}))  # same engine
        third = apexseal.simulate(scene)
        assert len(builds) == 1
        np.testing.assert_array_equal(third.state, first.state)
        assert not np.array_equal(second.state, first.state)
        engine_pool.clear()
        np.testing.assert_array_equal(apexseal.simulate(scene).state, first.state)  # a new engine: the same numbers
        apexseal.simulate(scene, rtol=1e-7)
        assert len(builds) == 3
    apexseal.simulate(scene)  # outside: a new engine, not kept
    assert len(builds) == 4


def test_outside_a_study_every_run_builds_its_engine(default_scene, builds):
    """Without reusing(), nothing is kept: an engine depends on module constants a user may change between runs."""
    apexseal.simulate(default_scene, samples_per_revolution=360)
    apexseal.simulate(default_scene, samples_per_revolution=360)
    assert len(builds) == 2 and not engine_pool._free


def test_an_engine_serves_one_run_at_a_time(default_functions, default_scene, builds):
    """While a run holds an engine, another run with the same key builds its own; both are kept after."""
    from apexseal.runtime.api import settings_of

    st = settings_of(default_scene)
    with engine_pool.reusing():
        _leases(default_functions, st, builds)


def _leases(default_functions, st, builds):
    a = engine_pool.lease(default_functions.c, st, n_samples=36, span=0.6283185307179586)
    b = engine_pool.lease(default_functions.c, st, n_samples=36, span=0.6283185307179586)
    assert a.engine is not b.engine and len(builds) == 2
    a.release()
    b.release()
    c = engine_pool.lease(default_functions.c, st, n_samples=36, span=0.6283185307179586)
    assert c.engine in (a.engine, b.engine) and len(builds) == 2
