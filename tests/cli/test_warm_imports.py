"""What a warm ``apexseal simulate --no-figures -q`` imports (issue: a warm run under a second of wall time).

Pinned by module, not by timing: each of these packages costs a warm run from 0.1 s (dask) to a second
(scipy.signal, sympy) of start-up, and the run needs none of them once the caches are warm (derivation,
compiled libraries, remembered unit conversions: runtime/scenes/unit_memo.py).
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

#: packages the warm run path must not import
HEAVY = ("sympy", "pint", "scipy", "pandas", "xarray", "matplotlib", "dask")

RUN = textwrap.dedent("""
    import json, sys
    from apexseal.cli import main

    try:
        main(["simulate", "--no-figures", "-q", "--out", sys.argv[1]], standalone_mode=False)
    finally:
        print("modules " + json.dumps(sorted(sys.modules)))
""")


def _modules(out) -> set[str]:
    proc = subprocess.run([sys.executable, "-c", RUN, str(out)], capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr[-2000:]
    line = next(x for x in proc.stdout.splitlines() if x.startswith("modules "))
    return set(json.loads(line.split(" ", 1)[1]))


def test_a_warm_run_imports_none_of_the_heavy_packages(tmp_path):
    _modules(tmp_path / "warm-up")  # fills the caches: compiled integrator, unit conversions
    modules = _modules(tmp_path / "run")
    assert "casadi" in modules and "apexseal.runtime.solving.run" in modules  # it did run
    assert "apexseal.commands_bench" not in modules  # sub-commands load on use
    imported = sorted(m for m in modules if any(m == h or m.startswith(h + ".") for h in HEAVY))
    assert not imported, f"the warm run path imported {imported}"
