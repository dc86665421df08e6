"""Pressure sources: periodic interpolation, interval means, table checks, the default table."""

import math
from importlib.resources import files
from pathlib import Path

import numpy as np
import pytest

from apexseal.runtime.scenes.errors import SceneError
from apexseal.runtime.scenes.pressure import (
    ConstantPressure,
    NoPressure,
    PeriodicLinear,
    TablePressure,
    load_table,
    parse_table,
)
from apexseal.runtime.scenes.pressure_default import (
    GAMMA,
    P_EXHAUST,
    P_SUPPLY,
    chamber_a_area,
    default_table,
    write_default_table,
)
from apexseal.runtime.scenes.scene import load_scene

TWO_PI = 2 * math.pi
SIMPLE = "theta_deg,Pa,Pb\n0,100,400\n90,200,300\n180,300,200\n270,200,100\n"


def table(text: str = SIMPLE, **kw) -> TablePressure:
    return parse_table(text, file="t.csv", **kw)


def dense_mean(f, a: float, b: float, n: int = 200001) -> float:
    t = np.linspace(a, b, n)
    y = f(t)
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(t)) / (b - a))


# ---------------------------------------------------------------------------
# interpolation


def test_table_hits_its_knots_and_interpolates_linearly():
    t = table()
    theta = np.radians([0, 90, 180, 270, 45, 225])
    np.testing.assert_allclose(t.Pa(theta), [100, 200, 300, 200, 150, 250])
    np.testing.assert_allclose(t.Pb(theta), [400, 300, 200, 100, 350, 150])


def test_table_is_periodic_and_wraps_between_last_and_first_row():
    t = table()
    theta = np.linspace(-3 * TWO_PI, 3 * TWO_PI, 1001)
    np.testing.assert_allclose(t.Pa(theta), t.Pa(np.mod(theta, TWO_PI)), atol=1e-9)
    # between 270 deg (200) and 360 = 0 deg (100): the wrap segment
    np.testing.assert_allclose(t.Pa(np.radians(315.0)), 150.0)
    np.testing.assert_allclose(t.Pb(np.radians(-45.0)), 250.0)


def test_call_returns_both_and_keeps_shape():
    pa, pb = table()(np.zeros((2, 3)))
    assert pa.shape == pb.shape == (2, 3)
    assert np.all(pa == 100) and np.all(pb == 400)


def test_table_in_minus_180_to_180_wraps():
    shifted = "theta_deg,Pa,Pb\n-180,300,200\n-90,200,100\n0,100,400\n90,200,300\n"
    a, b = table(shifted), table()
    theta = np.linspace(0, TWO_PI, 37)
    np.testing.assert_allclose(a.Pa(theta), b.Pa(theta))
    np.testing.assert_allclose(a.Pb(theta), b.Pb(theta))


def test_table_unit_converts_to_pascal():
    t = table("theta_deg,Pa,Pb\n0,6,1\n180,1,6\n", factor=1e5, unit="bar")
    np.testing.assert_allclose(t(np.array([0.0, math.pi])), [[6e5, 1e5], [1e5, 6e5]])
    assert t.to_dict()["unit"] == "bar"


def test_comments_and_blank_lines_are_skipped():
    t = table("# a comment\n\ntheta_deg,Pa,Pb\n# another\n0,1,2\n\n180,3,4\n")
    assert t.theta_deg.tolist() == [0.0, 180.0]


# ---------------------------------------------------------------------------
# interval means


@pytest.mark.parametrize(
    "a, b",
    [(0.1, 0.7), (5.9, 6.6), (-1.0, 0.3), (0.0, TWO_PI), (2.0, 2.0 + 3 * TWO_PI + 0.4), (-20.0, -19.99)],
)
def test_interval_means_are_exact_integrals(a, b):
    t = table()
    pa, pb = t.interval_means([a, b])
    assert pa[0] == pytest.approx(dense_mean(t.Pa, a, b), rel=1e-8)
    assert pb[0] == pytest.approx(dense_mean(t.Pb, a, b), rel=1e-8)


def test_interval_means_over_many_intervals_and_a_full_period():
    t = table()
    edges = np.linspace(0.3, 0.3 + TWO_PI, 721)
    pa, pb = t.interval_means(edges)
    assert pa.shape == pb.shape == (720,)
    # the weighted means over one period give the period mean: (area of the polygon) / 2π
    assert np.sum(pa * np.diff(edges)) / TWO_PI == pytest.approx(200.0)
    assert np.sum(pb * np.diff(edges)) / TWO_PI == pytest.approx(250.0)
    # a short interval's mean is the value at its middle (linear inside a segment)
    mid = 0.5 * (edges[1:] + edges[:-1])
    inside = np.floor(edges[:-1] / (math.pi / 2)) == np.floor(edges[1:] / (math.pi / 2))
    np.testing.assert_allclose(pa[inside], t.Pa(mid[inside]), rtol=1e-12)


def test_periodic_linear_antiderivative_is_continuous_and_grows_by_the_period_integral():
    f = PeriodicLinear(np.radians([10.0, 100.0, 250.0]), np.array([1.0, 5.0, 2.0]))
    x = np.linspace(-10, 10, 4001)
    F = f.integral(x)
    assert np.max(np.abs(np.diff(F))) < 5.0 * (x[1] - x[0]) + 1e-12  # no jumps: |f| <= 5
    np.testing.assert_allclose(f.integral(x + TWO_PI) - F, f.period_integral, rtol=1e-12)


@pytest.mark.parametrize("edges", [[0.0], [[0.0, 1.0]], [1.0, 0.5], [0.0, 0.0, 1.0], [0.0, np.nan]])
def test_interval_means_refuse_bad_edges(edges):
    with pytest.raises(ValueError, match="theta_edges"):
        table().interval_means(edges)


def test_constant_and_none_sources():
    c = ConstantPressure(6e5, 1e5)
    np.testing.assert_array_equal(c.Pa(np.zeros(3)), 6e5)
    np.testing.assert_array_equal(c.Pb(np.zeros(3)), 1e5)
    pa, pb = c.interval_means([0, 1, 2])
    assert pa.tolist() == [6e5, 6e5] and pb.tolist() == [1e5, 1e5]
    n = NoPressure()
    assert n.to_dict() == {"source": "none"}
    assert np.all(n.Pa(np.ones(4)) == 0) and np.all(n.interval_means([0, 1])[1] == 0)


# ---------------------------------------------------------------------------
# bad tables: one SceneError naming pressure.file, the file and the line


BAD = [
    ("header", "theta,Pa,Pb\n0,1,2\n90,1,2\n", ["line 1", "expected the header 'theta_deg,Pa,Pb'"]),
    ("columns", "theta_deg,Pa,Pb\n0,1,2\n90,1\n", ["line 3", "expected 3 comma-separated numbers", "got 2"]),
    ("not-a-number", "theta_deg,Pa,Pb\n0,1,2\n90,abc,2\n", ["line 3", "is not three numbers"]),
    ("nan", "theta_deg,Pa,Pb\n0,1,2\n90,nan,2\n", ["line 3", "Pa = nan is not a finite number"]),
    ("inf", "theta_deg,Pa,Pb\n0,1,inf\n90,1,2\n", ["line 2", "Pb = inf is not a finite number"]),
    (
        "negative",
        "theta_deg,Pa,Pb\n0,1,2\n90,-5,2\n",
        ["line 3", "Pa = -5 Pa is a negative absolute pressure", "allowed: >= 0"],
    ),
    (
        "not-increasing",
        "theta_deg,Pa,Pb\n0,1,2\n90,1,2\n45,1,2\n",
        ["line 4", "theta_deg = 45 is below the previous angle 90 (line 3)", "allowed: strictly increasing"],
    ),
    (
        "duplicate",
        "theta_deg,Pa,Pb\n0,1,2\n90,1,2\n90,3,2\n",
        ["line 4", "theta_deg = 90 repeats the previous angle 90 (line 3)", "allowed: strictly increasing"],
    ),
    ("one-row", "theta_deg,Pa,Pb\n0,1,2\n", ["1 data row", "allowed: at least 2 rows"]),
    ("no-rows", "theta_deg,Pa,Pb\n", ["0 data rows", "allowed: at least 2 rows"]),
    ("empty", "# only a comment\n", ["empty", "expected the header"]),
    (
        "span",
        "theta_deg,Pa,Pb\n0,1,2\n180,1,2\n360,1,2\n",
        ["angles span [0, 360] deg (lines 2-4)", "allowed: one revolution", "[0, 360)", "[-180, 180)"],
    ),
    ("span-negative", "theta_deg,Pa,Pb\n-270,1,2\n0,1,2\n", ["angles span [-270, 0] deg", "[-180, 180)"]),
]


@pytest.mark.parametrize("text, fragments", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_table(text, fragments):
    with pytest.raises(SceneError) as info:
        table(text)
    (problem,) = info.value.errors
    assert (problem.key, problem.value) == ("pressure.file", "t.csv")
    assert str(problem).startswith('pressure.file = "t.csv": t.csv')
    for fragment in fragments:
        assert fragment in problem.message, (fragment, problem.message)


def test_the_docs_error_table_shows_these_messages():
    docs = (Path(__file__).resolve().parents[2] / "docs" / "scenes.md").read_text(encoding="utf-8")
    for _, text, _ in BAD:
        with pytest.raises(SceneError) as info:
            parse_table(text, file="p.csv")
        assert f"`{info.value.errors[0]}`" in docs


def test_many_bad_rows_are_listed_then_summarised():
    text = "theta_deg,Pa,Pb\n" + "".join(f"{i},-1,1\n" for i in range(30))
    with pytest.raises(SceneError) as info:
        table(text)
    errors = info.value.errors
    assert len(errors) == 21 and errors[-1].message == "... and 10 more problems"


def test_missing_file_names_the_file(tmp_path):
    with pytest.raises(SceneError) as info:
        load_table("nope.csv", tmp_path)
    (problem,) = info.value.errors
    assert (problem.key, problem.value) == ("pressure.file", "nope.csv")
    assert "file not found" in problem.message and "nope.csv" in problem.message


def test_unreadable_file_names_the_file(tmp_path):
    (tmp_path / "folder.csv").mkdir()
    (tmp_path / "latin1.csv").write_bytes("theta_deg,Pa,Pb\n# \xe9\n".encode("latin-1"))
    for name in ("folder.csv", "latin1.csv"):
        with pytest.raises(SceneError) as info:
            load_table(name, tmp_path)
        (problem,) = info.value.errors
        assert (problem.key, problem.value) == ("pressure.file", name) and "cannot read" in problem.message


def test_scene_reports_a_bad_table_with_its_other_problems(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("theta_deg,Pa,Pb\n0,1,2\n0,1,2\n")
    with pytest.raises(SceneError) as info:
        load_scene().with_overrides(**{"pressure.file": str(bad), "seal.Wg": "1 mm"})
    assert sorted(info.value.keys()) == ["pressure.file", "seal.Wg"]
    assert "line 3" in str(info.value)


def test_scene_table_path_is_relative_to_the_scene_file(tmp_path):
    (tmp_path / "p.csv").write_text("theta_deg,Pa,Pb\n0,2e5,1e5\n180,1e5,2e5\n")
    text = files("apexseal.runtime").joinpath("scenes", "default.toml").read_text(encoding="utf-8")
    (tmp_path / "s.toml").write_text(text.replace('"expander-pressure.csv"', '"p.csv"'))
    scene = load_scene(tmp_path / "s.toml")
    assert scene.pressure.Pa(0.0) == 2e5 and scene.source_path == tmp_path / "s.toml"
    with pytest.raises(SceneError, match="file not found"):
        load_scene(tmp_path / "s.toml").with_overrides(**{"pressure.file": "other.csv"})


def test_constant_source_from_a_scene():
    scene = load_scene().with_overrides(
        **{
            "pressure.source": "constant",
            "pressure.file": None,
            "pressure.unit": None,
            "pressure.Pa": "6 bar",
            "pressure.Pb": 1.013e5,
        }
    )
    assert isinstance(scene.pressure, ConstantPressure)
    assert scene.pressure(np.array([1.0])) == (pytest.approx([6e5]), pytest.approx([1.013e5]))
    assert scene.effects.chamber_pressure


def test_source_none_switches_the_pressure_effect_off():
    scene = load_scene().with_overrides(
        **{
            "pressure.source": "none",
            "pressure.file": None,
            "pressure.unit": None,
            "effects.chamber_pressure": None,
        }
    )
    assert isinstance(scene.pressure, NoPressure) and not scene.effects.chamber_pressure
    assert scene.effects.spring  # the rest untouched


# ---------------------------------------------------------------------------
# the default table (an estimate of a gas expander; see scene_pressure_default.py)


@pytest.fixture(scope="module")
def default_csv() -> str:
    return files("apexseal.runtime").joinpath("scenes", "expander-pressure.csv").read_text(encoding="utf-8")


def test_default_table_is_reproducible(tmp_path, default_csv):
    out = write_default_table(tmp_path / "p.csv")
    assert out.read_text(encoding="utf-8") == default_csv


def test_default_table_says_it_is_an_estimate(default_csv):
    assert "ESTIMATE, not the paper's data" in default_csv.splitlines()[0]


def test_default_table_shape_and_phase():
    theta_deg, pa, pb = default_table()
    assert theta_deg.size == 720 and np.allclose(np.diff(theta_deg), 0.5) and theta_deg[0] == 0
    np.testing.assert_allclose(pb, np.roll(pa, -360))  # Pb(theta) = Pa(theta + pi)
    assert pa.max() == pytest.approx(P_SUPPLY) and pa.min() == pytest.approx(P_EXHAUST)


def test_default_table_is_an_ideal_expander():
    theta_deg, pa, _ = default_table()
    theta = np.radians(theta_deg)
    area = chamber_a_area(theta)
    admission = (theta_deg >= 185) & (theta_deg <= 202)
    expansion = (theta_deg > 202) & (theta_deg < 360)
    exhaust = (theta_deg >= 5) & (theta_deg <= 180)
    assert np.all(pa[admission] == P_SUPPLY) and np.all(pa[exhaust] == P_EXHAUST)
    # isentropic: P A^gamma constant, and the volume grows while the pressure falls
    pav = pa[expansion] * area[expansion] ** GAMMA
    np.testing.assert_allclose(pav, pav[0], rtol=1e-12)
    assert np.all(np.diff(area[expansion]) > 0) and np.all(np.diff(pa[expansion]) < 0)
    # chamber a is smallest at theta = pi and largest at theta = 0 (derive.chambers.housing_area)
    assert np.argmin(area) == 360 and np.argmax(area) == 0


def test_default_scene_uses_the_default_table(default_csv):
    scene = load_scene()
    theta_deg, pa, pb = default_table()
    np.testing.assert_allclose(scene.pressure.Pa(np.radians(theta_deg)), pa, atol=0.051)
    np.testing.assert_allclose(scene.pressure.Pb(np.radians(theta_deg)), pb, atol=0.051)


def test_a_table_read_again_is_shared_read_only_and_a_changed_one_is_read_anew(tmp_path):
    """The same file's text is parsed once per process (a sweep's every point reads it); the shared table cannot
    be changed through one scene, and other bytes give another table."""
    path = tmp_path / "p.csv"
    path.write_text(SIMPLE)
    first = load_table("p.csv", tmp_path)
    assert load_table("p.csv", tmp_path) is first
    with pytest.raises(ValueError, match="read-only"):
        first.pa[0] = 0.0
    assert load_table("p.csv", tmp_path, unit="bar") is not first  # another unit: another table
    path.write_text(SIMPLE.replace("100,400", "150,400"))
    again = load_table("p.csv", tmp_path)
    assert again is not first and again.Pa(0.0) == 150.0 and first.Pa(0.0) == 100.0


def test_a_table_in_bar_hashes_as_its_resolved_scene_in_pa(tmp_path):
    """The result's scene.toml writes the table in Pa: a scene whose table was in bar could never be continued (its
    content hash kept the unit, so the written scene was "not the scene the run computed")."""
    from apexseal.runtime.scenes.resolved import resolved_toml

    (tmp_path / "p.csv").write_text("theta_deg,Pa,Pb\n0,6,1.013\n180,1.013,6\n")
    scene = load_scene().with_overrides(**{"pressure": {"source": "table", "file": str(tmp_path / "p.csv"),
                                                        "unit": "bar"}})
    assert scene.pressure.unit == "bar" and scene.pressure.pa[0] == 6e5
    toml, files = resolved_toml(scene)
    out = tmp_path / "run"
    out.mkdir()
    (out / "scene.toml").write_text(toml)
    for name, content in files.items():
        (out / name).write_text(content)
    again = load_scene(out / "scene.toml")
    assert again.pressure.unit == "Pa"
    np.testing.assert_array_equal(again.pressure.pa, scene.pressure.pa)
    assert again.content_hash() == scene.content_hash()


@pytest.mark.parametrize("pressure", [{"source": "constant", "Pa": "6 bar", "Pb": "1 bar"}, {"source": "none"}],
                         ids=["constant", "none"])
def test_every_pressure_source_survives_its_resolved_scene(tmp_path, pressure):
    """The scene.toml a run writes reloads as the same scene for the sources without a table too (Pb written with
    Pa's value went unnoticed: only the table source was round-tripped)."""
    from apexseal.runtime.scenes.resolved import resolved_toml

    over = {"pressure": pressure} | ({"effects.chamber_pressure": False} if pressure["source"] == "none" else {})
    scene = load_scene().with_overrides(**over)
    toml, files = resolved_toml(scene)
    (tmp_path / "scene.toml").write_text(toml)
    for name, content in files.items():
        (tmp_path / name).write_text(content)
    again = load_scene(tmp_path / "scene.toml")
    assert again.pressure.to_dict() == scene.pressure.to_dict() and again.content_hash() == scene.content_hash()


def test_a_relative_table_given_to_the_embedded_scene_is_the_current_folder_s(tmp_path, monkeypatch):
    """``load_scene().with_overrides(**{"pressure.file": "expander-pressure.csv"})`` with the user's edited copy in
    the current folder read the package's table of that name beside the embedded scene, silently (the same
    content hash as the default). A relative file given to an embedded scene, from Python or --set, is the current
    folder's where it holds one (else the embedded scenes' table of that name); a scene file of the user's keeps
    its own folder (the test above)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "expander-pressure.csv").write_text("theta_deg,Pa,Pb\n0,1e5,1e5\n180,1e5,1e5\n")
    for scene in (load_scene().with_overrides(**{"pressure.file": "expander-pressure.csv"}),
                  load_scene(overrides={"pressure.file": "expander-pressure.csv"})):
        assert scene.pressure.Pa(1.0) == 1e5 and scene.content_hash() != load_scene().content_hash()
    with pytest.raises(SceneError, match="file not found"):
        load_scene().with_overrides(**{"pressure.file": "mine.csv"})
    (tmp_path / "expander-pressure.csv").unlink()  # a name the current folder does not hold: the package's table
    assert load_scene().with_overrides(**{"pressure.file": "expander-pressure.csv"}).content_hash() == \
        load_scene().content_hash()


def test_a_scene_named_like_one_of_apexseals_own_says_how_to_load_it():
    """load_scene("soft-contacts") said "file not found" and no more; apexseal's own scenes load by path only."""
    import apexseal

    with pytest.raises(SceneError, match=r"embedded_scene_path\('soft-contacts.toml'\)"):
        load_scene("soft-contacts")
    assert apexseal.load_scene(apexseal.embedded_scene_path("soft-contacts.toml")).name == "soft-contacts.toml"
    with pytest.raises(SceneError) as info:
        load_scene("nosuch")
    assert "embedded_scene_path" not in str(info.value)
