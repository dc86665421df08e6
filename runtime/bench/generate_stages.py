"""The generation station's stage times, cold and warm, as the README's "Code generation" table gives them.

Run ``python -m apexseal.runtime.bench.generate_stages [runs]``: ``runs`` times, each in a new empty cache,
``apexseal generate --flags quick --out DIR`` (everything cold: derivation, lowering, code generation, the
library compiled without optimisation) and then ``apexseal generate --flags optimised --out DIR`` (the derivation
cached, the library compiled again with optimisation); prints each run's stage times as the command reports them
and, per stage and flags, the median with the range.
"""

from __future__ import annotations

import os
import re
import statistics
import subprocess
import sys
import tempfile

#: a stage line of ``apexseal generate``: ``[apexseal generate] derive       1.96 s``
_STAGE = re.compile(r"\] (\w+)\s+([\d.]+) s$", re.M)


def _command(*args: str) -> list[str]:
    from ...cli import command

    return command("generate", *args)


def main(runs: int = 5) -> dict[str, dict[str, list[float]]]:
    times: dict[str, dict[str, list[float]]] = {"quick": {}, "optimised": {}}
    for i in range(runs):
        with tempfile.TemporaryDirectory(prefix="apexseal-stages-") as tmp:
            env = os.environ | {"APEXSEAL_CACHE": os.path.join(tmp, "cache")}
            for flags in times:
                out = subprocess.run(_command("--flags", flags, "--out", os.path.join(tmp, flags)), env=env,
                                     check=True, capture_output=True, text=True).stdout
                stages = {m.group(1): float(m.group(2)) for m in _STAGE.finditer(out)}
                for stage, seconds in stages.items():
                    times[flags].setdefault(stage, []).append(seconds)
                print(f"run {i + 1}/{runs}, {flags}: " + ", ".join(f"{k} {v:.2f} s" for k, v in stages.items()),
                      flush=True)
    print(f"load average at the end: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")
    for flags, stages in times.items():
        print(f"medians of {runs}, {flags}: " + ", ".join(
            f"{k} {statistics.median(v):.2f} s ({min(v):.2f}-{max(v):.2f})" for k, v in stages.items()))
    return times


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 5)
