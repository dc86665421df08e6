"""The chamber gas model in the hybrid system: closed chambers, the symmetric machine, leakage."""

from __future__ import annotations

import numpy as np
import pytest

import apexseal
from apexseal.runtime.api import model_functions

CHAMBER = {"pressure.source": "chamber", "pressure.file": None, "pressure.unit": None,
           "solver.samples_per_revolution": 360}


def _scene(**more):
    return apexseal.load_scene().with_overrides(**{**CHAMBER, **more})


@pytest.fixture(scope="module")
def closed():
    """One revolution with the ports closed and no leakage: two closed chambers (compressed 340-fold to some
    350 bar, so their pressure is kept off the seal)."""
    return apexseal.simulate(_scene(**{"gas.Cd_port": 0.0, "effects.chamber_pressure": False}), revolutions=1)


def test_closed_chambers_keep_their_mass(closed):
    assert closed.ok
    for m in ("ma", "mb"):
        mass = closed.column(m)
        assert np.max(np.abs(mass - mass[0])) <= 1e-9 * mass[0]


def test_closed_chambers_are_isentropic(closed):
    """p V^gamma = const through compression and expansion (gamma 1.4; the volume changes 340-fold)."""
    for c in "ab":
        p, V = closed.outputs["P" + c], closed.outputs["V" + c]
        assert V.max() / V.min() > 100
        pv = p * V**1.4
        assert np.max(np.abs(pv / pv[0] - 1)) < 1e-5


@pytest.mark.slow
def test_chambers_are_pi_out_of_phase_for_the_symmetric_machine():
    """Slow (two revolutions of the chamber gas model: 27 s in a suite run on a loaded machine, --durations): the
    default suite keeps its ten-minute budget on two cores; the gas model's runs there check its mass, energy and
    leakage."""
    r = apexseal.simulate(_scene(), revolutions=2)
    assert r.ok
    n = 360
    second = slice(n, 2 * n + 1)
    Pa, Pb = r.outputs["Pa"][second], r.outputs["Pb"][second]
    half = n // 2
    assert np.max(np.abs(Pa[half:] - Pb[: n + 1 - half])) < 1e-3 * Pa.max()
    assert Pa.max() > 5e5 and Pa.min() < 1.1e5  # filled from the supply and emptied to the exhaust


def test_leakage_is_zero_while_every_seal_contact_is_closed():
    s = apexseal.load_scene().with_overrides(**{**CHAMBER, "pressure.source": "chamber+leakage"})
    f = model_functions(s, compiled=False)  # evaluated at a few states: no compile needed
    p = s.parameter_vector(f.parameter_names)
    i_x = {n: i for i, n in enumerate(f.state_names)}
    x = np.zeros(len(f.state_names))
    V = 2e-4
    x[i_x["ma"]], x[i_x["Ua"]] = 6e5 * V / (287 * 300), 6e5 * V / 0.4  # unequal chambers
    x[i_x["mb"]], x[i_x["Ub"]] = 1e5 * V / (287 * 300), 1e5 * V / 0.4
    names = list(f.output_names)
    x_lift = x.copy()
    x_lift[i_x["x"]] = -20e-6  # the seal 20 um down its groove: the tip off the housing
    x_lift[i_x["y"]] = 1e-6
    for theta in (0.3, 2.0, 4.0):
        closed = np.array(f.outputs(theta, x, np.ones(len(f.guard_names)), p, [0, 0])).ravel()
        assert closed[names.index("mdot_leak_groove")] == 0.0
        assert closed[names.index("mdot_leak_tip")] == 0.0
        g = np.array(f.guards(theta, x_lift, p, [0, 0])).ravel()
        opened = np.array(f.outputs(theta, x_lift, (g < 0).astype(float), p, [0, 0])).ravel()
        drop = np.sign(opened[names.index("Pa")] - opened[names.index("Pb")])
        assert drop != 0
        assert drop * opened[names.index("mdot_leak_tip")] > 0  # from the higher pressure over the lifted tip
        assert drop * opened[names.index("mdot_leak_groove")] > 0


@pytest.mark.slow
def test_coupled_model_with_leakage_off_equals_the_uncoupled_one():
    a = apexseal.simulate(_scene(), revolutions=1)
    b = apexseal.simulate(_scene(**{"pressure.source": "chamber+leakage", "gas.Cd_leak": 0.0}), revolutions=1)
    assert a.ok and b.ok
    np.testing.assert_allclose(b.state, a.state, rtol=1e-9, atol=1e-15)
    assert np.all(b.outputs["mdot_leak_groove"] == 0) and np.all(b.outputs["mdot_leak_tip"] == 0)


def test_the_scene_that_ran_keeps_the_gas_model(tmp_path):
    """A result's scene.toml (the resolved scene) keeps pressure.source and the [gas] keys: reloading it gives
    the same scene, so a gas result re-runs."""
    from apexseal.runtime.scenes.resolved import resolved_toml
    from apexseal.runtime.scenes.scene import load_scene

    scene = apexseal.load_scene().with_overrides(**{**CHAMBER, "pressure.source": "chamber+leakage", "gas.Cd_leak": 0.5})
    text, files = resolved_toml(scene)
    (tmp_path / "scene.toml").write_text(text)
    for name, content in files.items():
        (tmp_path / name).write_text(content)
    again = load_scene(tmp_path / "scene.toml")
    assert again.pressure.to_dict() == {"source": "chamber+leakage"}
    assert again.content_hash() == scene.content_hash()
    assert np.array_equal(again.parameter_vector(), scene.parameter_vector())


def test_gas_columns_have_units_and_the_gas_figures_draw(closed, tmp_path):
    """The gas states and outputs are in the one table of outputs (CSV header, pandas units) and a gas run
    writes the Fig. 11 pressures and the p-V diagram besides the paper's four figures."""
    from apexseal.runtime.results.figure_job import write_figures

    df = closed.to_pandas()
    assert {"ma", "Ub", "Va", "mdot_leak_tip"} <= set(df.columns)
    assert df.attrs["units"]["ma"] == "kg" and df.attrs["units"]["mdot_in_a"] == "kg/s"
    names = {p.name for p in write_figures(closed, tmp_path)}
    assert {"fig11_pressures.png", "pv_diagram.png", "fig12_displacements.png"} <= names
    assert all((tmp_path / n).stat().st_size > 0 for n in names)


def test_the_figure_view_of_a_gas_run_draws_the_same_figures(closed, tmp_path):
    """A figure process is handed figure_view(result) and the scene's ports (the view has no scene): fewer
    outputs, the same six PNG files, byte for byte."""
    from apexseal.runtime.results.figure_job import write_figures
    from apexseal.runtime.results.figures import ports_of
    from apexseal.runtime.results.saved_figures import figure_outputs, figure_view

    view = figure_view(closed)
    assert {"Va", "Vb", "Pa", "Pb", "F_housing_X"} <= set(figure_outputs(closed)) == set(view.outputs)
    assert len(view.outputs) < len(closed.outputs) and view.scene is None
    ports = ports_of(closed.scene)
    full, light = write_figures(closed, tmp_path / "full", ports), write_figures(view, tmp_path / "view", ports)
    assert [p.name for p in full] == [p.name for p in light] and len(full) == 6
    for a, b in zip(full, light, strict=True):
        assert a.read_bytes() == b.read_bytes(), a.name


@pytest.mark.slow
def test_the_gas_figures_laid_out_from_the_memo_are_the_same(closed, tmp_path, monkeypatch):
    """Fig. 11 and the p-V diagram (and the four others of a gas run) saved with a kept layout: the bytes
    matplotlib's constrained layout gives (runtime/results/layout_memo.py)."""
    from test_layout_memo import kept_layouts_draw_the_same

    from apexseal.runtime.results.figures import ports_of

    monkeypatch.setenv("APEXSEAL_CACHE", str(tmp_path))
    monkeypatch.delenv("APEXSEAL_LAYOUT_MEMO", raising=False)
    kept_layouts_draw_the_same(closed, ports_of(closed.scene))


def test_the_gas_sources_are_the_gas_models_pressure_models():
    """Each pressure.source that integrates the gas model names the gas model's pressure_model choice it sets (the
    scene's checks pass the name through), and every other source sets "input"."""
    from apexseal.derive.submodels.gas import ChamberGas
    from apexseal.runtime.scenes.schema import GAS_SOURCES, PRESSURE_SOURCES

    (option,) = [o for o in ChamberGas.options if o.name == "pressure_model"]
    assert set(option.choices) == {"input", *GAS_SOURCES} and set(GAS_SOURCES) < set(PRESSURE_SOURCES)


def test_the_console_prints_the_gas_cycle(closed, capsys):
    """`apexseal simulate` and `show` printed no number of the gas model: its masses, work and pressures were only in
    summary.json."""
    from apexseal.cli_common import describe_result
    from apexseal.runtime.results.summary import summarise

    summary = summarise(closed)
    describe_result(closed, summary)
    line = next(ln for ln in capsys.readouterr().out.splitlines() if "chamber gas" in ln)
    gas = summary["gas"]
    assert f"inducted {gas['inducted_mass_kg'] * 1e3:.4g} g" in line and "indicated work" in line
    assert f"..{max(gas['pressure_Pa'][c]['max'] for c in 'ab') / 1e5:.3g} bar" in line


def test_sweeps_and_compare_collect_the_gas_quantities(closed, default_functions):
    """The gas model's masses, work and pressures are quantities of a sweep and rows of `compare` (they were only in
    summary.json); NaN for a run without the gas model."""
    import math

    from apexseal.runtime.results.quantities import collect
    from apexseal.runtime.results.summary import summarise

    gas = summarise(closed)["gas"]
    q = collect(closed, ("gas.inducted", "gas.work", "gas.pressure.max"))
    assert q["gas.inducted"] == gas["inducted_mass_kg"] * 1e3 and q["gas.work"] == gas["indicated_work_J"]["total"]
    assert q["gas.pressure.max"] == max(gas["pressure_Pa"][c]["max"] for c in "ab") > 1e7  # compressed 340-fold
    plain = apexseal.simulate(apexseal.load_scene(), revolutions=1, samples_per_revolution=72,
                              functions=default_functions.sx)
    assert math.isnan(collect(plain, ("gas.work",))["gas.work"])
