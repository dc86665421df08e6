"""Wall time of a warm ``apexseal simulate --no-figures -q`` of the default scene, as a user sees it.

Run ``python -m apexseal.runtime.bench.startup [runs]``: one untimed run (it fills the caches), then ``runs``
timed runs of the CLI in fresh processes (each writes into a temporary folder); prints each run's wall time and
CPU time (user + system of the process, from the operating system: less sensitive than wall time to other work
on the machine) and their medians. Also lists the heavy packages the run imported (``-X importtime`` of the
same command), which should be none. Python writes its bytecode cache as in any install, unless
``PYTHONDONTWRITEBYTECODE`` is set (then every run compiles apexseal's modules again: about 0.2 s more).
"""

from __future__ import annotations

import resource
import statistics
import subprocess
import sys
import tempfile
import time

#: packages a warm run does not need (tests/cli/test_warm_imports.py pins that it imports none of them)
HEAVY = ("sympy", "pint", "scipy", "pandas", "xarray", "matplotlib", "dask")


def _command(out: str) -> list[str]:
    from ...cli import command

    return command("simulate", "--no-figures", "-q", "--out", out)


def _cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def main(runs: int = 5) -> float:
    with tempfile.TemporaryDirectory(prefix="apexseal-startup-") as out:
        subprocess.run(_command(out), check=True, capture_output=True)  # warm-up: caches filled
        walls, cpus = [], []
        for _ in range(runs):
            c0, t0 = _cpu(), time.perf_counter()
            subprocess.run(_command(out), check=True, capture_output=True)
            walls.append(time.perf_counter() - t0)
            cpus.append(_cpu() - c0)
            print(f"warm apexseal simulate --no-figures -q: {walls[-1]:.2f} s wall, {cpus[-1]:.2f} s CPU")
        trace = subprocess.run([sys.executable, "-X", "importtime", *_command(out)[1:]], capture_output=True, text=True)
        heavy = sorted({line.split("|")[-1].strip().split(".")[0] for line in trace.stderr.splitlines()
                        if line.split("|")[-1].strip().split(".")[0] in HEAVY})
    median = statistics.median(walls)
    print(f"median of {runs}: {median:.2f} s wall, {statistics.median(cpus):.2f} s CPU; heavy modules imported: "
          f"{', '.join(heavy) or 'none'}")
    return median


if __name__ == "__main__":
    import argparse

    parser = argparse.ArgumentParser(prog="python -m apexseal.runtime.bench.startup", description=__doc__)
    parser.add_argument("runs", nargs="?", type=int, default=5, help="timed runs (default: 5)")
    main(parser.parse_args().runs)
