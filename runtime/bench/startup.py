"""Wall time of a warm ``apexseal simulate --no-figures -q`` of the default scene, as a user sees it.

Run ``python -m apexseal.runtime.bench.startup [runs]``: one untimed run (it fills the caches), then ``runs``
timed runs of the CLI in fresh processes (each writes into a temporary folder); prints each wall time and the
median. Also says whether the run imported sympy (``-X importtime`` of the same command).
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
import time


def _command(out: str) -> list[str]:
    return [sys.executable, "-c", "from apexseal.cli import main; main()", "simulate", "--no-figures", "-q", "--out", out]


def main(runs: int = 5) -> float:
    with tempfile.TemporaryDirectory(prefix="apexseal-startup-") as out:
        subprocess.run(_command(out), check=True, capture_output=True)  # warm-up: caches filled
        walls = []
        for _ in range(runs):
            t0 = time.perf_counter()
            subprocess.run(_command(out), check=True, capture_output=True)
            walls.append(time.perf_counter() - t0)
            print(f"warm apexseal simulate --no-figures -q: {walls[-1]:.2f} s wall")
        trace = subprocess.run([sys.executable, "-X", "importtime", *_command(out)[1:]], capture_output=True, text=True)
        heavy = sorted({line.split("|")[-1].strip().split(".")[0] for line in trace.stderr.splitlines()
                        if line.split("|")[-1].strip().split(".")[0] in ("sympy", "pint", "matplotlib", "pydantic")})
    median = statistics.median(walls)
    print(f"median of {runs}: {median:.2f} s wall; heavy modules imported: {', '.join(heavy) or 'none'}")
    return median


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 5)
