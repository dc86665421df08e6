"""A scene whose chamber volume reaches <= 0 on the revolution is refused before the gas model runs (API, file, CLI)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from click.testing import CliRunner

import apexseal
from apexseal.cli import main
from apexseal.derive import chambers, numbers
from apexseal.derive.symbols import P, theta
from apexseal.runtime.scenes.errors import SceneError
from apexseal.runtime.scenes.scene import embedded_scene_path

GAS = {"pressure.source": "chamber+leakage", "pressure.file": None, "pressure.unit": None}
GEOM = {"r": 0.010, "L": 0.050, "H": 0.100, "Cr": 1e-4}


@pytest.mark.parametrize("embodiment", ["circolimacon", "limacon-to-circular"])
def test_the_bound_on_k_is_where_the_symbolic_volume_reaches_zero(embodiment):
    """Just above the k the check allows, the sympy volumes (derive.chambers) are positive all the revolution;
    just below it, one of them is negative somewhere."""
    k_min = numbers.smallest_lobe_offset(embodiment, **GEOM)
    assert 0 < k_min < GEOM["L"]
    grid = np.linspace(0, 2 * math.pi, 2001)
    for k, positive in ((k_min * (1 + 1e-6), True), (k_min * (1 - 1e-3), False)):
        subs = {P[n]: v for n, v in {**GEOM, "k": k}.items()}
        smallest = min(float(np.min(sp.lambdify(theta, V.subs(subs), "numpy")(grid)))
                       for V in chambers.chamber_volumes(embodiment, P, theta))
        assert (smallest > 0) is positive, (k, smallest)


def test_the_smallest_volume_of_the_limacon_lobe_is_its_clearance_volume():
    """H Cr (pi L - 4 r - pi Cr / 2) (docs/gas.md), at theta = pi for chamber a (0 for b)."""
    r, L, H, Cr = GEOM["r"], GEOM["L"], GEOM["H"], GEOM["Cr"]
    V, th, chamber = numbers.smallest_chamber_volume("limacon-to-limacon", r=r, L=L, H=H, Cr=Cr)
    assert V == pytest.approx(H * Cr * (math.pi * L - 4 * r - math.pi * Cr / 2), rel=1e-9)
    assert (chamber, th) in (("a", pytest.approx(math.pi)), ("b", 0.0))


def test_the_api_refuses_circular_lobes_that_reach_the_housing_and_accepts_a_fitting_one():
    scene = apexseal.load_scene().with_overrides(**GAS)
    with pytest.raises(SceneError) as info:
        scene.with_overrides(**{"machine.embodiment": "limacon-to-circular"})
    assert info.value.keys() == ["machine.k"]
    assert "allowed: k > 24.0617 mm" in str(info.value)
    fits = scene.with_overrides(**{"machine.embodiment": "limacon-to-circular", "machine.k": "25 mm"})
    assert fits.machine.k == pytest.approx(0.025)


def test_without_the_gas_model_the_volumes_are_not_checked():
    """The table, constant and no-pressure sources never use the chamber volumes: k = 0 stays allowed there."""
    scene = apexseal.load_scene().with_overrides(**{"machine.embodiment": "circolimacon"})
    assert scene.pressure.kind == "table" and scene.machine.k == 0


def test_the_cli_refuses_the_scene_file_and_writes_nothing(tmp_path):
    text = embedded_scene_path("expander-gas.toml").read_text(encoding="utf-8")
    bad = text.replace('embodiment = "limacon-to-limacon"', 'embodiment = "circolimacon"')
    assert bad != text
    path = tmp_path / "bad.toml"
    path.write_text(bad, encoding="utf-8")
    with pytest.raises(SceneError, match="machine.k = \"0 mm\": chamber b's volume reaches"):
        apexseal.load_scene(path)
    r = CliRunner().invoke(main, ["simulate", str(path), "--out", str(tmp_path / "o"), "-q"])
    assert r.exit_code != 0
    assert 'machine.k = "0 mm"' in r.output and "allowed: k > 19.7732 mm" in r.output
    assert not (tmp_path / "o").exists()
