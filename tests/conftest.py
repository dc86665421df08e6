"""Shared fixtures: the default scene and its model functions, built once per test session."""

from __future__ import annotations

import os
import tempfile

import pytest

# a private cache per test session, so tests never depend on what a user's cache holds
os.environ.setdefault("APEXSEAL_CACHE", os.path.join(tempfile.gettempdir(), "apexseal-test-cache"))


@pytest.fixture(scope="session")
def default_scene():
    import apexseal

    return apexseal.load_scene()


@pytest.fixture(scope="session")
def default_functions(default_scene):
    from apexseal.generated.load import load_functions

    return load_functions(default_scene.effects, default_scene.assumptions, flags="quick")


@pytest.fixture
def artefacts(tmp_path):
    """A private, verified copy of the committed generated/default artefacts, to corrupt at will."""
    import shutil

    from apexseal.generated.load import DEFAULT_DIR
    from apexseal.generated.manifest import verify

    dst = tmp_path / "default"
    shutil.copytree(DEFAULT_DIR, dst)
    verify(dst)
    return dst
