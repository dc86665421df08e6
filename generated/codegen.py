"""CasADi C code of the model's Functions, one file per group.

Groups: ``casadi_model.c`` (rhs and its Jacobian, rhs_switched and its Jacobian,
guards, velocity_guards, outputs) and ``casadi_modes_<k>.c`` (``MODES_PER_FILE``
modes with their Jacobians each). Several files let the compiler work in parallel;
their names depend only on the mode count, never on the machine. Each file gets a
CasADi header (``with_header``) for the C dispatch of ``apexseal_dispatch.c``.
CasADi's own internal symbols carry the file name as prefix, so the files link into
one library without clashes.
"""

from __future__ import annotations

import os
from pathlib import Path

import casadi as ca

from .functions import ModelFunctions

MODES_PER_FILE = 4


def c_groups(fns: ModelFunctions) -> dict[str, list[ca.Function]]:
    """File stem -> the Functions it holds (Jacobians right after their Function)."""
    groups = {"casadi_model": [fns.rhs, fns.rhs_jac, fns.rhs_switched, fns.rhs_switched_jac, fns.guards,
                               fns.velocity_guards, fns.outputs]}
    labels = fns.mode_labels
    for k in range(0, len(labels), MODES_PER_FILE):
        chunk = labels[k:k + MODES_PER_FILE]
        groups[f"casadi_modes_{k // MODES_PER_FILE}"] = [f for lab in chunk for f in (fns.modes[lab], fns.mode_jacs[lab])]
    return groups


def write_c(fns: ModelFunctions, out_dir: Path) -> dict[str, list[str]]:
    """Write every group's ``.c`` and ``.h`` into ``out_dir``; return C file name -> Function names."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    written = {}
    for stem, functions in c_groups(fns).items():
        # CodeGenerator.generate(prefix) writes prefix + file name; Function.generate with a path asserts
        cg = ca.CodeGenerator(f"{stem}.c", {"with_header": True})
        for f in functions:
            cg.add(f)
        cg.generate(str(out_dir) + os.sep)
        written[f"{stem}.c"] = [f.name() for f in functions]
    return written
