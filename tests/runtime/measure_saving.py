"""What saving costs next to simulating, and whether memory grows with the run (README, "Faults and results").

Run: ``python tests/runtime/measure_saving.py [revolutions]`` (default 50, the default scene, compiled erk). Per
revolution it times the integrator calls, the assembly of the revolution's outputs and the writing of its part
(with the progress record); it prints the medians, their ratios, the totals, the final read-back, the optional
CSV, and the peak resident memory after the 5th and the last revolution.
"""

from __future__ import annotations

import resource
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import apexseal
from apexseal.runtime.api import run_scene, settings_of
from apexseal.runtime.results.folder import ResultFolder
from apexseal.runtime.results.reading import read
from apexseal.runtime.solving import run as run_mod


def peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


class TimedFolder(ResultFolder):
    def __init__(self, *a, **k):
        super().__init__(*a, **k)
        self.write_s: list[float] = []
        self.peaks: list[float] = []

    def append(self, part, z_end=None, carried=None):
        t = time.perf_counter()
        super().append(part, z_end, carried)
        self.write_s.append(time.perf_counter() - t)
        self.peaks.append(peak_mb())


def main(revolutions: int = 50) -> None:
    if revolutions < 5:
        raise SystemExit(f"revolutions = {revolutions}: the memory after the 5th revolution is compared with the "
                         "last; allowed: revolutions >= 5")
    scene = apexseal.load_scene()
    settings = settings_of(scene, revolutions=revolutions)
    calls, assembly = [], []
    real_make, real_assemble = run_mod.make_engine, run_mod.assemble_blocks

    def make_engine(*a, **k):
        engine = real_make(*a, **k)
        run = engine.run

        def timed(*args):
            t = time.perf_counter()
            out = run(*args)
            calls.append(time.perf_counter() - t)
            return out

        engine.run = timed
        return engine

    def assemble_blocks(*a, **k):
        t = time.perf_counter()
        out = real_assemble(*a, **k)
        assembly.append(time.perf_counter() - t)
        return out

    run_mod.make_engine, run_mod.assemble_blocks = make_engine, assemble_blocks
    run_scene(scene, settings.replace(revolutions=1))  # compile (or load) the integrator first
    calls.clear()
    assembly.clear()
    with tempfile.TemporaryDirectory() as tmp:
        sink = TimedFolder(Path(tmp) / "out")
        t = time.perf_counter()
        result = run_scene(scene, settings, sink=sink)
        total = time.perf_counter() - t
        t = time.perf_counter()
        read(sink.staging)
        read_s = time.perf_counter() - t
        t = time.perf_counter()
        sink.write_csv()
        csv_s = time.perf_counter() - t
        sink.commit()
    sim, asm, wr = np.median(calls), np.median(assembly), np.median(sink.write_s)
    print(f"{revolutions} revolutions of the default scene ({settings.samples_per_revolution} samples each, "
          f"{settings.method}, compiled={result.info['compiled']}): {result.status}, {result.n} samples")
    print(f"median per revolution: integrator {sim * 1e3:.1f} ms, assembly {asm * 1e3:.1f} ms, "
          f"writing the part {wr * 1e3:.1f} ms")
    print(f"ratios of medians: writing / integrator = {wr / sim:.3f}, (assembly + writing) / integrator = "
          f"{(asm + wr) / sim:.2f}")
    print(f"totals: run {total:.2f} s (integrator {sum(calls):.2f} s, assembly {sum(assembly):.2f} s, writing "
          f"{sum(sink.write_s):.2f} s); read back {read_s:.2f} s; trajectory.csv on request {csv_s:.2f} s")
    print(f"peak resident memory: {sink.peaks[4]:.0f} MB after revolution 5, {sink.peaks[-1]:.0f} MB after "
          f"revolution {len(sink.peaks)}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 50)
