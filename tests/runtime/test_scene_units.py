"""Quantities with units in scene files (runtime/scenes/units.py)."""

import math

import pytest

from apexseal.runtime.scenes.units import QuantityError, Range, parse_pressure_unit, parse_quantity


@pytest.mark.parametrize(
    "value, unit, bare, expected",
    [
        ("3 mm", "m", None, 0.003),
        ("3mm", "m", None, 0.003),
        (0.003, "m", None, 0.003),
        (3, "m", None, 3.0),
        ("0.1", "1", None, 0.1),  # a quoted plain number where no unit is needed
        ("3.06 mm", "m", None, 0.00306),  # rounded to 15 digits: exactly the decimal
        ("1500 rpm", "rpm", "rpm", 1500.0),
        (1500, "rpm", "rpm", 1500.0),  # operation.rpm: bare numbers are rev/min
        ("25 rev/s", "rpm", "rpm", 1500.0),
        ("157.079632679490 rad/s", "rpm", "rpm", 1500.0),
        ("1500 rpm", "rad/s", None, 157.079632679490),
        ("6 bar", "Pa", None, 6.0e5),
        ("101.3 kPa", "Pa", None, 1.013e5),
        ("30 deg", "rad", None, math.pi / 6),
        ("-25 deg", "rad", None, math.radians(-25)),
        ("0.5 rad", "rad", None, 0.5),
        ("5e3 N/m", "N/m", None, 5000.0),
        ("5 kN/m", "N/m", None, 5000.0),
        ("207 N*s/m", "N*s/m", None, 207.0),
        ("207 N s/m", "N*s/m", None, 207.0),
        ("7200 kg/m^3", "kg/m^3", None, 7200.0),
        ("17.3 g", "kg", None, 0.0173),
        ("1.05e-7 kg*m^2", "kg*m^2", None, 1.05e-7),
        ("1 mm/s", "m/s", None, 1e-3),
        ("10 %", "1", None, 0.1),
        (0.12, "1", None, 0.12),
    ],
)
def test_parses(value, unit, bare, expected):
    assert parse_quantity(value, unit, bare=bare) == pytest.approx(expected, rel=1e-14)


def test_rounding_makes_unit_spellings_equal():
    assert parse_quantity("3.06 mm", "m") == 0.00306
    assert parse_quantity("99.9 mm", "m") == 0.0999


@pytest.mark.parametrize(
    "value, unit, fragments",
    [
        ("3 mm", "N/m", ["wrong unit", "stiffness in N/m", "mm"]),
        ("6 bar", "m", ["wrong unit", "length in m"]),
        ("10 %", "m", ["wrong unit", "length in m"]),
        (30, "rad", ["give a unit: deg or rad"]),
        ("30", "rad", ["give a unit: deg or rad"]),
        ("10 %", "rad", ["give a unit: deg or rad"]),
        (0, "rad/s", ["give a unit: deg or rad"]),
        ("1 m", "rad", ["wrong unit", "angle in rad"]),
        ("25 Hz", "rpm", ["ambiguous", "rpm", "not Hz"]),
        ("25 1/s", "rad/s", ["ambiguous", "rad/s"]),
        ("3 mmm", "m", ["unknown unit 'mmm'", "length in m"]),
        ("3 (mm", "m", ["cannot read", "length in m"]),
        ("3 mm 4", "m", ["one number, then its unit", "'mm 4'", "length in m"]),  # pint alone reads 12 mm
        ("6 mm / 2", "m", ["one number, then its unit", "length in m"]),  # pint alone reads 3 mm
        ("inf mm", "m", ["must be finite", "length in m"]),
        ("abc", "1", ["is not a number", "plain number"]),
        ("mm", "m", ["needs a number first", "length in m"]),
        ("3,5 mm", "m", ["decimal point", "length in m"]),
        (True, "m", ["got bool", "length in m"]),
        ([3], "m", ["got list", "length in m"]),
        (float("nan"), "m", ["finite", "length in m"]),
        (float("inf"), "N/m", ["finite", "stiffness in N/m"]),
    ],
)
def test_refuses(value, unit, fragments):
    with pytest.raises(QuantityError) as info:
        parse_quantity(value, unit, key="seal.Ws")
    text = str(info.value)
    assert text.startswith(f"seal.Ws = {value!r}: ")
    for fragment in fragments:
        assert fragment in text


def test_wrong_dimension_names_key_value_and_expected_unit():
    with pytest.raises(QuantityError) as info:
        parse_quantity("3 mm", "N/m", key="spring.ks")
    err = info.value
    assert (err.key, err.value) == ("spring.ks", "3 mm")
    assert "N/m" in err.reason and "spring.ks" in str(err) and "'3 mm'" in str(err)


@pytest.mark.parametrize("unit, factor", [("Pa", 1.0), ("kPa", 1e3), ("bar", 1e5), ("MPa", 1e6)])
def test_pressure_units(unit, factor):
    assert parse_pressure_unit(unit) == factor


@pytest.mark.parametrize("unit", ["m", "xyz", 3, ""])
def test_pressure_unit_refused(unit):
    with pytest.raises(QuantityError, match="pressure unit"):
        parse_pressure_unit(unit)


def test_range_description_and_check():
    r = Range(ge=0, lt=1)
    assert r.describe() == "0 <= value < 1"
    assert r.holds(0) and r.holds(0.99) and not r.holds(1) and not r.holds(-1e-12)
    assert Range(gt=0).describe("m") == "> 0 m"
    assert not Range(gt=0).holds(0)
    assert Range(ge=36, le=100000).describe(name="n") == "36 <= n <= 100000"
    assert Range(le=3).describe("m") == "<= 3 m"
    assert Range().describe() == "any finite value"
