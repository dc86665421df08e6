"""What runs is what was generated: the station's records on the run path, and a run without sympy."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

from apexseal.generated.compile import build_function, function_dir, function_source
from apexseal.generated.load import DEFAULT_DIR
from apexseal.generated.manifest import read_manifest


def test_compiled_integrator_is_on_the_station_record(default_scene, default_functions):
    """The erk integrator a run compiles calls the model's artefact Functions, and its record says which."""
    from apexseal.runtime.api import settings_of
    from apexseal.runtime.solving.methods import make_engine

    fns = default_functions.c
    manifest = read_manifest(DEFAULT_DIR)
    assert fns.library is not None and fns.model_hash == manifest.input_hash
    assert fns.sx().rhs.is_a("SXFunction") and fns.rhs.is_a("External")
    st = settings_of(default_scene, flags="quick")
    engine = make_engine(fns, st, n_samples=36, span=0.6283185307179586)
    assert engine.compiled
    # what the engine compiled: same C and place
    source = function_source(engine.vm, model_hash=fns.sx().model_hash, link=engine.link)
    src = source.c_file
    record = json.loads((function_dir(src.parent.name) / "function.json").read_text())
    assert record["model"] == manifest.input_hash
    assert record["files"] == {src.name: src.parent.name}
    # the library in the cache was built from exactly this record (a cache hit: nothing is compiled here)
    so = build_function(source, flags="quick")
    built = json.loads((so.parent / "build.json").read_text())
    assert built["sources"]["c_sha256"] == src.parent.name
    assert so.is_file()


RUN = textwrap.dedent("""
    import sys
    import apexseal

    scene = apexseal.load_scene()
    after_scene = "sympy" in sys.modules
    if {block}:
        class Block:
            def find_spec(self, name, path=None, target=None):
                if name == "sympy" or name.startswith("sympy."):
                    raise ImportError("the run imported " + name)
        for m in [m for m in sys.modules if m == "sympy" or m.startswith("sympy.")]:
            del sys.modules[m]
        sys.meta_path.insert(0, Block())
    result = apexseal.simulate(scene, revolutions=1)
    print(result.status, after_scene, "sympy" in sys.modules)
""")


def _run(block: bool) -> list[str]:
    out = subprocess.run([sys.executable, "-c", RUN.format(block=block)], capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    return out.stdout.split()


def test_run_after_load_scene_never_imports_sympy(default_functions):
    """Everything after load_scene (artefacts current) works with sympy made unimportable."""
    status, _, _ = _run(block=True)
    assert status == "completed"


def test_fresh_process_run_leaves_sympy_out(default_functions):
    status, after_scene, after_run = _run(block=False)
    assert status == "completed"
    assert after_scene == "False"  # load_scene reads the scene without sympy (derived parameters in numpy)
    assert after_run == "False"
