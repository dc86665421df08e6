"""What the model's outputs and guards cost per sample, in the model library's loop and in CasADi's map
(runtime/results/sampled.py): ``python -m apexseal.runtime.bench.sample_cost [N]`` times both at N samples (one
revolution of the default run's, 3600, by default), medians of 9 interleaved calls after a warm-up."""

from __future__ import annotations

import statistics
import sys
import time

import numpy as np

from ..api import model_functions
from ..results.sampled import looped_outputs, mapped_outputs
from ..scenes.scene import load_scene


def main(argv=None) -> None:
    """Time both ways at one revolution of the default run's samples (3600): medians of 9 after a warm-up."""
    import argparse

    parser = argparse.ArgumentParser(prog="python -m apexseal.runtime.bench.sample_cost", description=__doc__)
    parser.add_argument("samples", nargs="?", type=int, default=3600, help="samples to time (default: 3600)")
    n = parser.parse_args(sys.argv[1:] if argv is None else argv).samples
    sc = load_scene()
    f = model_functions(sc)
    if f.library is None:
        raise SystemExit("no compiled model library (no C compiler?): nothing to compare")
    rng = np.random.default_rng(0)
    theta = np.linspace(0.0, 2 * np.pi, n)
    X = rng.normal(size=(len(f.state_names), n)) * np.array([1e-6, 3e-5, 5e-3, 1e-3, 0.1, 1.0])[:, None]
    closed = rng.integers(0, 2, (len(f.guard_names), n)).astype(float)
    U = np.full((f.outputs.size1_in(4), n), 2e5)
    P = sc.parameter_vector(f.parameter_names)
    ways = {"library loop": lambda: looped_outputs(f, theta, X, closed, P, U),
            "CasADi map": lambda: mapped_outputs(f, theta, X, closed, P, U)}
    times = {k: [] for k in ways}
    for call in ways.values():  # warm-up: maps built, library loaded
        call()
    for _ in range(9):  # interleaved
        for k, call in ways.items():
            t = time.perf_counter()
            call()
            times[k].append(time.perf_counter() - t)
    for k, ts in times.items():
        print(f"{k}: {1e3 * statistics.median(ts):.2f} ms for {n} samples ({1e9 * statistics.median(ts) / n:.0f} ns "
              "per sample, outputs and guards)")


if __name__ == "__main__":
    main()
