"""How long a default run's figures take against its simulation: ``python -m apexseal.runtime.results.timing``.

Runs the default scene once to warm the caches (derivation, compiled libraries), then ``repeats`` times:
``apexseal.simulate(scene)`` (wall time of the call: integrator set-up from the cache plus integration; and
the integration alone, ``result.info["wall_time_s"]``) and :func:`.figures.write_figures` (draw and save the four
PNG files), as ``apexseal simulate`` draws them (some in a forked second process, :mod:`.figure_job`) and all in
this process, in turn. Prints the medians and their ratios, all measured in one process.
"""

from __future__ import annotations

import statistics
import sys
import tempfile
import time


def measure(repeats: int = 5) -> dict:
    import apexseal

    from .figures import ports_of, write_figures

    scene = apexseal.load_scene()
    result = apexseal.simulate(scene)  # warm-up: derivation and compilation come from the caches afterwards
    with tempfile.TemporaryDirectory() as tmp:
        write_figures(result, tmp, ports_of(scene))
        call, integration, figures, alone = [], [], [], []
        for _ in range(repeats):
            t0 = time.perf_counter()
            result = apexseal.simulate(scene)
            call.append(time.perf_counter() - t0)
            integration.append(result.info["wall_time_s"])
            t0 = time.perf_counter()
            write_figures(result, tmp, ports_of(scene), fork=True)
            figures.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            write_figures(result, tmp, ports_of(scene), fork=False)
            alone.append(time.perf_counter() - t0)
    med = {k: statistics.median(v) for k, v in (("simulate_call_s", call), ("integration_s", integration),
                                                  ("figures_s", figures), ("figures_one_process_s", alone))}
    med["figures_over_simulate_call"] = med["figures_s"] / med["simulate_call_s"]
    med["figures_over_integration"] = med["figures_s"] / med["integration_s"]
    med["repeats"] = repeats
    return med


def main() -> None:
    repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    m = measure(repeats)
    print(f"default scene, medians of {repeats} runs: simulate() {m['simulate_call_s']:.2f} s (integration "
          f"{m['integration_s']:.2f} s); four figures {m['figures_s']:.2f} s = {m['figures_over_simulate_call']:.2f} x "
          f"the simulate() call, {m['figures_over_integration']:.1f} x the integration (in one process: "
          f"{m['figures_one_process_s']:.2f} s)")


if __name__ == "__main__":
    main()
