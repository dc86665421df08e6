"""A cold derivation says what it is doing: the chamber gas model's took some 30 s with no line between its start
and its end (derive/model.py)."""

from __future__ import annotations

import logging

import sympy as sp

from apexseal.derive.effects import Effects
from apexseal.derive.model import derive_model
from apexseal.derive.options import NONE, ON, Option
from apexseal.derive.submodels import registry
from apexseal.derive.submodels.base import Context, State, Submodel


class Lag(Submodel):
    """A cheap submodel with its own states, as the chamber gas has: a first-order lag of the seal's x and y."""

    name = "lag"
    summary = "a first-order lag of the seal's x and y (a test's own states)"
    switch = "lag"
    options = (Option("lag", (NONE, ON), "the lagged x and y"),)
    states = (State("x_lag", "m", "x lagged", 1e-6), State("y_lag", "m", "y lagged", 1e-6))
    output_columns = (("lag_gap", "m", "the distance of the lagged point from the seal's centre"),)

    def rates(self, ctx: Context) -> dict:
        return {"x_lag": ctx.X["x"] - ctx.X["x_lag"], "y_lag": ctx.X["y"] - ctx.X["y_lag"]}

    def outputs(self, ctx: Context) -> dict:
        return {"lag_gap": sp.sqrt((ctx.X["x"] - ctx.X["x_lag"]) ** 2 + (ctx.X["y"] - ctx.X["y_lag"]) ** 2)}

    @classmethod
    def initial_state(cls, values, theta: float) -> dict:
        return {"x_lag": 0.0, "y_lag": 0.0}


def _lines(caplog) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.name == "apexseal"]


def test_a_derivation_with_own_states_reports_each_step_and_each_rate(caplog):
    """The derivation of a model with a submodel's own states (the gas model's case, here a cheap lag) logged
    nothing: now its long steps are stages (start, done) and each of the submodel's rates and outputs has a line
    before it is brought to plain symbols, in order."""
    caplog.set_level(logging.INFO, logger="apexseal")
    with registry.registered(Lag):
        model = derive_model(Effects.only("inertia", "lag"))
    assert model.state_names[-2:] == ("x_lag", "y_lag")
    lines = _lines(caplog)
    expected = ["derivation: kinematics and contact geometry (Eqs. 10-47) ...",
                "derivation: the contacts' laws and the equations of motion (Eqs. 33-80) ...",
                "derivation: the submodels' own states (x_lag, y_lag): rates, pressures, outputs ...",
                "derivation: lag: rate of x_lag (1/2)", "derivation: lag: rate of y_lag (2/2)",
                "derivation: lag: output lag_gap (1/1)"]
    at = [lines.index(e) for e in expected]  # each there (ValueError otherwise), and in this order
    assert at == sorted(at), lines
    for stage in (expected[0], expected[1], expected[2]):
        done = stage.removesuffix(" ...") + ": done in "
        assert any(ln.startswith(done) for ln in lines), (done, lines)


def test_a_model_without_own_states_has_no_line_per_expression(caplog):
    """Only a submodel with its own states (costly expressions) reports each one: the seal's outputs say nothing."""
    caplog.set_level(logging.INFO, logger="apexseal")
    derive_model(Effects.only("inertia"))
    lines = _lines(caplog)
    assert lines and not [ln for ln in lines if "own states" in ln or ": rate of " in ln or ": output " in ln], lines
