"""The manifest of a folder of generated artefacts: what went in, what came out.

``manifest.json`` records the inputs of the generation (digest of the derivation's
source and of the generator's own modules, effects, assumptions, the templates,
the CasADi and sympy versions), their sha256 (``input_hash``, the cache key), the
sha256 of every file written, the modes, each Function's instruction count and the
names of the state, parameters, guards and outputs. It holds no time stamps and no
paths, so regenerating from the same inputs gives the same bytes.

Trust: a loader never trusts the manifest beside the files alone (an edit of a C file and of its hash in
that manifest would pass). :func:`trust` records the manifest's own sha256 in the station's index when
the station writes it: ``index.json`` of the package's ``generated/`` folder for the committed artefacts,
``<cache>/gen/index/`` (by folder) for any other folder; :func:`verify` with ``trusted=True`` refuses a
manifest whose sha256 is not the recorded one.

Compiler flags are not an input of the generated files (the C is the same for every
flag set); they enter the key of the compiled library instead (see ``compile.py``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import casadi

from ..derive.assumptions import Assumptions
from ..derive.cache import cache_dir, model_inputs, source_digest
from ..derive.effects import Effects
from ..files import content_key, files_digest, sha256_bytes, sha256_file
from ..loaded_code import note
from ..versions import distribution_version

FORMAT = "apexseal-generated/1"
MANIFEST_NAME = "manifest.json"
TEMPLATE_DIR = Path(__file__).resolve().parent / "templates"
_HERE = Path(__file__).resolve().parent
#: the generator modules whose code shapes the generated files
#: (hybrid, layout, scaling: the hybrid DAE, whose Functions hybrid_ode and hybrid_zero the model library holds)
GENERATOR_MODULES = ("lower.py", "functions.py", "codegen.py", "render.py", "manifest.py", "generate.py", "hybrid.py",
                     "layout.py", "scaling.py")
#: the station's index of the committed artefacts (folder name -> sha256 of its manifest)
PACKAGE_INDEX = _HERE / "index.json"


class StaleArtefactError(RuntimeError):
    """Generated artefacts that do not match their manifest or the current inputs."""

    def __init__(self, directory: Path | str, problems: list[str]):
        self.directory = str(directory)
        self.problems = problems
        super().__init__(f"stale or modified generated artefacts in {directory}: " + "; ".join(problems))


class StaleArtefactWarning(UserWarning):
    """Artefacts were stale or modified and are being rebuilt."""


def template_paths() -> list[Path]:
    return sorted(p for p in TEMPLATE_DIR.iterdir() if ".in." in p.name)


def generator_files() -> list[Path]:
    """The modules whose code shapes the generated files (what :func:`generator_digest` hashes)."""
    return [_HERE / m for m in GENERATOR_MODULES]


def generator_digest() -> str:
    note(generator_files())  # what this process imported of them (loaded_code: generate compares)
    return content_key([files_digest(_HERE, GENERATOR_MODULES)])


def inputs_record(effects: Effects, assumptions: Assumptions) -> dict[str, Any]:
    """Everything the generated files depend on (cheap: no derivation)."""
    return {
        "derive_source": source_digest(),
        **model_inputs(effects, assumptions),  # submodels, effects, assumptions
        "generator_source": generator_digest(),
        "templates": {p.name: sha256_file(p) for p in template_paths()},
        "casadi": casadi.__version__,
        "sympy": distribution_version("sympy"),  # the distribution's version: reading it does not import sympy
    }


def hash_of(record: dict[str, Any]) -> str:
    return content_key(record)


def input_hash(effects: Effects, assumptions: Assumptions) -> str:
    """The sha256 that names the artefacts of these effects and assumptions under the current sources."""
    return hash_of(inputs_record(effects, assumptions))


@dataclass
class Manifest:
    """The parsed ``manifest.json`` plus, after :func:`generate`, the stage timings and the library."""

    data: dict[str, Any]
    directory: Path | None = None
    #: stage -> seconds (derive, lower, codegen, render, compile); not written to the file
    timings: dict[str, float] = field(default_factory=dict)
    library: Path | None = None

    @property
    def input_hash(self) -> str:
        return self.data["input_hash"]

    @property
    def files(self) -> dict[str, str]:
        return self.data["files"]

    @property
    def c_files(self) -> list[str]:
        return [name for name in self.files if name.endswith(".c")]

    @property
    def modes(self) -> list[dict[str, Any]]:
        return self.data["modes"]

    @property
    def effects(self) -> Effects:
        return Effects(**self.data["inputs"]["effects"])

    @property
    def assumptions(self) -> Assumptions:
        return Assumptions(**self.data["inputs"]["assumptions"])

    def dumps(self) -> str:
        return json.dumps(self.data, indent=2) + "\n"


def read_manifest(directory: Path) -> Manifest:
    path = Path(directory) / MANIFEST_NAME
    return Manifest(json.loads(path.read_text()), Path(directory))


def _index_entry(directory: Path) -> tuple[Path, str]:
    """Where the trusted sha256 of this folder's manifest is recorded, and under which key."""
    directory = Path(directory).resolve()
    if directory.parent == _HERE:
        return PACKAGE_INDEX, directory.name
    key = directory.as_posix()
    return cache_dir() / "gen" / "index" / f"{sha256_bytes(key.encode())[:32]}.json", key


def trust(directory: Path) -> None:
    """Record the sha256 of ``directory``'s manifest in the station's index (called by the station only)."""
    from ..files import atomic_write

    path, key = _index_entry(directory)
    try:
        index = json.loads(path.read_text())
    except (OSError, ValueError):
        index = {}
    index[key] = sha256_file(Path(directory) / MANIFEST_NAME)
    atomic_write(path, json.dumps(dict(sorted(index.items())), indent=2) + "\n")


def trusted_digest(directory: Path) -> str | None:
    path, key = _index_entry(directory)
    try:
        return json.loads(path.read_text()).get(key)
    except (OSError, ValueError, AttributeError):
        return None


def verify(directory: Path, *, expected_hash: str | None = None, trusted: bool = False) -> Manifest:
    """Check a folder of artefacts against its manifest and the current inputs; raise :class:`StaleArtefactError`.

    Detects: a missing or unreadable manifest, a manifest whose recorded hash does not
    match its own inputs record, inputs that changed since generation (derivation or
    generator source, templates, versions), other effects/assumptions than expected,
    and files whose sha256 differs from the manifest; with ``trusted=True`` also a manifest
    whose own sha256 is not the one the station recorded (:func:`trust`).
    """
    directory = Path(directory)
    try:
        manifest = read_manifest(directory)
        data = manifest.data
        if data.get("format") != FORMAT:
            raise StaleArtefactError(directory, [f"format {data.get('format')!r} is not {FORMAT!r}"])
        recorded = data["inputs"]
        effects, assumptions = manifest.effects, manifest.assumptions
    except StaleArtefactError:
        raise
    except Exception as exc:  # missing, not JSON, missing keys, unknown effect names
        raise StaleArtefactError(directory, [f"unreadable {MANIFEST_NAME} ({type(exc).__name__}: {exc})"]) from exc
    problems = []
    if trusted and trusted_digest(directory) != sha256_file(directory / MANIFEST_NAME):
        problems.append(f"{MANIFEST_NAME} is not the one the generator recorded in its index (edited manifest)")
    if hash_of(recorded) != data["input_hash"]:
        problems.append("the manifest's input_hash does not match its own inputs record (edited manifest)")
    current = inputs_record(effects, assumptions)
    if hash_of(current) != data["input_hash"]:
        changed = sorted(k for k in current if current[k] != recorded.get(k))
        problems.append(f"inputs changed since generation: {', '.join(changed) or 'hash'}")
    if expected_hash is not None and hash_of(current) != expected_hash:  # sources alike: the options differ
        problems.append("generated for other effects/assumptions than requested")
    for name, digest in data["files"].items():
        path = directory / name
        if not path.is_file():
            problems.append(f"{name} is missing")
        elif sha256_file(path) != digest:
            problems.append(f"{name} differs from the manifest (sha256)")
    if problems:
        raise StaleArtefactError(directory, problems)
    return manifest
