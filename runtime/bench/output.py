"""Write a benchmark result: results.json, table.md, effects.md and work-precision.png (atomically, file by file)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from ...files import atomic_open, atomic_write
from .plot import work_precision
from .report import effects_md, table_md

FILES = ("results.json", "table.md", "effects.md", "work-precision.png")


def _clean(v):
    """JSON-safe: numpy scalars and arrays to Python, non-finite floats to None."""
    if isinstance(v, dict):
        return {str(k): _clean(x) for k, x in v.items()}
    if isinstance(v, list | tuple):
        return [_clean(x) for x in v]
    if isinstance(v, np.ndarray):
        return _clean(v.tolist())
    if isinstance(v, np.generic):
        v = v.item()
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def write_outputs(results: dict, out: Path, command: str) -> dict[str, Path]:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    results = dict(results, command=command)
    paths = {name: out / name for name in FILES}
    atomic_write(paths["results.json"], json.dumps(_clean(results), indent=1) + "\n")
    atomic_write(paths["table.md"], table_md(results, command) + "\n")
    atomic_write(paths["effects.md"], effects_md(results, command))
    with atomic_open(paths["work-precision.png"], "wb") as fh:
        work_precision(results, fh)
    return paths


def rewrite_reports(folder: Path) -> list[Path]:
    """Write ``table.md``, ``effects.md`` and ``work-precision.png`` of a benchmark folder again from its
    ``results.json``, without running anything: after a change of the reports or of the diagram, a committed run
    shows them (``python -m apexseal.runtime.bench.output docs/bench``). A folder without effects.md (a run kept
    for its table alone) gets none."""
    folder = Path(folder)
    results = json.loads((folder / "results.json").read_text())
    command = results["command"]
    written = [folder / "table.md"]
    atomic_write(folder / "table.md", table_md(results, command) + "\n")
    if (folder / "effects.md").exists():
        atomic_write(folder / "effects.md", effects_md(results, command))
        written.append(folder / "effects.md")
    with atomic_open(folder / "work-precision.png", "wb") as fh:
        work_precision(results, fh)
    return [*written, folder / "work-precision.png"]


if __name__ == "__main__":
    import argparse

    parser = argparse.ArgumentParser(prog="python -m apexseal.runtime.bench.output",
                                     description="Write the reports of benchmark runs again from their results.json.")
    parser.add_argument("folders", nargs="*", default=["apexseal-out/bench"], type=Path,
                        help="folders holding results.json (default: apexseal-out/bench)")
    for folder in parser.parse_args().folders:
        for path in rewrite_reports(folder):
            print(f"wrote {path}")
