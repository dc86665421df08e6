"""The model's Functions for a scene, from the station's artefacts: no derivation when they are current.

``load_functions(effects, assumptions)`` returns a :class:`LoadedFunctions` with

* ``.sx``: the SX Functions, deserialized from the artefacts' ``casadi_model.casadi`` (the Functions
  whose C is ``casadi_model.c``); integrators embed these;
* ``.c``: the same Functions as ``casadi.external`` of the compiled model library (or the SX ones,
  with a :class:`~.compile.CompilerFallbackWarning`, when no compiler works).

Names of the state, parameters, guards, outputs and modes come from the manifest, not from the
derivation, so a run whose artefacts are current never imports sympy.

Where the artefacts come from: for the default effects and assumptions, the committed folder
``generated/default/`` if it is current and its manifest is the one the station recorded (else a
:class:`~.manifest.StaleArtefactWarning` and they are regenerated into the cache); otherwise
``cache_dir()/gen/<input hash>/``, derived and generated on first use (with progress lines).
"""

from __future__ import annotations

import ctypes
import os
import shlex
import warnings
from dataclasses import dataclass
from pathlib import Path

from ..derive.assumptions import Assumptions
from ..derive.cache import cache_dir
from ..derive.choices import options_of
from ..derive.effects import Effects
from ..derive.modes import Mode
from ..derive.submodels.registry import extended
from ..files import content_key, file_lock, stat_key, writing_cache
from ..progress import stage
from .codegen import SERIALIZED, read_serialized
from .compile import compiled_or_interpreted
from .compiler import compiler
from .functions import ModelFunctions, with_hybrid
from .manifest import MANIFEST_NAME, Manifest, StaleArtefactError, StaleArtefactWarning, input_hash, verify

DEFAULT_DIR = Path(__file__).resolve().parent / "default"


@dataclass
class LoadedFunctions:
    sx: ModelFunctions
    #: compiled externals (or ``sx`` after a compiler fallback); None with ``compiled=False``
    c: ModelFunctions | None
    manifest: Manifest | None
    #: folder of the C artefacts, and the compiled library (None: not compiled)
    source_dir: Path | None
    library: Path | None

    @property
    def compiled(self) -> bool:
        return self.library is not None


def is_default(effects: Effects, assumptions: Assumptions) -> bool:
    """The committed default artefacts are for these inputs: the default effects and assumptions, with the
    built-in submodels alone (a user's submodel that is on changes the model's inputs, so they are not stale then,
    only not for this model: no warning, its artefacts come from the cache; one that is off changes nothing)."""
    return (effects == Effects() and assumptions == Assumptions()
            and not extended(options_of(effects, assumptions)))


def _out_argument(folder: Path) -> str:
    """``folder`` as a command's argument: relative to the working folder when inside it (``generated/default``
    in a checkout), otherwise whole (an installed package's folder), quoted for a shell where needed."""
    try:
        shown = Path(os.path.relpath(folder))
    except ValueError:  # another drive
        shown = folder
    return shlex.quote(str(folder if shown.parts[:1] == ("..",) else shown))


def refresh_command() -> str:
    """The command that regenerates the committed default artefacts (:data:`DEFAULT_DIR`), as one types it where
    one stands (the stale warning's and ``apexseal generate --check``'s advice)."""
    return f"apexseal generate --out {_out_argument(DEFAULT_DIR)} --no-compile"


def _current(directory: Path, expected: str) -> bool:
    try:
        verify(directory, expected_hash=expected, trusted=True)
    except StaleArtefactError as exc:
        if (directory / MANIFEST_NAME).exists():
            warnings.warn(f"{exc}; regenerating", StaleArtefactWarning, stacklevel=4)
        return False
    return True


def artefact_dir(effects: Effects | None = None, assumptions: Assumptions | None = None, *, echo=None) -> Path:
    """The folder holding current, trusted artefacts for these inputs (deriving and generating them if needed;
    current ones are only read, and a cache that cannot take new ones raises :class:`~apexseal.files.CacheError`)."""
    effects = effects or Effects()
    assumptions = assumptions or Assumptions()
    expected = input_hash(effects, assumptions)
    if is_default(effects, assumptions):
        try:
            verify(DEFAULT_DIR, expected_hash=expected, trusted=True)
            return DEFAULT_DIR
        except StaleArtefactError as exc:
            warnings.warn(f"{exc}. Using regenerated artefacts from the cache instead; refresh the committed ones "
                          f"with `{refresh_command()}`", StaleArtefactWarning,
                          stacklevel=3)
    target = cache_dir() / "gen" / expected
    if target.is_dir() and _current(target, expected):
        return target
    with writing_cache(cache_dir()), file_lock(cache_dir() / "gen" / f"{expected}.lock",
                                               f"the artefacts of effects {effects.label}"):
        try:
            verify(target, expected_hash=expected, trusted=True)  # another process generated it while we waited
            return target
        except StaleArtefactError:
            pass  # generated below, outside this handler: a failing derivation is not reported as a missing manifest
        from .generate import generate  # the station (jinja2, the derivation): imported only to generate

        with stage(f"deriving the equations of motion and generating their C for effects {effects.label} "
                   "(first use; cached afterwards)"):
            generate(effects, assumptions, target, compile=False, echo=echo)
    return target


def functions_of(directory: Path, manifest: Manifest) -> ModelFunctions:
    """The SX Functions of a verified artefact folder, named from its manifest (no sympy); the hybrid Functions
    are rebuilt from rhs and guards (the same SX as the station's, whose C is in the library)."""
    fns = read_serialized(Path(directory) / SERIALIZED)
    names = manifest.data["names"]
    guards = tuple(names["guards"])
    return with_hybrid(ModelFunctions(
        rhs=fns["rhs"], rhs_jac=fns["rhs"].jacobian(), rhs_switched=fns["rhs_switched"], guards=fns["guards"],
        outputs=fns["outputs"],
        mode_list=tuple(Mode(tuple(bool(c) for c in m["closed"]), guards) for m in manifest.modes),
        state_names=tuple(names["state"]), parameter_names=tuple(names["parameters"]),
        input_names=tuple(names["inputs"]), guard_names=guards, activation_names=tuple(names["activations"]),
        output_names=tuple(names["outputs"]),
        n_instructions={k: v["n_instructions"] for k, v in manifest.data["functions"].items()},
        model_hash=manifest.input_hash,
    ))


def check_library(library: Path, manifest: Manifest) -> None:
    """Refuse a model library whose compiled-in generation record is not the manifest's."""
    lib = ctypes.CDLL(str(library))
    fn = lib.apexseal_model_input_hash
    fn.restype = ctypes.c_char_p
    got = fn().decode()
    if got != manifest.input_hash:
        raise StaleArtefactError(library, [f"the library was built from the record {got[:12]}..., not from the "
                                           f"manifest's {manifest.input_hash[:12]}..."])


#: what :func:`load_functions` returned in this process, by its arguments, with the fingerprint it was current for
_LOADED: dict[tuple, tuple[tuple, LoadedFunctions]] = {}


def _fingerprint(loaded: LoadedFunctions, expected_hash: str) -> tuple | None:
    """What a loaded model was current for: the input hash of today's sources, and the stat of its manifest, of
    every file the manifest lists and of the compiled library (None when one of them is gone)."""
    folder = loaded.source_dir
    files = [folder / MANIFEST_NAME, *(folder / name for name in loaded.manifest.data["files"])]
    try:
        return (expected_hash, *(stat_key(p) for p in [*files, *([loaded.library] if loaded.library else [])]))
    except OSError:
        return None


def load_functions(effects: Effects | None = None, assumptions: Assumptions | None = None, *, compiled: bool = True,
                   flags: str = "optimised", echo=None) -> LoadedFunctions:
    """SX and compiled Functions of a model from its artefacts; derives, generates and compiles what is missing.

    Within a process the Functions of a model are loaded once: a later call (every point of a sweep, every run
    of a notebook) returns the same :class:`LoadedFunctions` while the sources give the same input hash and
    none of the model's files has changed its stat since they were checked against the manifest, with the same
    compiler command; otherwise it checks and loads again. A compiler fallback is not kept (a later call tries
    the compiler again)."""
    effects = effects or Effects()
    assumptions = assumptions or Assumptions()
    key = (content_key([effects.as_dict(), assumptions.as_dict()]), bool(compiled), flags, compiler(), str(DEFAULT_DIR))
    expected = input_hash(effects, assumptions)
    kept = _LOADED.get(key)
    if kept is not None and kept[0] == _fingerprint(kept[1], expected):
        return kept[1]
    loaded = _load(effects, assumptions, compiled=compiled, flags=flags, echo=echo)
    fingerprint = _fingerprint(loaded, expected) if loaded.manifest.input_hash == expected else None
    if fingerprint is not None and (loaded.compiled or not compiled):
        _LOADED[key] = (fingerprint, loaded)
    return loaded


def _load(effects: Effects, assumptions: Assumptions, *, compiled: bool, flags: str, echo) -> LoadedFunctions:
    source = artefact_dir(effects, assumptions, echo=echo)
    manifest = verify(source, trusted=True)
    sx = functions_of(source, manifest)
    if not compiled:
        return LoadedFunctions(sx, None, manifest, source, None)
    # the derivatives in the library are found by name from their Function's external
    externals, library = compiled_or_interpreted(source, list(sx.functions()), sx.functions(), flags=flags)
    if library is None:
        return LoadedFunctions(sx, sx, manifest, source, None)
    check_library(library, manifest)
    c = sx.with_functions(externals)
    c.symbolic, c.library = sx, library
    return LoadedFunctions(sx, c, manifest, source, library)
