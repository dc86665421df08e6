"""trajectory.csv (on request): one row per sample, written part by part with one format operation per row.

The first line, ``# apexseal result <run id>, <n> samples``, ties the file to its result.json (pandas:
``read_csv(path, comment="#")``); the header carries each column's SI unit (``x [m]``, docs/outputs.md).
Formatting numbers as text is what costs (``python tests/runtime/measure_saving.py`` times it), so the binary
parts (parts/*.npz) are the default format.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from .outputs import header as units_header
from .result import SimulationResult


def header(part: SimulationResult, guard_names) -> list[str]:
    """The column names with their SI units (``x [m]``), from the one table of outputs (docs/outputs.md)."""
    return units_header(["theta_deg", "time_s", *part.state_names, "mode", *[f"closed_{g}" for g in guard_names],
                         *part.outputs])


def write_csv(fh, run_id: str, samples: int, parts: Iterable[SimulationResult], guard_names=None) -> None:
    """Write the CSV of ``parts`` (consecutive parts of one result) to the text file ``fh``."""
    fh.write(f"# apexseal result {run_id}, {samples} samples\n")
    first = True
    for part in parts:
        guards = guard_names or [f"{i}" for i in range(part.closed.shape[0])]
        if first:
            fh.write(",".join(header(part, guard_names or guards)) + "\n")
            first = False
        if not part.n:
            continue
        n_x, n_g, n_o = part.state.shape[0], part.closed.shape[0], len(part.outputs)
        row = ",".join(["%.6f", "%.9e", *["%.9e"] * n_x, "%s", *["%d"] * n_g, *["%.9e"] * n_o])
        numbers = np.vstack([np.degrees(part.theta), part.time, part.state]).T.tolist()
        closed = part.closed.T.astype(int).tolist()
        outs = np.vstack([part.outputs[k] for k in part.outputs]).T.tolist() if n_o else [[]] * part.n
        fh.write("\n".join(row % (*a, m, *c, *o) for a, m, c, o in zip(numbers, part.modes, closed, outs, strict=True)))
        fh.write("\n")
