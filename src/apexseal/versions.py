"""Versions of installed distributions, read once per process.

``importlib.metadata.version`` parses the distribution's metadata file on every call (about 1 ms); a run asks for
sympy's version several times (the derivation key, the generation record, the result's provenance), and a sweep
or a notebook once per simulation. What is installed does not change under a running process that has imported it.
"""

from __future__ import annotations

from functools import cache


@cache
def distribution_version(name: str) -> str:
    """The installed version of the distribution ``name`` (without importing it: sympy's import takes a second)."""
    from importlib.metadata import version

    return version(name)
