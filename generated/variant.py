"""Model variants: a model's Functions built otherwise than its manifest says, compiled under a record of their own.

The manifest (:mod:`.manifest`) describes the model a run executes. A measurement also compiles variants that no
manifest describes: the model lowered with ``sympy.cse`` first (runtime/bench/levers.py), the model library without
the hybrid Functions, as it was before the erk integrator called it (runtime/bench/linking.py). Each one gets a
record at the station, ``<cache>/gen/variant/<hash>/variant.json``:

* ``of``: the input hash of the manifest whose model (its derivation, or its Functions) the variant was built from;
* ``how``: what was done otherwise, in words and options;
* ``functions``: the sha256 of the variant's SX Functions serialized (every one ``ModelFunctions.functions()``
  lists);
* ``hash``: the sha256 over those three, the variant's own hash;
* ``library_files`` once :func:`.compile.variant_library` wrote its C: file name -> sha256.

The hash stands where a model's input hash would: it is the variant's ``ModelFunctions.model_hash``, so the
``function.json`` of everything compiled from it names it (``model``) and carries the record's ``of`` and ``how``
(``variant``; :func:`.compile.function_source`), and the library of its own C is built under a key naming it.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path

from ..derive.cache import cache_dir
from ..files import atomic_write, content_key, read_json_object, sha256_bytes
from .codegen import serialized
from .functions import ModelFunctions

VARIANT_RECORD = "variant.json"
FORMAT = "apexseal-variant/1"
#: the file name of a variant's library (``{key}``: the start of its cache key)
VARIANT_LIBRARY = "libapexseal_variant_{key}.so"


def variant_dir(variant_hash: str) -> Path:
    """The station's folder of one variant: its record and the C of its library."""
    return cache_dir() / "gen" / "variant" / variant_hash


def variant_record(model_hash: str | None) -> dict | None:
    """The record of the variant whose hash is ``model_hash`` (None: no variant of that hash is on record, e.g. a
    manifest's input hash)."""
    if not model_hash:
        return None
    record = read_json_object(variant_dir(model_hash) / VARIANT_RECORD)
    return record if record is not None and record.get("hash") == model_hash else None


def record_variant(fns: ModelFunctions, *, of: str | None, how: Mapping) -> ModelFunctions:
    """``fns`` (SX Functions built from the model of the manifest whose input hash is ``of``, otherwise than it
    says: ``how``) with ``model_hash`` set to the variant's own hash, its record written at the station."""
    if not of:
        raise ValueError(f"of: {of!r}; a variant names the input hash of the manifest whose model it was built from")
    if not how:
        raise ValueError(f"how: {how!r}; a variant says what was done otherwise than its manifest says")
    body = {"of": of, "how": dict(how), "functions": sha256_bytes(serialized(fns.functions().values()).encode())}
    variant_hash = content_key(body)
    if variant_record(variant_hash) is None:
        folder = variant_dir(variant_hash)
        folder.mkdir(parents=True, exist_ok=True)
        atomic_write(folder / VARIANT_RECORD, json.dumps({"format": FORMAT, "hash": variant_hash, **body},
                                                         indent=2) + "\n")
    return replace(fns, model_hash=variant_hash)


def sympy_cse_variant(effects, assumptions) -> ModelFunctions:
    """The model of these inputs lowered with one ``sympy.cse`` over every expression first
    (:func:`.functions.build_functions` with ``sympy_cse``), on record as a variant of their manifest's model."""
    from ..derive.cache import cached_model
    from .functions import build_functions
    from .manifest import input_hash

    fns = build_functions(cached_model(effects, assumptions), sympy_cse=True)
    how = {"lowering": "sympy.cse over every expression, then the memoised tree walk and casadi.cse",
           "build_functions": {"sympy_cse": True}}
    return record_variant(fns, of=input_hash(effects, assumptions), how=how)
