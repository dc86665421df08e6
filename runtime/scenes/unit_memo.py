"""Unit conversions remembered between runs, so that a warm scene load never imports pint.

Importing pint and loading its registry cost about half a second, several times a warm run's integration.
Reading a quantity (``"3.06 mm"`` as a length in m) is a pure function of the text, the expected unit and the
unit of bare numbers, so each conversion pint makes is kept in ``$APEXSEAL_CACHE/units/conversions-<key>.json``
and looked up before pint is asked. The key is the sha256 of units.py (the rules of reading) and pint's version:
a change to either starts a new file. Only successful conversions are kept; a value pint rejects is read by pint
again, so its message is always the current one. The file is read once per process and written (atomically,
merged with what other processes added) when the process ends; a file that cannot be read or written is
ignored and rebuilt, like the compile cache. The file holds its entries with their sha256 (``{"entries": ...,
"sha256": ...}``): a file whose entries do not match it (a value edited by hand, a file of another format) is
discarded whole, so a warm load never reads a conversion pint did not make.
"""

from __future__ import annotations

import atexit
import hashlib
import json
from pathlib import Path
from typing import Any

#: at most this many conversions are kept (a sweep over written quantities adds one per value)
LIMIT = 20000

_memo: dict[str, float] | None = None
_added: dict[str, float] = {}


def key_of(*parts: Any) -> str:
    """The memo key of a conversion: its inputs, with the type of the value (``3`` and ``"3"`` differ)."""
    return json.dumps([type(parts[0]).__name__, *parts])


def _path() -> Path:
    from apexseal.derive.cache import cache_dir
    from apexseal.versions import distribution_version

    h = hashlib.sha256(Path(__file__).with_name("units.py").read_bytes())
    h.update(distribution_version("pint").encode())
    return cache_dir() / "units" / f"conversions-{h.hexdigest()[:16]}.json"


def _read(path: Path) -> dict[str, float]:
    """The file's conversions, or none when its entries do not match their sha256 (see the module's docstring)."""
    from apexseal.files import content_key, read_json_object

    data = read_json_object(path) or {}
    entries = data.get("entries")
    if not isinstance(entries, dict) or data.get("sha256") != content_key(entries):
        return {}
    return {k: float(v) for k, v in entries.items() if isinstance(v, int | float)}


def _loaded() -> dict[str, float]:
    global _memo
    if _memo is None:
        try:
            _memo = _read(_path())
        except Exception:  # no cache folder, no pint metadata: remember nothing
            _memo = {}
    return _memo


def lookup(key: str) -> float | None:
    """The remembered result of a conversion, or None."""
    return _loaded().get(key)


def remember(key: str, value: float) -> None:
    """Keep a conversion; written to the cache when the process ends."""
    if not _added:
        atexit.register(flush)
    _loaded()[key] = value
    _added[key] = value


def flush() -> None:
    """Write the conversions added by this process (merged with the file as it is now)."""
    if not _added:
        return
    try:
        from apexseal.files import atomic_write, content_key

        path = _path()
        merged = _read(path)
        merged.update(_added)
        if len(merged) > LIMIT:  # keep the newest: this process's, then the file's latest entries
            merged = dict(list(merged.items())[-LIMIT:])
        path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write(path, json.dumps({"entries": merged, "sha256": content_key(merged)}).encode())
    except Exception:  # a cache that cannot be written only costs the next run pint's import
        pass
    _added.clear()
