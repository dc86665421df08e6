"""Write a benchmark result: results.json, table.md, effects.md and work-precision.png (atomically, file by file)."""

from __future__ import annotations

import json
import math
import os
import tempfile
from pathlib import Path

import numpy as np

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


def _write_text(path: Path, text: str) -> None:
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    with os.fdopen(fd, "w", encoding="utf-8") as fh:
        fh.write(text)
    os.chmod(tmp, 0o644)
    os.replace(tmp, path)


def write_outputs(results: dict, out: Path, command: str) -> dict[str, Path]:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    results = dict(results, command=command)
    paths = {name: out / name for name in FILES}
    _write_text(paths["results.json"], json.dumps(_clean(results), indent=1) + "\n")
    _write_text(paths["table.md"], table_md(results, command) + "\n")
    _write_text(paths["effects.md"], effects_md(results, command))
    tmp = out / ".work-precision.tmp.png"
    work_precision(results, tmp)
    os.replace(tmp, paths["work-precision.png"])
    return paths
