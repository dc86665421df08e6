"""Shared fixtures of the code-generation tests: the default model, its compiled Functions, parameters, states.

The default model is compiled once per session with the "quick" flags (the library
lands in the apexseal cache, so later sessions reuse it).
"""

from __future__ import annotations

import numpy as np
import pytest
from gen_helpers import parameter_vector

from apexseal.derive import cached_model


@pytest.fixture(scope="session")
def model():
    return cached_model()


@pytest.fixture(scope="session")
def loaded():
    """SX and compiled ("quick") Functions of the default model, from generated/default."""
    from apexseal.generated.load import load_functions

    out = load_functions(flags="quick")
    assert out.compiled, "the default model should compile on the test machine"
    return out


@pytest.fixture(scope="session")
def params() -> np.ndarray:
    return parameter_vector()


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20180101)
