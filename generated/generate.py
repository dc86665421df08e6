"""Generate the C artefacts of one model: derive, lower, write CasADi C, render templates, record, compile.

``generate(effects, assumptions, out_dir)`` writes into ``out_dir``:

* ``casadi_model.c/.h``: CasADi C of every Function a run executes (the model library);
* ``casadi_model.casadi``: the same SX Functions serialized (integrators embed them, without sympy);
* ``apexseal_model.h`` and ``apexseal_model.c``: rendered from ``templates/`` (names, and the record's
  hash compiled into the library);
* ``manifest.json``: the record of inputs and outputs (see :mod:`.manifest`).

The manifest's sha256 is also recorded in the station's index (:func:`.manifest.trust`), which is what
loaders check it against.

Files are staged in a temporary folder next to ``out_dir`` and moved in one by one
with ``os.replace``; the manifest goes last, so a reader that finds a manifest
finds the files it lists (and :func:`.manifest.verify` checks them anyway).
The time of each stage is printed and returned in ``Manifest.timings``.
"""

from __future__ import annotations

import shutil
import tempfile
import time
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from ..derive.assumptions import Assumptions
from ..derive.cache import cached_model, derivation_files
from ..derive.effects import Effects
from ..files import atomic_write, sha256_file
from ..loaded_code import refuse_edited
from .codegen import write_c, write_serialized
from .functions import ModelFunctions, build_functions, library_groups
from .manifest import FORMAT, MANIFEST_NAME, Manifest, generator_files, hash_of, inputs_record, trust
from .render import render_all

#: file name patterns that generate() owns in an output folder (old ones are removed)
OWNED_PATTERNS = ("casadi_*.c", "casadi_*.h", "casadi_*.casadi", "apexseal_*.c", "apexseal_*.h", MANIFEST_NAME)


class StageTimer:
    """Times named stages and prints one line per stage."""

    def __init__(self, echo: Callable[[str], None] | None = print):
        self.timings: dict[str, float] = {}
        self.echo = echo

    @contextmanager
    def __call__(self, stage: str) -> Iterator[None]:
        t0 = time.perf_counter()
        yield
        dt = time.perf_counter() - t0
        self.timings[stage] = self.timings.get(stage, 0.0) + dt
        if self.echo:
            self.echo(f"[apexseal generate] {stage:<8} {dt:8.2f} s")


def build_record(fns: ModelFunctions, inputs: dict[str, Any], c_files: dict[str, list[str]]) -> dict[str, Any]:
    """The manifest's content except the output files' hashes (also the templates' render context)."""
    file_of = {name: file for file, names in c_files.items() for name in names}
    all_fns = {f.name(): f for group in library_groups(fns).values() for f in group}
    return {
        "format": FORMAT,
        "input_hash": hash_of(inputs),
        "inputs": inputs,
        "names": {
            "state": list(fns.state_names), "parameters": list(fns.parameter_names), "inputs": list(fns.input_names),
            "guards": list(fns.guard_names), "activations": list(fns.activation_names),
            "outputs": list(fns.output_names),
        },
        "modes": [
            {"index": i, "label": m.label, "closed": [int(c) for c in m.closed]}
            for i, m in enumerate(fns.mode_list)
        ],
        "functions": {
            name: {"file": file_of[name], "n_instructions": fns.n_instructions[name],
                   "inputs": f.name_in(), "outputs": f.name_out()}
            for name, f in all_fns.items()
        },
    }


def render_context(record: dict[str, Any], fns: ModelFunctions, c_files: dict[str, list[str]]) -> dict[str, Any]:
    names = record["names"]
    effects = Effects(**record["inputs"]["effects"])
    return {
        **names, "input_hash": record["input_hash"], "modes": record["modes"], "effects_label": effects.label,
        "casadi_headers": [f.removesuffix(".c") + ".h" for f in c_files],
    }


def _install(stage_dir: Path, out_dir: Path, names: list[str]) -> None:
    """Move the staged files into ``out_dir`` (manifest last) and drop owned files that are no longer produced."""
    out_dir.mkdir(parents=True, exist_ok=True)
    for old in {p for pattern in OWNED_PATTERNS for p in out_dir.glob(pattern)}:
        if old.name not in names:
            old.unlink()
    for name in sorted(names, key=lambda n: n == MANIFEST_NAME):
        (stage_dir / name).replace(out_dir / name)


def generate(effects: Effects | None = None, assumptions: Assumptions | None = None, out_dir: Path | str = ".", *,
             flags: str = "optimised", compile: bool = True, echo: Callable[[str], None] | None = print) -> Manifest:
    """Derive (cached), build the Functions, write C + rendered templates + manifest into ``out_dir``, compile.

    ``flags`` ("quick" or "optimised") only affects the compile stage; ``compile=False``
    skips it. Returns the :class:`Manifest` with ``timings`` (seconds per stage:
    derive, lower, codegen, render, compile) and ``library`` (the shared library in
    the cache, or None when not compiled or no compiler works).
    """
    effects = effects or Effects()
    assumptions = assumptions or Assumptions()
    out_dir = Path(out_dir)
    # the C is generated by the code this process imported: refused if a file changed since (loaded_code)
    refuse_edited([*derivation_files(effects, assumptions), *generator_files()], "generate the model's C")
    timer = StageTimer(echo)
    if echo:
        echo(f"[apexseal generate] model {effects.label}: deriving and generating (once per model; cached)")
    with timer("derive"):
        model = cached_model(effects, assumptions)
    with timer("lower"):
        fns = build_functions(model)
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    stage_dir = Path(tempfile.mkdtemp(dir=out_dir.parent, prefix=f".{out_dir.name}.staging."))
    try:
        with timer("codegen"):
            c_files = write_c(fns, stage_dir)
            serialized = write_serialized(fns, stage_dir)
        with timer("render"):
            record = build_record(fns, inputs_record(effects, assumptions), c_files)
            rendered = render_all(render_context(record, fns, c_files), stage_dir)
            names = sorted({*c_files, *(f.removesuffix(".c") + ".h" for f in c_files), serialized, *rendered})
            record["files"] = {name: sha256_file(stage_dir / name) for name in names}
            manifest = Manifest(record, out_dir)
            atomic_write(stage_dir / MANIFEST_NAME, manifest.dumps())
            _install(stage_dir, out_dir, [*names, MANIFEST_NAME])
            trust(out_dir)
    finally:
        shutil.rmtree(stage_dir, ignore_errors=True)
    if compile:
        from .compile import compile_library
        from .compiler import CompilerUnavailable

        with timer("compile"):
            try:
                manifest.library = compile_library(out_dir, flags=flags)
            except CompilerUnavailable as exc:
                from ..signals import StopSignals

                StopSignals.raise_pending()  # the compiler failed because a signal stopped the work
                warnings.warn(str(exc), stacklevel=2)
    manifest.timings = timer.timings
    return manifest
