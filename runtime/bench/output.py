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
