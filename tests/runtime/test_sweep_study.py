"""Study files of sweeps: what a good one gives (points, units, designs) and how a bad one is refused."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from sweep_helpers import LIGHT, light_study

from apexseal.runtime.studies.sweep import StudyError, study_from_toml
from apexseal.runtime.studies.sweep.design import design_points
from apexseal.runtime.studies.sweep.execute import scenes_of


def test_grid_points_are_si_values_in_order():
    st = light_study()
    pts = design_points(st)
    assert len(pts) == 16
    ks = sorted({p["spring.ks"] for p in pts})
    assert ks[0] == 3000.0 and ks[-1] == 20000.0
    assert np.allclose(np.diff(np.log(ks)), np.log(20 / 3) / 3)  # log spacing
    assert sorted({p["spring.delta_s"] for p in pts}) == [0.001, 0.002, 0.003, 0.004]  # mm -> m
    assert pts[0] == {"spring.ks": 3000.0, "spring.delta_s": 0.001}
    assert pts[1]["spring.delta_s"] == 0.002  # the last parameter varies fastest
    assert st.units()["spring.ks"] == "N/m" and st.units()["friction_power.total"] == "W"


@pytest.mark.parametrize("kind", ["sobol", "halton", "lhs", "random"])
def test_sampled_designs_stay_in_the_box_and_repeat_with_the_seed(kind):
    st = light_study(**{"[collect]": f'[design]\nkind = "{kind}"\npoints = 32\nseed = 7\n\n[collect]',
                        'values = ["1 mm", "2 mm", "3 mm", "4 mm"]': 'from = "1 mm"\nto = "4 mm"\npoints = 2'})
    a, b = design_points(st), design_points(st)
    assert a == b and len(a) == 32
    ks = np.array([p["spring.ks"] for p in a])
    ds = np.array([p["spring.delta_s"] for p in a])
    assert ks.min() >= 3000 and ks.max() <= 20000 and ds.min() >= 0.001 and ds.max() <= 0.004
    assert len(set(ks)) == 32  # continuous, not snapped to the grid
    # log scale: half the points below the geometric mean, as the unit cube's are below 0.5 (exactly for the
    # balanced designs; a linear mapping put 8-9 of 32 there, and range(8, 25) let that pass)
    below = (np.log(ks) < np.log(3000 * 20000) / 2).sum()
    assert below == 16 if kind in ("sobol", "halton", "lhs") else below in range(10, 23)


def test_a_sampled_design_draws_from_a_range_without_its_points():
    """A sampled design's range was refused without ``points`` ("from, to and points go together"), which it then
    did not use: from and to are enough, an integer key's draws stay integers, and a grid still needs them."""
    st = light_study(**{"points = 4\n": "", "[collect]": '[design]\nkind = "sobol"\npoints = 8\n\n[collect]',
                        '[parameters."spring.delta_s"]\nvalues = ["1 mm", "2 mm", "3 mm", "4 mm"]':
                        '[parameters."operation.revolutions"]\nfrom = 1\nto = 3'})
    points = design_points(st)
    assert len({p["spring.ks"] for p in points}) == 8 and all(3e3 <= p["spring.ks"] <= 2e4 for p in points)
    assert {type(p["operation.revolutions"]) for p in points} == {int}
    assert {p["operation.revolutions"] for p in points} <= {1, 2, 3}
    with pytest.raises(StudyError, match="parameters.spring.ks.points = \"\\(missing\\)\": from, to and points go"):
        light_study(**{"points = 4\n": ""})


def test_a_quoted_plain_number_is_read_as_the_scene_reads_it():
    """``"friction.mu1" = ["0.1", "0.2"]`` was refused ("expected a number", no range) although the scene takes
    "0.1"; an angle without its unit, or an integer key's quoted value, is told what is allowed."""
    mu = light_study(**{'values = ["1 mm", "2 mm", "3 mm", "4 mm"]':
                        'values = ["1 mm"]\n[parameters."friction.mu1"]\nvalues = ["0.1", "0.2"]'})
    assert {p["friction.mu1"] for p in design_points(mu)} == {0.1, 0.2}
    for table, message in (('"operation.start_angle" = [0, 30]', "allowed: -360 <= value <= 360 deg"),
                           ('"operation.revolutions" = ["2", 3]', "expected an integer, 1 <= n <= 100000")):
        with pytest.raises(StudyError, match=message):
            light_study(**{"[collect]": f"[parameters]\n{table}\n\n[collect]"})


def test_listed_values_are_categorical_in_a_sampled_design():
    st = light_study(**{"[collect]": '[design]\nkind = "lhs"\npoints = 40\n\n[collect]'})
    assert {p["spring.delta_s"] for p in design_points(st)} <= {0.001, 0.002, 0.003, 0.004}


BAD = [
    # the unknown key's values are shown as written (they were shown as "")
    ({'[parameters."spring.ks"]': '[parameters."spring.kss"]'}, "parameters.spring.kss",
     'parameters.spring.kss = {from = "3e3 N/m", to = "2e4 N/m", points = 4}: not a scene key'),
    ({'from = "3e3 N/m"': 'from = "3e3 kg"'}, "parameters.spring.ks.from", "wrong unit"),
    ({"points = 4": "points = 1"}, "parameters.spring.ks.points", "1 is out of range; allowed: n >= 2"),
    ({'from = "3e3 N/m"': 'from = "-3e3 N/m"'}, "parameters.spring.ks.from", "log scale needs from > 0"),
    ({'to = "2e4 N/m"': 'to = "2e3 N/m"'}, "parameters.spring.ks", "from must be below to"),
    ({'"revolutions"]': '"revolution"]'}, "collect.quantities", "did you mean 'revolutions'"),
    ({"[collect]": '[design]\nkind = "sobbol"\n\n[collect]'}, "design.kind", "allowed"),
    ({"[collect]": '[design]\nkind = "sobol"\npoints = 30\n\n[collect]'}, "design.points", "power of 2"),
    ({"[collect]": '[design]\npoints = 30\n\n[collect]'}, "design.points", "a grid has the product"),
    ({'max_wall_time = "60 s"': 'max_wall_time = "-1 s"'}, "run.max_wall_time", "out of range"),
    ({'"friction_power.total" = { max = "35 W" }': '"gap.max" = { max = "1 um" }'}, "feasible.gap.max",
     "not a collected quantity"),
    ({'"friction_power.total" = { max = "35 W" }': 'gap.max = { max = "1 um" }'}, "feasible.gap",
     'quote a dotted name: "gap.max"'),
    ({'{ max = "35 W" }': '{ max = "35 N" }'}, "feasible.friction_power.total.max", "wrong unit"),
    ({"[run]": "[runn]"}, "runn", "unknown key (did you mean 'run'?)"),
    ({'"solver.rtol" = 1e-4': '"solver.rtol" = 5'}, "scene.solver.rtol", "out of range"),
    ({'name = "light"': 'name = "../../elsewhere"'}, "study.name", "not a plain folder name"),  # the output folder
    ({'name = "light"': 'name = ""'}, "study.name", "not a plain folder name"),
    # a base scene file that is not there, beside a [scene] table: it was named "scene.scene"
    ({'name = "light"': 'name = "light"\nscene = "nope.toml"'}, "study.scene", "file not found"),
    # a misspelt default had no suggestion
    ({'name = "light"': 'name = "light"\nscene = "defualt"'}, "study.scene", "file not found (did you mean 'default'?)"),
    ({'"solver.rtol" = 1e-4': 'solver.rtol = 5'}, "scene.solver.rtol", "out of range"),  # a nested key
    ({"points = 4": 'points = "4"'}, "parameters.spring.ks.points", "expected an integer"),
    ({"[collect]": '[design]\nseed = -1\n\n[collect]'}, "design.seed", "-1 is out of range; allowed: n >= 0"),
    ({'[parameters."spring.delta_s"]\nvalues = ["1 mm", "2 mm", "3 mm", "4 mm"]':
      '[parameters."operation.revolutions"]\nfrom = 1\nto = 1.4\npoints = 3'},
     "parameters.operation.revolutions.points", "at least 3 integers"),  # collapsed to one point before
    # spring.delta_s = [...] in [parameters]: TOML's parameter "spring" with a key "delta_s" ("unknown key" alone)
    ({'[parameters."spring.delta_s"]\nvalues = ["1 mm", "2 mm", "3 mm", "4 mm"]':
      '[parameters]\nspring.delta_s = ["1 mm", "2 mm"]'},
     "parameters.spring.delta_s", 'quote its dotted name: "spring.delta_s" = ["1 mm", "2 mm"]'),
    # a value listed twice (in any unit) ran the same point twice; in a sampled design it weighed double
    ({'values = ["1 mm", "2 mm", "3 mm", "4 mm"]': 'values = ["1 mm", "2 mm", "0.001 m"]'},
     "parameters.spring.delta_s.values", "0.001 m repeated (values[0], values[2]); allowed: distinct values"),
    ({'values = ["1 mm", "2 mm", "3 mm", "4 mm"]': 'values = ["1 mm", "2 mm"]\n[parameters."solver.method"]\n'
      'values = ["erk", "rosenbrock", "erk"]'},
     "parameters.solver.method.values", '"erk" repeated (values[0], values[2])'),
    # a range narrower than its points at the 12 digits scenes keep: the same point several times
    ({'to = "2e4 N/m"': 'to = "3.0000000000001e3 N/m"'}, "parameters.spring.ks.points",
     "give 1 distinct value(s) at 12 significant digits"),
]


@pytest.mark.parametrize(("replace", "key", "message"), BAD, ids=[b[1] for b in BAD])
def test_bad_study_files_are_refused_naming_key_value_and_range(replace, key, message):
    with pytest.raises(StudyError) as info:
        light_study(**replace)
    assert key in info.value.keys(), str(info.value)
    assert message in str(info.value)


def test_a_point_outside_the_scene_range_is_refused_before_any_work():
    """A value the scene refuses (delta_s < 0) names the point, the key, the value and the allowed range; reading
    the study says so (load_study accepted it and only the sweep refused it), with the file's other problems."""
    with pytest.raises(StudyError) as info:
        light_study(**{'values = ["1 mm", "2 mm", "3 mm", "4 mm"]': 'values = ["1 mm", "-2 mm"]'})
    text = str(info.value)
    assert "parameters.spring.delta_s" in info.value.keys()
    assert "-0.002" in text and "out of range" in text and ">= 0" in text and "(points 1, 3, 5, 7)" in text


@pytest.mark.parametrize("design", ["grid", "sobol"])
def test_a_sweep_over_angles_gives_each_point_its_angle(design):
    """The points' values are SI numbers, and a scene refuses a bare angle (deg or rad?): every point of a sweep
    over operation.start_angle or the initial tilt was refused ("give a unit: deg or rad"). The scenes take them
    with their unit, rad; the table keeps the SI numbers."""
    st = light_study(**{'[parameters."spring.ks"]\nfrom = "3e3 N/m"\nto = "2e4 N/m"\npoints = 4\nscale = "log"':
                        '[parameters."operation.start_angle"]\nfrom = "0 deg"\nto = "90 deg"\npoints = 3',
                        'values = ["1 mm", "2 mm", "3 mm", "4 mm"]': "",
                        '[parameters."spring.delta_s"]':
                        '[parameters."operation.initial_state.phi"]\nvalues = ["0 deg", "0.1 deg"]',
                        "[feasible]": (f"[design]\nkind = \"{design}\"\npoints = 4\n\n[feasible]" if design != "grid"
                                       else "[feasible]")})
    points = scenes_of(st)
    assert len(points) == (6 if design == "grid" else 4)
    for _, scene, values in points:
        assert isinstance(values["operation.start_angle"], float)
        assert scene.operation.start_angle == pytest.approx(values["operation.start_angle"], rel=1e-14, abs=0)
        assert scene.operation.initial_state.phi == pytest.approx(values["operation.initial_state.phi"], rel=1e-14)
    if design == "grid":
        assert sorted({v["operation.start_angle"] for _, _, v in points}) == pytest.approx([0, np.pi / 4, np.pi / 2])


def test_a_value_refused_at_many_points_is_one_problem_naming_them():
    """A bad listed value recurs at every point of the grid that holds it: one line naming the points (it was one
    line per point, cut at ten lines under a header that counted those ten as the study's problems)."""
    with pytest.raises(StudyError) as info:
        light_study(**{'values = ["1 mm", "2 mm", "3 mm", "4 mm"]': 'values = ["1 mm", "-2 mm", "3 mm", "4 mm"]'})
    assert [str(p) for p in info.value.errors] == [
        "parameters.spring.delta_s = -0.002: -0.002 m is out of range; allowed: >= 0 m (points 1, 5, 9, 13)"]
    assert str(info.value).startswith("study light.toml: 1 problem\n")
    with pytest.raises(StudyError) as info:  # 0 at 16 of the 128 points
        light_study(**{"[collect]": '[parameters."operation.revolutions"]\nvalues = [1, 0, 2, 3, 4, 5, 6, 7]\n\n'
                                    "[collect]"})
    (problem,) = info.value.errors
    assert problem.key == "parameters.operation.revolutions" and problem.value == 0
    assert problem.message.endswith("(16 points: 1, 9, 17, 25, 33, ..., 121)")


def test_past_ten_distinct_problems_the_check_stops_and_says_where():
    """Every point refused with a value of its own: the first ten are listed, and the error says that the points
    after them were not checked (it listed ten as if they were all)."""
    with pytest.raises(StudyError) as info:
        light_study(**{'values = ["1 mm", "2 mm", "3 mm", "4 mm"]': 'from = "-20 mm"\nto = "-1 mm"\npoints = 12'})
    assert len(info.value.errors) == 10 and all(p.message.endswith(f"(point {i})")
                                                for i, p in enumerate(info.value.errors))
    assert str(info.value).startswith("study light.toml: 10 problems (checked points 0 to 9 of 48; the others were "
                                      "not checked)\n")


def test_the_command_refusing_a_point_leaves_no_empty_folder(tmp_path):
    from click.testing import CliRunner
    from sweep_helpers import LIGHT

    from apexseal.cli import main

    study = tmp_path / "bad.toml"
    study.write_text(LIGHT.replace('values = ["1 mm", "2 mm", "3 mm", "4 mm"]', 'values = ["1 mm", "-2 mm"]'))
    r = CliRunner().invoke(main, ["sweep", str(study), "-w", "1", "-q", "-o", str(tmp_path / "out")])
    assert r.exit_code == 1 and "(points 1, 3, 5, 7)" in r.output, r.output
    assert not (tmp_path / "out").exists()
    assert "writing to" not in r.output, r.output  # it said so before refusing the study, writing nothing


@pytest.mark.parametrize("workers", [0, 1.5], ids=["zero", "not-an-integer"])
def test_run_sweep_refuses_a_number_of_workers_out_of_range(tmp_path, workers):
    """run_sweep checks ``workers`` as the command line's --workers is checked (1 to 4096), before any folder or
    cluster: 0 started a cluster of every core, a negative number one with no workers that waited for ever."""
    from apexseal.runtime.studies.sweep import run_sweep

    allowed = "allowed: an integer 1 <= n <= 4096 (1: serially in this process), or None (a worker per core)"
    with pytest.raises(ValueError) as info:
        run_sweep(light_study(), tmp_path / "out", workers=workers, quiet=True)
    assert str(info.value) == f"workers = {workers!r}: {allowed}"
    assert not (tmp_path / "out").exists()
    from apexseal.runtime.studies.sweep.execute import check_workers

    for bad in (-2, 4097, True):
        with pytest.raises(ValueError, match=f"workers = {bad!r}: allowed"):
            check_workers(bad)
    check_workers(None), check_workers(1), check_workers(4096)


def test_a_list_is_short_for_values_and_a_bare_value_is_refused_with_both_forms():
    short = study_from_toml('[parameters]\n"spring.ks" = ["1e3 N/m", 3e3]\n')
    assert short.parameters[0].values == (1000.0, 3000.0)
    assert short.content_hash() == study_from_toml('[parameters."spring.ks"]\nvalues = ["1e3 N/m", 3e3]\n').content_hash()
    with pytest.raises(StudyError) as info:
        study_from_toml('[parameters]\n"spring.ks" = "3e3 N/m"\n')
    assert info.value.keys() == ["parameters.spring.ks"]
    assert "as a list" in str(info.value) and "from, to and points" in str(info.value)


def test_malformed_toml_and_missing_parameters():
    with pytest.raises(StudyError, match="malformed TOML"):
        study_from_toml("[study\nname = 1")
    with pytest.raises(StudyError) as info:
        study_from_toml(LIGHT.split("[parameters")[0])
    assert "parameters" in info.value.keys()


def test_the_shipped_example_is_the_200_point_design_map():
    from apexseal.commands_sweep import example_path
    from apexseal.runtime.studies.sweep import load_study

    st = load_study(example_path("preload-map"))
    assert len(design_points(st)) == 200
    assert [p.key for p in st.parameters] == ["spring.delta_s", "spring.ks"]
    assert {c.column for c in st.constraints} == {"liftoff_fraction", "friction_power.total"}


def test_the_sampling_example_asks_where_the_energy_balance_closes():
    """`apexseal sweep --example sampling`: the default machine over the output samples per revolution (a decade
    and more on a log axis), its region where the seal's energy balance over the samples closes as a run's summary
    says it does (runtime/results/energy.py)."""
    from apexseal.commands_sweep import EXAMPLES, example_path
    from apexseal.runtime.results.energy import CLOSES_WITHIN
    from apexseal.runtime.studies.sweep import load_study

    assert "sampling" in EXAMPLES
    st = load_study(example_path("sampling"))
    (p,) = st.parameters
    assert p.key == "solver.samples_per_revolution" and p.scale == "log"
    values = [pt[p.key] for pt in design_points(st)]
    assert values == sorted(values) and values[0] <= 360 and values[-1] >= 36000 and 3600 in values
    (c,) = st.constraints
    assert (c.column, c.min, c.max) == ("energy.residual_fraction", None, CLOSES_WITHIN)
    assert {"energy.residual", "energy.residual_fraction"} <= set(st.quantities)


def test_docs_list_every_quantity_and_design():
    from pathlib import Path

    from apexseal.runtime.results.quantities import quantity_help
    from apexseal.runtime.studies.sweep.study import DESIGNS

    docs = (Path(__file__).resolve().parents[2] / "docs" / "sweeps.md").read_text(encoding="utf-8")
    assert [q for q in quantity_help() if f"`{q}`" not in docs] == []
    assert [d for d in DESIGNS if f'`"{d}"`' not in docs] == []


def test_the_documented_study_file_is_a_valid_study():
    """The annotated study file of docs/sweeps.md, every key in it, is read as written."""
    from pathlib import Path

    docs = (Path(__file__).resolve().parents[2] / "docs" / "sweeps.md").read_text(encoding="utf-8")
    study = study_from_toml(docs.split("## The study file")[1].split("```toml\n")[1].split("```")[0])
    assert [p.key for p in study.parameters] == ["spring.delta_s", "solver.method", "spring.ks"]
    assert (study.design, study.points, study.max_wall_time) == ("sobol", 64, 600.0)
    assert len(design_points(study)) == 64


@pytest.mark.parametrize("design", ["grid-1", pytest.param("grid-2", marks=pytest.mark.slow),
                                    pytest.param("sobol", marks=pytest.mark.slow)])
def test_figures_of_each_design_shape(design, tmp_path):
    """Line plot (one parameter), heat map (grid), coloured points (sampled), each with the feasible region."""
    from apexseal.runtime.studies.sweep.figures import sweep_figures

    if design == "grid-1":
        st = study_from_toml(LIGHT.replace('[parameters."spring.delta_s"]\nvalues = ["1 mm", "2 mm", "3 mm", "4 mm"]',
                                           ""))
    elif design == "grid-2":
        st = light_study()
    else:
        st = light_study(**{"[collect]": '[design]\nkind = "sobol"\npoints = 16\n\n[collect]'})
    pts = design_points(st)
    rng = np.random.default_rng(1)
    import pandas as pd

    table = pd.DataFrame([{"point": i, "status": "completed" if i != 3 else "failed", **p,
                           **{q: rng.random() for q in st.quantities}} for i, p in enumerate(pts)])
    paths = sweep_figures(st, table, tmp_path)
    names = {p.name for p in paths}
    assert names == {f"{q}.png" for q in st.quantities} | {"feasible.png"}
    assert all(p.stat().st_size > 5000 for p in paths)


def test_an_unquoted_dotted_scene_key_sets_that_key_only():
    """solver.method = "rosenbrock" (unquoted, which TOML reads as a table) replaced the base's whole [solver],
    dropping the other keys given there and before."""
    st = light_study(**{'"solver.rtol" = 1e-4': '"solver.rtol" = 1e-4\nsolver.method = "rosenbrock"'})
    assert st.scene.solver.method == "rosenbrock"
    assert st.scene.solver.samples_per_revolution == 36 and st.scene.solver.rtol == 1e-4


def test_a_scene_key_that_repairs_a_broken_base_is_still_named_as_its_own(tmp_path):
    """With a base scene that does not load alone, a bad [scene] key was blamed on the base file."""
    from apexseal.runtime.scenes.scene import default_scene_text
    from apexseal.runtime.studies.sweep import study_from_toml

    (tmp_path / "base.toml").write_text(default_scene_text().replace('ks = "5e3 N/m"', 'ks = "abc"'))
    (tmp_path / "expander-pressure.csv").write_text(
        (Path(__file__).resolve().parents[2] / "runtime" / "scenes" / "expander-pressure.csv").read_text())
    text = LIGHT.replace('name = "light"', 'name = "light"\nscene = "base.toml"').replace(
        '"solver.rtol" = 1e-4', '"solver.rtol" = 5\n"spring.ks" = "5e3 N/m"')
    with pytest.raises(StudyError) as info:
        study_from_toml(text, source="s.toml", base_dir=tmp_path)
    assert info.value.keys() == ["scene.solver.rtol"], str(info.value)


def test_a_row_that_did_not_complete_is_never_feasible():
    """Feasible means completed and every constraint met: a failed or interrupted point whose quantities happen to
    meet the constraints is not feasible, with constraints or without."""
    import pandas as pd

    table = pd.DataFrame({"status": ["completed", "failed", "interrupted"], "liftoff_fraction": [0.0] * 3,
                          "friction_power.total": [10.0] * 3})
    st = light_study()
    assert st.constraints and list(st.feasible(table)) == [True, False, False]
    bare = light_study(**{'[feasible]\nliftoff_fraction = { max = 0 }\n"friction_power.total" = { max = "35 W" }\n': ""})
    assert not bare.constraints and list(bare.feasible(table)) == [True, False, False]


def test_every_problem_of_a_study_is_reported_at_once():
    """A table with a wrong key or type does not hide the problems of the others: an unknown key of [design], an
    unquoted dotted parameter, reversed bounds (shown in one unit), an unknown quantity and a constraint on a column
    not collected come in one error (the key and type problems used to come alone, the rest on the next try)."""
    text = """
[parameters.operation.rpm]
from = 1000
to = 3000
[parameters."spring.ks"]
from = "5e3 N/mm"
to = "2e4 N/m"
points = 3
[design]
bogus = 1
[collect]
quantities = ["friction_power.total", "liftof_fraction"]
[feasible]
"penetration.c9" = { max = 1 }
"""
    with pytest.raises(StudyError) as info:
        study_from_toml(text)
    by_key = {p.key: p.message for p in info.value.errors}
    assert set(by_key) == {"parameters.operation.rpm", "design.bogus", "parameters.spring.ks", "collect.quantities",
                           "feasible.penetration.c9"}, by_key
    assert '[parameters."operation.rpm"]' in by_key["parameters.operation.rpm"]
    assert "5e+06 N/m is not below 20000 N/m" in by_key["parameters.spring.ks"]
    assert "did you mean 'liftoff_fraction'" in by_key["collect.quantities"]


def test_a_parameter_no_law_reads_is_refused():
    """Varying mu2 while the study's scene has groove friction off ran identical points without a word; a
    parameter read by some law while another friction is on (v_eps) or whose effect is varied too passes."""
    base = '[scene]\n"effects.groove_friction" = false\n'
    with pytest.raises(StudyError) as info:
        study_from_toml(base + '[parameters]\n"friction.mu2" = [0.1, 0.2]\n')
    (p,) = info.value.errors
    assert p.key == "parameters.friction.mu2" and "read by no law while effects.groove_friction is off" in p.message
    study_from_toml(base + '[parameters]\n"friction.v_eps" = ["1 mm/s", "2 mm/s"]\n')
    study_from_toml(base + '[parameters]\n"friction.mu2" = [0.1, 0.2]\n"effects.groove_friction" = [true, false]\n')


def _constant_pressure_scene(path) -> None:
    """The default scene with constant chamber pressures (2 and 1 bar), written to ``path``."""
    import apexseal
    from apexseal.runtime.scenes.resolved import resolved_toml

    const = apexseal.load_scene().with_overrides(**{"pressure.source": "constant", "pressure.Pa": "2 bar",
                                                    "pressure.Pb": "1 bar", "pressure.file": None,
                                                    "pressure.unit": None})
    path.write_text(resolved_toml(const)[0])


def test_a_chamber_pressure_varied_while_the_chamber_pressure_is_off_is_refused(tmp_path):
    """pressure.Pa and pressure.Pb are no model parameters but inputs read only while effects.chamber_pressure is
    on (the pressure submodel's scene inputs, registry.scene_inputs): varied with it off, every point was the same
    run, without a word. Varied with the effect, they pass."""
    _constant_pressure_scene(tmp_path / "const.toml")
    text = ('[study]\nscene = "const.toml"\n[scene]\n"effects.chamber_pressure" = false\n'
            '[parameters]\n"pressure.Pa" = ["2 bar", "3 bar"]\n"pressure.Pb" = ["1 bar", "1.5 bar"]\n')
    with pytest.raises(StudyError) as info:
        study_from_toml(text, base_dir=tmp_path)
    assert {p.key for p in info.value.errors} == {"parameters.pressure.Pa", "parameters.pressure.Pb"}, info.value
    for p in info.value.errors:
        assert "read by no law while effects.chamber_pressure is off" in p.message, p
    study_from_toml(text + '"effects.chamber_pressure" = [true, false]\n', base_dir=tmp_path)


def test_a_gas_value_varied_without_a_gas_pressure_source_is_refused():
    """The gas model's values are read only with pressure.source = "chamber" or "chamber+leakage": varied under the
    default scene's table every point was the same run. The message names the key that decides it (the choice
    pressure_model follows pressure.source); varied with the source, the study passes."""
    varied = '[parameters]\n"gas.p_supply" = ["5 bar", "6 bar"]\n'
    with pytest.raises(StudyError) as info:
        study_from_toml(varied)
    (p,) = info.value.errors
    assert p.key == "parameters.gas.p_supply"
    assert "read by no law while pressure.source is neither 'chamber' nor 'chamber+leakage'" in p.message
    study_from_toml(varied + '"pressure.source" = ["chamber", "table"]\n')


def test_a_parameter_a_modelling_choice_reads_is_refused_without_it():
    """contacts.delta_ref is read under assumptions.damping_law = "penetration" only: varied without that choice it
    is refused, naming the choice; with it in [scene], or varied with it, it passes."""
    varied = '[parameters]\n"contacts.delta_ref" = ["10 nm", "30 nm"]\n'
    with pytest.raises(StudyError) as info:
        study_from_toml(varied)
    (p,) = info.value.errors
    assert p.key == "parameters.contacts.delta_ref"
    assert "read by no law while assumptions.damping_law is not 'penetration'" in p.message
    assert "make that choice in [scene]" in p.message
    study_from_toml('[scene]\n"assumptions.damping_law" = "penetration"\n' + varied)
    study_from_toml(varied + '"assumptions.damping_law" = ["penetration", "velocity"]\n')


def test_a_parameter_whose_effect_follows_a_varied_parent_is_not_refused():
    """Varying effects.housing_contact varies housing_friction with it where a scene leaves the child unset (it
    follows its parent), so mu1 is read at some points: such a study was refused as varying a parameter no law
    reads. The check leaves a parameter alone whenever its effect or a parent of it is varied."""
    text = ('[scene]\n"effects.housing_contact" = false\n"effects.housing_damping" = false\n'
            '"effects.housing_friction" = false\n'
            '[parameters]\n"effects.housing_contact" = [true, false]\n"friction.mu1" = [0.1, 0.2]\n')
    study_from_toml(text)


def test_a_malformed_study_table_keeps_its_scene_and_a_bad_parameter_its_own_problem(tmp_path):
    """With [study] malformed (a name with a space), the study's scene was dropped for the default one, so a key
    right for its own scene was refused against the default's; a constraint on a parameter refused for its own
    problem was reported again as 'not collected'."""
    _constant_pressure_scene(tmp_path / "const.toml")
    text = ('[study]\nname = "has space"\nscene = "const.toml"\n[scene]\n"pressure.Pa" = "3 bar"\n'
            '[parameters]\n"spring.ks" = [1e3, 2e3]\n"bad" = {from = 1}\n[feasible]\n"bad" = {max = 1}\n')
    with pytest.raises(StudyError) as info:
        study_from_toml(text, base_dir=tmp_path)
    assert {p.key for p in info.value.errors} == {"study.name", "parameters.bad"}, info.value


def test_the_output_folder_table_says_the_figures_are_the_command_s_and_how_to_draw_them():
    """docs/sweeps.md listed <quantity>.png and feasible.png in the output folder while run_sweep from Python writes
    no figure: the table says they are the command's and names the function that draws them."""
    from pathlib import Path

    import apexseal.commands_sweep as command
    from apexseal.runtime.studies.sweep.figures import sweep_figures

    docs = (Path(__file__).resolve().parents[2] / "docs" / "sweeps.md").read_text(encoding="utf-8")
    assert "| `<quantity>.png` | `apexseal sweep` only" in docs and "| `feasible.png` | `apexseal sweep` only" in docs
    assert "`apexseal.runtime.studies.sweep.figures.sweep_figures(study, report.table, \"out/\")`" in docs
    assert "sweep_figures(st, report.table, out)" in Path(command.__file__).read_text(encoding="utf-8")
    assert sweep_figures.__module__ == "apexseal.runtime.studies.sweep.figures"


def test_a_heat_map_keeps_positive_values_positive_and_names_the_points_without_a_value():
    """With rpm values [0.01, 1500, 3000] the heat map's first cell reached -750 rpm (a negative speed), and its
    invalid points were blank cells without a legend entry."""
    import pandas as pd

    from apexseal.runtime.results.figures import new_figure
    from apexseal.runtime.studies.sweep.figures import quantity_figure

    st = light_study(**{'[parameters."spring.ks"]\nfrom = "3e3 N/m"\nto = "2e4 N/m"\npoints = 4\nscale = "log"':
                        '[parameters."operation.rpm"]\nvalues = ["0.01 rpm", "1500 rpm", "3000 rpm"]'})
    pts = design_points(st)
    table = pd.DataFrame([{"point": i, "status": "invalid" if p["operation.rpm"] < 1 else "completed", **p,
                           **{q: float(i) for q in st.quantities}} for i, p in enumerate(pts)])
    ax = new_figure((6.4, 4.8)).add_subplot()
    quantity_figure(st, table, "friction_power.total", None, ax=ax, feasible=st.feasible(table))
    assert ax.get_xlim()[0] >= 0, ax.get_xlim()
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["invalid (4): no value"]


def test_a_heat_map_of_three_parameters_says_its_cells_are_feasible_at_every_value_of_the_third():
    """With a third parameter a cell's colour was the mean over it and its hatching "not feasible at every value of
    it", while the title counted points ("5 of 8 points" over 1 clear cell of 4): title and panel say both."""
    import pandas as pd

    from apexseal.runtime.results.figures import new_figure
    from apexseal.runtime.studies.sweep.figures import feasible_count, quantity_figure

    st = light_study(**{"points = 4": "points = 2", '"1 mm", "2 mm", "3 mm", "4 mm"': '"1 mm", "2 mm"',
                        "[collect]": '[parameters]\n"friction.mu1" = [0.1, 0.2]\n\n[collect]'})
    pts = design_points(st)
    power = [20.0 if (p["spring.ks"] < 1e4 and p["spring.delta_s"] < 1.5e-3) or p["friction.mu1"] < 0.15 else 50.0
             for p in pts]  # below the 35 W bound: one cell at both mu1, three cells at mu1 = 0.1 alone
    table = pd.DataFrame([{"point": i, "status": "completed", **p, "friction_power.total": w,
                           **{q: 0.0 for q in st.quantities if q != "friction_power.total"}}
                          for i, (p, w) in enumerate(zip(pts, power, strict=True))])
    feasible = st.feasible(table)
    assert feasible_count(st, table, feasible) == "5 of 8 points; 1 of 4 cells feasible at every value of friction.mu1"
    ax = new_figure((6.4, 4.8)).add_subplot()
    quantity_figure(st, table, "friction_power.total", None, ax=ax, feasible=feasible)
    assert "(mean over friction.mu1; unhatched: feasible at every value of it)" in ax.get_title().replace("\n", " ")


def test_a_points_value_is_refused_with_the_files_other_problems_and_checked_once():
    """The study file was checked first and the points' scenes only by the sweep: a misspelt quantity hid a value
    the scene refuses until the next run, and load_study accepted a study the sweep then refused. Both are said at
    once now, and the sweep takes the points load_study checked (a study changed since is checked again)."""
    from dataclasses import replace

    with pytest.raises(StudyError) as info:
        light_study(**{'values = ["1 mm", "2 mm", "3 mm", "4 mm"]': 'values = ["1 mm", "-2 mm"]',
                       '"revolutions"]': '"revolution"]'})
    assert set(info.value.keys()) == {"collect.quantities", "parameters.spring.delta_s"}, str(info.value)
    st = light_study()
    assert st.points_checked[0] == st.content_hash() and scenes_of(st) == list(st.points_checked[1])
    other = replace(st, scene=st.scene.with_overrides(**{"solver.rtol": 1e-5}))
    assert {s.solver.rtol for _, s, _ in scenes_of(other)} == {1e-5}  # not the points of the study it came from
