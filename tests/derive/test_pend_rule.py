"""The modelling choice assumptions.pend_rule (derive/submodels/pressure.py, Eq. 75): the groove-bottom pressure
Pend under the seal's back face. 'open-side' gives it the pressure of the chamber whose side of the groove is open
from the mouth to the back corner, consistently with gap_pressure = 'open-side' (which gives an open side's gap its
chamber's pressure all the way down); the default 'mean' keeps (Pa + Pb)/2 whatever the gaps."""

from __future__ import annotations

import pytest
import sympy as sp

from apexseal.derive import contact_geometry, kinematics
from apexseal.derive.assumptions import Assumptions
from apexseal.derive.choices import options_of
from apexseal.derive.effects import Effects
from apexseal.derive.model import submodel_contacts
from apexseal.derive.submodels.pressure import groove_bottom_pressure
from apexseal.derive.submodels.registry import activation_symbols

PA, PB = 5e5, 1e5
#: which gaps are closed (1) on each side -> the chamber whose gas reaches the groove bottom
CASES = [
    ({"b1": 0, "b2": 0, "b3": 1, "b4": 1}, PB),  # chamber b's side open from mouth to back corner
    ({"b1": 1, "b2": 1, "b3": 0, "b4": 0}, PA),
    ({"b1": 0, "b2": 1, "b3": 0, "b4": 0}, PA),  # b's back corner closed: only a's gas gets through
    ({"b1": 0, "b2": 0, "b3": 0, "b4": 0}, (PA + PB) / 2),  # both open: the mean
    ({"b1": 1, "b2": 0, "b3": 0, "b4": 1}, (PA + PB) / 2),  # neither side open through: the mean
]


@pytest.mark.parametrize(("closed", "expected"), CASES)
def test_open_side_takes_the_chamber_whose_side_is_open_through(closed, expected):
    assert groove_bottom_pressure(PA, PB, "open-side", closed) == pytest.approx(expected)
    assert groove_bottom_pressure(PA, PB, "mean", closed) == pytest.approx((PA + PB) / 2)


def test_open_side_without_the_groove_contacts_is_the_mean():
    assert groove_bottom_pressure(PA, PB, "open-side") == pytest.approx((PA + PB) / 2)


@pytest.fixture(scope="module")
def kg():
    k = kinematics.build()
    return k, contact_geometry.build(k)


@pytest.mark.parametrize(("closed", "expected"), CASES[:2])
def test_the_back_face_load_of_the_model_carries_that_pressure(kg, closed, expected):
    """The back-face load Fs7 = Pend Ws Bs along Xs (Eq. 75) of the derived pressure submodel, in a mode."""
    k, g = kg
    opts = options_of(Effects(), Assumptions(pend_rule="open-side"))
    load = next(ld for ld in submodel_contacts("pressure", k, g, opts)[0].loads if ld.name == "s7")
    acts = activation_symbols()
    values = {acts[f"s_{b}"]: v for b, v in closed.items()}
    fx = sp.sympify(load.force.dot(k.S.x)).subs(values)
    numbers = {"Ws": 1.0, "Bs": 1.0, "Pa": PA, "Pb": PB}
    assert float(fx.subs({s: numbers[str(s)] for s in fx.free_symbols})) == pytest.approx(expected)
