"""Shared fixtures: the default scene and its model functions, built once per test session."""

from __future__ import annotations

import os
import signal
import tempfile

import pytest

# a private cache per test session, so tests never depend on what a user's cache holds
os.environ.setdefault("APEXSEAL_CACHE", os.path.join(tempfile.gettempdir(), "apexseal-test-cache"))

# The signal tests stop runs, in this process and in those it starts, as a terminal's Ctrl-C or a batch scheduler's
# SIGTERM would. A runner may start the suite with these signals ignored (a shell's background job ignores SIGINT),
# and a run leaves a signal ignored at its start ignored (src/apexseal/signals.py; its own test starts a process
# so): the suite runs with the handlers a process started from a terminal has.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)
if signal.getsignal(signal.SIGTERM) is signal.SIG_IGN:
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def pytest_configure(config):
    """The tests are of apexseal's own model: a submodel that a package installed beside it declares as an entry point
    (docs/extending.md) is left out of this process's registry before any test module is imported, as a user's cache
    is left out above (the tests of installed submodels install their own)."""
    from apexseal.derive.submodels import registry

    for name in registry.installed():
        registry.unregister(name)


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


@pytest.fixture(scope="session")
def soft_scene():
    """The embedded soft-contacts scene (kw = 6.2e7, kg = 1.05e6 N/m, the first default): the scene of the numerical
    tests written for it (convergence orders, method agreement) and of the preload study's numbers. Same effects
    as the default, so ``default_functions`` serve it; its runs warn (implausible penetrations)."""
    import apexseal
    from apexseal.runtime.scenes.scene import embedded_scene_path

    return apexseal.load_scene(embedded_scene_path("soft-contacts.toml"))


@pytest.fixture
def sigterm_redelivered():
    """A SIGTERM handler that records, for the test: a library call that caught a SIGTERM ends the process by
    delivering it again once what it computed is kept (apexseal.signals.StopSignals.redeliver_term), which would end
    the test process. Yields the list of SIGTERMs so delivered."""
    import signal

    seen: list[int] = []
    before = signal.signal(signal.SIGTERM, lambda signum, frame: seen.append(signum))
    try:
        yield seen
    finally:
        signal.signal(signal.SIGTERM, before)


@pytest.fixture
def signalled_in(monkeypatch):
    """``signalled_in(module, name)``: ``module.name`` sends this process a SIGTERM, then does what it did (a signal
    that lands exactly while that work runs)."""
    import signal

    def patch(module, name: str, signum: int = signal.SIGTERM) -> None:
        real = getattr(module, name)

        def signalled(*args, **kwargs):
            os.kill(os.getpid(), signum)  # noted by the command's handler, not acted on at once
            return real(*args, **kwargs)

        monkeypatch.setattr(module, name, signalled)

    return patch
