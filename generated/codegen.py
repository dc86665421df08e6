"""CasADi C code of the model's Functions, and the same Functions serialized.

``casadi_model.c`` (with its header) holds what a run executes: rhs and its Jacobian,
rhs_switched, guards, outputs, and the hybrid DAE's ``hybrid_ode`` and ``hybrid_zero``
(the compiled erk integrator calls them); ``casadi_model_events.c`` the derivatives of those that it calls at
events only. Both are compiled into the model library.
``casadi_model.casadi`` holds the same SX Functions serialized by CasADi (deterministic
text): the runtime deserializes them to build integrators without sympy, so the
Functions an integrator embeds are the ones whose C is in the library.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

import casadi as ca

from .functions import ModelFunctions, library_groups

SERIALIZED = "casadi_model.casadi"
#: the SX Functions serialized (their Jacobian is rebuilt from them when needed)
SERIALIZED_FUNCTIONS = ("rhs", "rhs_switched", "guards", "outputs")


def serialized(functions: Iterable[ca.Function]) -> str:
    """The Functions in one CasADi serialization (deterministic text), in the order given."""
    s = ca.StringSerializer()
    for f in functions:
        s.pack(f)
    return s.encode()


def write_serialized(fns: ModelFunctions, out_dir: Path) -> str:
    """Write the SX Functions of :data:`SERIALIZED_FUNCTIONS` into one CasADi serialization; return its name."""
    every = fns.functions()
    (Path(out_dir) / SERIALIZED).write_text(serialized(every[name] for name in SERIALIZED_FUNCTIONS) + "\n")
    return SERIALIZED


def read_serialized(path: Path) -> dict[str, ca.Function]:
    """The Functions of a file written by :func:`write_serialized`, by name."""
    d = ca.StringDeserializer(Path(path).read_text().strip())
    out = {}
    for _ in SERIALIZED_FUNCTIONS:
        f = d.unpack()
        out[f.name()] = f
    return out


def write_c(fns: ModelFunctions, out_dir: Path) -> dict[str, list[str]]:
    """Write every group's ``.c`` and ``.h`` into ``out_dir``; return C file name -> Function names."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    written = {}
    for stem, functions in library_groups(fns).items():
        if not functions:
            continue
        # CodeGenerator.generate(prefix) writes prefix + file name; Function.generate with a path asserts
        cg = ca.CodeGenerator(f"{stem}.c", {"with_header": True})
        for f in functions:
            cg.add(f)
        cg.generate(str(out_dir) + os.sep)
        written[f"{stem}.c"] = [f.name() for f in functions]
    return written
