"""The model's Functions for a scene: SX (to embed in integrators) and compiled C, built when missing.

``load_functions(effects, assumptions)`` returns a :class:`LoadedFunctions` with

* ``.sx``: the SX Functions (:class:`~.functions.ModelFunctions`), from the cached derivation;
* ``.c``: the same Functions as ``casadi.external`` of the compiled library (or the SX ones,
  with a :class:`~.compile.CompilerFallbackWarning`, when no compiler works).

Where the C comes from: for the default effects and assumptions, the committed
artefacts in ``generated/default/`` if their manifest matches the current inputs
(else a :class:`~.manifest.StaleArtefactWarning` and they are regenerated into the
cache); otherwise ``cache_dir()/gen/<input hash>/``, generated on first use.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

from ..derive.assumptions import Assumptions
from ..derive.cache import cache_dir, cached_model, derivation_key
from ..derive.effects import Effects
from ..files import file_lock
from ..progress import stage
from .compile import compiled_or_interpreted
from .functions import ModelFunctions, build_functions
from .manifest import MANIFEST_NAME, Manifest, StaleArtefactError, StaleArtefactWarning, input_hash, read_manifest, verify

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
    return effects == Effects() and assumptions == Assumptions()


def _current(directory: Path, expected: str) -> bool:
    try:
        verify(directory, expected_hash=expected)
    except StaleArtefactError as exc:
        if (directory / MANIFEST_NAME).exists():
            warnings.warn(f"{exc}; regenerating", StaleArtefactWarning, stacklevel=4)
        return False
    return True


def artefact_dir(effects: Effects | None = None, assumptions: Assumptions | None = None) -> Path:
    """The folder holding current C artefacts for these inputs (generating them into the cache if needed)."""
    from .generate import generate

    effects = effects or Effects()
    assumptions = assumptions or Assumptions()
    expected = input_hash(effects, assumptions)
    if is_default(effects, assumptions):
        try:
            verify(DEFAULT_DIR, expected_hash=expected)
            return DEFAULT_DIR
        except StaleArtefactError as exc:
            warnings.warn(f"{exc}. Using regenerated artefacts from the cache instead; refresh the committed ones "
                          "with `apexseal generate --out generated/default`", StaleArtefactWarning, stacklevel=3)
    target = cache_dir() / "gen" / expected
    if target.is_dir() and _current(target, expected):
        return target
    with file_lock(cache_dir() / "gen" / f"{expected}.lock"):
        try:
            verify(target, expected_hash=expected)  # another process generated it while we waited
        except StaleArtefactError:
            with stage(f"generating C for effects {effects.label} (first use; cached afterwards)"):
                generate(effects, assumptions, target, compile=False, echo=None)
    return target


def _derived(effects: Effects, assumptions: Assumptions):
    """The derived model from the cache, with a progress report when it must be derived (tens of seconds)."""
    if (cache_dir() / "derive" / f"{derivation_key(effects, assumptions)}.pkl").exists():
        return cached_model(effects, assumptions)
    with stage(f"deriving the equations of motion (sympy; effects {effects.label}; first use, cached afterwards)"):
        return cached_model(effects, assumptions)


def load_functions(effects: Effects | None = None, assumptions: Assumptions | None = None, *, compiled: bool = True,
                   flags: str = "optimised") -> LoadedFunctions:
    """SX and compiled Functions of a model; generates and compiles what the cache lacks."""
    effects = effects or Effects()
    assumptions = assumptions or Assumptions()
    sx = build_functions(_derived(effects, assumptions))
    if not compiled:
        return LoadedFunctions(sx, None, None, None, None)
    source = artefact_dir(effects, assumptions)
    manifest = read_manifest(source)
    externals, library = compiled_or_interpreted(source, manifest.function_names, sx.functions(), flags=flags)
    return LoadedFunctions(sx, sx.with_functions(externals), manifest, source, library)
