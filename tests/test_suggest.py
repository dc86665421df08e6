"""One "did you mean" for every error about a name."""

from __future__ import annotations

import pytest

from apexseal.derive.assumptions import AssumptionError, Assumptions
from apexseal.derive.effects import EffectError, Effects
from apexseal.runtime.solving.methods import check_method
from apexseal.suggest import did_you_mean


def test_did_you_mean_suggests_the_closest_string_only():
    assert did_you_mean("cvode", ["erk", "cvodes", "idas"]) == " (did you mean 'cvodes'?)"
    assert did_you_mean("zzz", ["erk", "cvodes"]) == ""
    assert did_you_mean(3, ["3", "4"]) == ""
    assert did_you_mean("kww", ("kw", "cw"), cutoff=0.5) == " (did you mean 'kw'?)"


def test_did_you_mean_names_every_name_equally_close_in_their_order():
    """``drag.cd`` was said to mean only ``cd2``, though ``cd1`` is as close."""
    assert did_you_mean("cd", ["cd1", "cd2", "kw"]) == " (did you mean 'cd1' or 'cd2'?)"
    assert did_you_mean("kg", ["kw", "kg1", "kg2", "kg3", "kg4"]) == (
        " (did you mean 'kg1' or 'kg2' or 'kg3'?)")  # at most three


@pytest.mark.parametrize(("call", "error", "message"), [
    (lambda: check_method("cvode"), ValueError,
     "solver.method = 'cvode' is not a method (did you mean 'cvodes'?); allowed: erk"),
    (lambda: Effects.from_mapping({"inertial": True}), EffectError,
     "effects.inertial is not an effect (did you mean 'inertia'?); known: inertia"),
    (lambda: Assumptions(damping="alway"), AssumptionError,
     "assumptions.damping = 'alway' is not allowed (did you mean 'always'?); allowed: in-contact, always"),
    (lambda: Assumptions.from_mapping({"dampin": "always"}), AssumptionError,
     "assumptions.dampin is not a modelling choice (did you mean 'damping'?); known: "),
])
def test_every_name_error_words_its_hint_the_same_way(call, error, message):
    with pytest.raises(error) as info:
        call()
    assert message in str(info.value)
