"""The order in which a parallel build starts its C files: the default model library built with its files started
in order of :func:`~apexseal.generated.compile.compile_cost` (the build's order) and in order of size (the order
before it), interleaved, in one process.

Run ``python -m apexseal.runtime.bench.build_order [runs]`` (default 5): prints each build's wall time, the medians
and their ratio. It compiles the committed C of ``generated/default`` with the ``optimised`` flags into temporary
folders (nothing is cached).
"""

from __future__ import annotations

import statistics
import sys
import tempfile
import time
from pathlib import Path

from ...generated import compile as build
from ...generated.compiler import compiler, flag_list

ORDERS = {"compile_cost": build.compile_cost, "size": lambda p: p.stat().st_size}


def main(runs: int = 5) -> dict[str, list[float]]:
    files = sorted((Path(build.__file__).parent / "default").glob("*.c"))
    flags, cc = flag_list("optimised"), compiler()
    times: dict[str, list[float]] = {name: [] for name in ORDERS}
    for i in range(runs):
        for name, key in ORDERS.items():
            order = sorted(files, key=key, reverse=True)
            with tempfile.TemporaryDirectory(prefix="apexseal-order-") as tmp:
                t = time.perf_counter()
                build._compile_all(cc, flags, files, Path(tmp), Path(tmp) / "lib.so", order_by=key)
                times[name].append(time.perf_counter() - t)
            print(f"run {i + 1}/{runs}, by {name} ({', '.join(p.name for p in order)}): {times[name][-1]:.2f} s",
                  flush=True)
    med = {name: statistics.median(v) for name, v in times.items()}
    for name, v in times.items():
        print(f"by {name}: median {med[name]:.2f} s ({min(v):.2f}-{max(v):.2f})")
    print(f"ratio compile_cost / size: {med['compile_cost'] / med['size']:.2f}")
    return times


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 5)
