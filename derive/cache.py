"""Content-hash cache of derivations.

The key is a sha256 over the derivation's inputs: the source of every module of
``apexseal.derive``, the source of every submodel that enters the model (a user's
too, while it is on), the effects, the assumptions and the sympy version. A hit
loads the pickled :class:`DerivedModel` (well under a second); a miss, or an entry
that is corrupt or not a DerivedModel, derives and stores it atomically
(:func:`apexseal.files.atomic_write`), so no process ever reads a half-written file; a
lock per key lets one process derive a model at a time, and the others wait for it and read it.
"""

from __future__ import annotations

import os
import pickle
from dataclasses import replace
from pathlib import Path

from ..files import atomic_open, content_key, file_lock, files_digest
from ..loaded_code import note, refuse_edited
from ..versions import distribution_version
from .assumptions import Assumptions
from .effects import Effects

_DERIVE_DIR = Path(__file__).resolve().parent


def cache_dir() -> Path:
    """Where derivations and compiled libraries are kept: $APEXSEAL_CACHE or the user cache folder."""
    env = os.environ.get("APEXSEAL_CACHE")
    if env:
        return Path(env)
    import platformdirs

    return Path(platformdirs.user_cache_dir("apexseal"))


def _source_names() -> list[str]:
    return [n for n in (p.relative_to(_DERIVE_DIR).as_posix() for p in sorted(_DERIVE_DIR.rglob("*.py")))
            if "paper" not in n]  # the printed forms and their check (paper.py, paper_check/) do not change it


def source_digest() -> str:
    """sha256 of the derivation's own source files (a change to any of them invalidates the cache)."""
    names = _source_names()
    note(_DERIVE_DIR / n for n in names)  # what this process imported of them (refuse_edited compares)
    return files_digest(_DERIVE_DIR, names)


def derivation_files(effects: Effects, assumptions: Assumptions) -> list[Path]:
    """The source files a model of these inputs is derived from: apexseal's derivation and every submodel that
    enters it, with its helpers (what :func:`derivation_key` hashes)."""
    from .choices import options_of
    from .submodels.registry import entering
    from .submodels.sources import files_of

    opts = options_of(effects, assumptions)
    return [*(_DERIVE_DIR / n for n in _source_names()), *(f for cls in entering(opts) for f in files_of(cls))]


def model_inputs(effects: Effects, assumptions: Assumptions) -> dict:
    """What of the registry and the options a model is derived from: the sources of the submodels that enter it
    and their options' values. A user's or a package's submodel that is off enters with neither
    (:func:`~.submodels.registry.entering`), so installing one changes no other model's key, its derivation or its
    generated artefacts."""
    from .choices import options_of
    from .submodels.registry import digest, left_out_options

    opts = options_of(effects, assumptions)
    out = left_out_options(opts)
    return {
        "submodels": digest(opts),
        "effects": {k: v for k, v in effects.as_dict().items() if k not in out},
        "assumptions": {k: v for k, v in assumptions.as_dict().items() if k not in out},
    }


def derivation_key(effects: Effects, assumptions: Assumptions) -> str:
    payload = {
        "source": source_digest(),
        **model_inputs(effects, assumptions),
        "sympy": distribution_version("sympy"),  # without importing sympy
    }
    return content_key(payload)


def cached_model(effects: Effects | None = None, assumptions: Assumptions | None = None, *, refresh: bool = False):
    """The derived model for these inputs, from the cache when it is there (see :func:`model.derive_model`)."""
    from .model import derive_model

    effects = effects or Effects()
    assumptions = assumptions or Assumptions()
    path = cache_dir() / "derive" / f"{derivation_key(effects, assumptions)}.pkl"
    if not refresh and (model := _cached(path, effects, assumptions)) is not None:
        return model
    # one process derives a model at a time: another that misses it meanwhile (a parallel test process, a sweep's
    # workers) waits, saying so, and reads what the first stored, instead of deriving it again beside it
    with file_lock(path.with_suffix(".lock"), f"the derivation {path.stem[:12]}"):
        if not refresh and (model := _cached(path, effects, assumptions)) is not None:
            return model
        refuse_edited(derivation_files(effects, assumptions), "derive the model")  # never an old model, new key
        model = derive_model(effects, assumptions)
        with atomic_open(path, "wb") as fh:
            pickle.dump(model, fh, protocol=pickle.HIGHEST_PROTOCOL)
    return model


def _cached(path: Path, effects: Effects, assumptions: Assumptions):
    """The DerivedModel stored at ``path`` for these inputs, or None where there is none that loads."""
    from .model import DerivedModel

    if not path.exists():
        return None
    try:
        with path.open("rb") as fh:
            model = pickle.load(fh)
    except Exception:  # a corrupt or foreign file: derive again and overwrite it
        return None
    if not isinstance(model, DerivedModel):  # a valid pickle of something else is treated the same way
        return None
    return replace(model, effects=effects, assumptions=assumptions)  # the same inputs, perhaps with a user's
    # submodel off in one of them and absent in the other
