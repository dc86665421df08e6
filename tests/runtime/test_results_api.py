"""SimulationResult for a notebook user (issue: results a notebook user can trust and look at).

Each defect of the issue has a test here: repr dumping arrays, undocumented fields, no xarray/pandas, no
event list, empty erk statistics, internal summary, figures returning paths and switching the backend,
Fig. 12's overlapping radial labels and clipped legend, Fig. 14's linear axis and side-lobe peaks, and a
saved result that does not record its scene.
"""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import matplotlib
import numpy as np
import pytest

import apexseal
from apexseal.runtime.results.figures import ports_of
from apexseal.runtime.results.outputs import describe, documented_names, header, markdown_table
from apexseal.runtime.results.result import SimulationResult

SAMPLES = 360  # the integrator of tests/runtime/test_simulate.py: compiled once per session

#: the repository (the tests run from a checkout; the package itself may be installed elsewhere)
REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def result(default_scene, default_functions):
    return apexseal.simulate(default_scene, samples_per_revolution=SAMPLES, flags="quick", rtol=1e-8,
                             functions=default_functions.sx)


def test_repr_is_short_and_says_what_matters(result):
    text = repr(result)
    assert len(text) < 160 and "\n" not in text and "array" not in text
    for part in ("completed", "1.00 rev", f"{result.n} samples", f"{result.n_events} events", "friction power"):
        assert part in text, part
    html = result._repr_html_()
    assert html.startswith("<table") and "friction power" in html and "b1" in html
    # the samples' row says what a notebook user otherwise finds only in summary(): whether the samples resolve the
    # contacts' ringing and the loads' work (the console's notes)
    summary = result.summary()
    assert f"{result.n} ({SAMPLES} per revolution); the contacts&#x27; ringing" in html
    assert ("not resolved (" in html) == (not summary["sampling"]["resolved"])
    assert ("the energy balance misses" in html) == (not summary["energy_balance"]["closes"])
    from dataclasses import replace

    from apexseal.runtime.results.result import StopInfo

    failed = replace(result, status="failed", stop=StopInfo(0.5, "q1", "the integrator failed: step size underflow "
                                                                     "at theta = 0.5 rad after 20000 steps"))
    text = repr(failed)  # why it stopped, cut short (the whole is in .stop)
    assert text.startswith("SimulationResult(failed (the integrator failed: step size underflow at theta = 0.5 r…), "
                           "1.00 rev") and len(text) < 200


def test_equality_is_identity_and_the_data_compare_as_xarray_compares_them(result):
    """``a == b`` raised "truth value of an array is ambiguous" (the dataclass compared its numpy fields): it is
    identity, and the docstring says how to compare the data."""
    from dataclasses import replace

    from apexseal.runtime.results.compare import Comparison
    from apexseal.runtime.studies.preload.problem import Periodic, PreloadMap, PreloadSetup
    from apexseal.runtime.studies.preload.schedule import Resimulation
    from apexseal.runtime.studies.sweep.execute import SweepReport

    twin = replace(result)
    assert result == result and result != twin and twin in [result, twin]
    assert result.to_xarray().equals(twin.to_xarray()) and "to_xarray().equals" in SimulationResult.__doc__
    for cls in (Comparison, SweepReport, PreloadMap, Periodic, PreloadSetup, Resimulation):  # they hold arrays too
        assert cls.__eq__ is object.__eq__, cls


def test_an_unknown_column_names_the_closest_and_the_columns(result):
    """``result.column("xx")`` was a bare KeyError('xx'): it says what plot() says of an unknown quantity."""
    with pytest.raises(KeyError, match=r"column 'Pf_totl' is not a state nor an output of this result \(did you mean "
                                       r"'Pf_total'\?\); its columns: x, y, phi, xd, yd, phid, "):
        result.column("Pf_totl")
    assert np.array_equal(result.column("Pf_total"), result.outputs["Pf_total"])


def test_the_docstring_describes_the_fields_as_they_are(result):
    """It said ``state_names()`` (a tuple), listed the guards b1 first (the model's order starts at xs5) and called
    ``events`` a running count without saying it is float64."""
    doc = SimulationResult.__doc__
    assert isinstance(result.state_names, tuple) and "state_names()" not in doc
    assert f"``{result.guard_names!r}``".replace("'", '"') in doc
    assert result.events.dtype == np.float64 and "float64" in doc
    assert np.all(np.diff(result.events, axis=1) >= 0) and result.n_events == result.events[:, -1].sum()


def test_save_says_a_saved_result_cannot_be_continued():
    """docs/results.md said each part holds z_end, but a result saved from memory holds none, and resume refuses it
    (tests/runtime/test_continuation.py): its docstring and the docs say so."""
    assert "cannot be continued" in SimulationResult.save.__doc__ and "out=folder" in SimulationResult.save.__doc__
    docs = (REPO / "docs" / "results.md").read_text(encoding="utf-8")
    assert "saved\n  from memory with `result.save(folder)` has the samples only" in docs


def test_help_documents_every_field_with_units():
    doc = SimulationResult.__doc__
    for name in ("theta", "time", "state", "closed", "events", "outputs", "guard_names", "modes", "status", "stop",
                 "info", "scene"):
        assert f"``{name}``" in doc, name
    assert "x, y (m), phi (rad), xd, yd (m/s), phid (rad/s)" in doc


def test_dir_of_the_package_lists_the_api():
    assert {"load_scene", "simulate", "SimulationResult", "plot_comparison", "Model"} <= set(dir(apexseal))


@pytest.mark.parametrize(("name", "module"), [
    ("SceneError", "apexseal.runtime.scenes.errors"), ("SettingsError", "apexseal.runtime.solving.settings"),
    ("PreloadStudyError", "apexseal.runtime.studies.preload.problem"),
    ("StudyError", "apexseal.runtime.studies.sweep.study"), ("SchedulerError", "apexseal.runtime.studies.sweep.execute"),
    ("ResultFolderError", "apexseal.runtime.results.reading"),
    ("ResultStorageError", "apexseal.runtime.results.folder")])
def test_the_exceptions_a_user_catches_are_the_package_s(name, module):
    """Before, only SceneError was: ``except apexseal.SettingsError`` was an AttributeError, and a user had to find
    the module that defines each."""
    import importlib

    assert getattr(apexseal, name) is getattr(importlib.import_module(module), name)
    assert name in apexseal.__all__ and name in dir(apexseal) and issubclass(getattr(apexseal, name), Exception)
    assert name in apexseal.__doc__


def test_xarray_has_units_and_meanings_and_round_trips_through_netcdf(result, tmp_path):
    ds = result.to_xarray()
    assert ds["x"].dims == ("theta",) and ds["time"].attrs["units"] == "s"
    for name, var in ds.data_vars.items():
        assert var.attrs.get("long_name"), name
        if name != "mode" and not name.startswith(("closed_", "events_")):
            assert var.attrs["units"] == describe(name).unit, name
    assert ds.attrs["scene_hash"] == result.scene.content_hash()
    import xarray as xr

    ds.to_netcdf(tmp_path / "r.nc", engine="scipy")
    with xr.open_dataset(tmp_path / "r.nc", engine="scipy") as back:
        assert np.array_equal(back["y"].values, result.state[1])
        assert back["Pf_total"].attrs["units"] == "W"


def test_pandas_has_every_column_with_units(result):
    df = result.to_pandas()
    assert df.index.name == "theta_deg" and len(df) == result.n
    assert np.array_equal(df["phi"].to_numpy(), result.state[2])
    assert df.attrs["units"]["x"] == "m" and df.attrs["units"]["Pf_total"] == "W"
    assert set(df.columns) == {*(c for c in documented_names() if c != "theta_deg")}


def test_event_list_accounts_for_every_switch(result):
    ev = result.event_list()
    assert list(ev.columns) == ["theta_deg", "time_s", "contact", "direction", "switches"]
    assert ev["switches"].sum() == result.n_events > 0
    assert (np.diff(ev["theta_deg"]) >= 0).all()
    for _, row in ev[ev["switches"] == 1].iterrows():  # a single switch: the contact state after it matches
        i = result.guard_names.index(row["contact"])
        k = int(np.searchsorted(np.degrees(result.theta), row["theta_deg"]))
        assert bool(result.closed[i, k]) == (row["direction"] == "closes")
    assert set(ev["direction"]) <= {"closes", "opens", "closes+opens", "opens+closes"}


@pytest.mark.parametrize("method", ["erk", pytest.param("cvodes", marks=pytest.mark.slow)])  # cvodes: 9 s
def test_solver_statistics_for_every_method(default_scene, default_functions, method, result):
    """erk's statistics were empty: a compiled integrator reports none, so calls and events are counted."""
    r = result if method == "erk" else apexseal.simulate(default_scene, method=method, samples_per_revolution=90,
                                                         rtol=1e-7, functions=default_functions.sx)
    stats = r.solver_stats
    assert stats["n_engine_calls"] >= 1
    assert stats["n_events"] == r.n_events > 0


def test_summary_is_public(result):
    s = result.summary()
    assert s["status"] == "completed" and s["events_total"] == result.n_events
    assert s["housing_force_spectrum_peaks"]


def test_means_are_of_the_computed_samples_and_the_spectrum_gives_amplitudes(result):
    """The run's means leave the start sample out (each later sample ends a computed interval), and the housing
    force spectrum reads a sine's amplitude, not half of it (both survived a mutation of the code before)."""
    from apexseal.runtime.results.result import run_mean
    from apexseal.runtime.results.spectra import spectrum

    assert run_mean(np.array([100.0, 1.0, 3.0])) == 2.0 and np.isnan(run_mean(np.array([5.0])))
    pf = result.outputs["Pf_total"]
    assert pf[0] != pf[1:].mean()  # a start sample that would move the mean if it were counted
    assert result.summary()["mean_friction_power_W"]["total"] == pytest.approx(pf[1:].mean(), rel=1e-12)
    n, dt, w0 = 4096, 1e-4, 2 * np.pi * 64 / (4096 * 1e-4)  # 64 periods: w0 on a bin
    t = np.arange(n) * dt
    w, amp = spectrum(3.0 * np.sin(w0 * t) + 7.0, dt)
    assert w[np.argmax(amp)] == pytest.approx(w0) and amp.max() == pytest.approx(3.0, rel=1e-3)


def test_the_summary_places_extremes_and_weighs_modes_over_the_computed_samples(result):
    """Each extreme's angle is a sample holding that extreme, and the time in each mode is counted over the samples
    after the start (a min_at_deg taken at the maximum and a start sample counted in went unnoticed)."""
    s = result.summary()
    deg = np.degrees(result.theta) % 360
    for i, (name, scale) in enumerate((("x", 1e6), ("y", 1e6), ("phi", 1e3))):
        v, ext = result.state[i] * scale, s["extremes"][name]
        assert v[np.isclose(deg, ext["min_at_deg"], atol=1e-9)].min() == ext["min"] == v.min()
        assert v[np.isclose(deg, ext["max_at_deg"], atol=1e-9)].max() == ext["max"] == v.max()
    later = np.array(result.modes[1:])
    assert s["mode_fraction"] == pytest.approx({m: float(np.mean(later == m)) for m in set(later)})


def test_contact_patterns_tell_every_combination_apart():
    """The packed codes of the closed flags are distinct for every combination (a product in place of the shift
    made patterns collide, and samples took other modes' labels)."""
    from apexseal.runtime.results.assemble import contact_patterns

    closed = np.array(list(itertools.product([0, 1], repeat=5)), bool).T  # every pattern of 5 contacts
    patterns, which = contact_patterns(closed[:, ::-1])
    assert patterns.shape == (5, 32) and np.array_equal(patterns[:, which], closed[:, ::-1])


def test_an_event_angle_is_where_the_gap_interpolates_to_zero(result):
    """An interval with one switch puts its event where the contact's gap, linear between the two samples, is zero
    (the other end of the interval went unnoticed)."""
    from apexseal.derive.submodels.registry import guards

    gap_of = {g.name: g.output for g in guards()}
    events = result.event_list()
    deg = np.degrees(result.theta)
    checked = 0
    for row in events[events["switches"] == 1].itertuples():
        gap = result.outputs[gap_of[row.contact]]
        k = int(np.searchsorted(deg, row.theta_deg)) - 1
        if 0 <= k < len(deg) - 1 and gap[k] != gap[k + 1] and deg[k] < row.theta_deg < deg[k + 1]:
            at = np.interp(row.theta_deg, deg[k:k + 2], gap[k:k + 2])
            assert abs(at) <= 1e-9 * max(abs(gap[k]), abs(gap[k + 1]))
            checked += 1
    assert checked > 0  # (3 such intervals in this run: most hold several switches)


def test_plots_return_figures_and_leave_the_backend_alone(result):
    import matplotlib.pyplot as plt

    backend, figs_before = matplotlib.get_backend(), plt.get_fignums()
    from matplotlib.figure import Figure

    assert isinstance(result.plot(), Figure)
    many = result.plot("fig12", "fig13", "fig14", "modes")
    assert len(many) == 4 and all(isinstance(f, Figure) for f in many)
    q = result.plot("x", "Pf_total")
    assert len(q.axes) == 2 and q.axes[1].get_ylabel() == "Pf_total (W)"
    assert matplotlib.get_backend() == backend and plt.get_fignums() == figs_before
    with pytest.raises(ValueError, match="did you mean 'Pf_total'"):
        result.plot("Pf_totl")


def _drawn(fig):
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig).draw()
    return fig


def _boxes(fig, artists):
    renderer = fig.canvas.get_renderer()  # an Agg canvas (FigureCanvasAgg), attached by _drawn
    return [a.get_window_extent(renderer) for a in artists if a.get_visible() and a.get_text()]


def test_fig12_labels_do_not_overlap_and_the_legend_names_both_ports(result):
    fig = _drawn(result.plot("fig12"))
    for ax in fig.axes:
        lo, hi = ax.get_ylim()
        shown = [t for t, v in zip(ax.yaxis.get_ticklabels(), ax.yaxis.get_ticklocs(), strict=True) if lo <= v <= hi]
        labels = _boxes(fig, shown)
        assert len(labels) <= 5
        assert not any(a.overlaps(b) for a, b in itertools.combinations(labels, 2)), ax.get_title()
    title = _boxes(fig, [fig._suptitle])[0]
    assert not any(title.overlaps(b) for b in _boxes(fig, [ax.title for ax in fig.axes]))
    for ax in fig.axes:  # each panel's title, placed at a given height, clears its angle labels (the 90 deg one)
        head = _boxes(fig, [ax.title])[0]
        assert not any(head.overlaps(b) for b in _boxes(fig, ax.xaxis.get_ticklabels())), ax.get_title()
    legend = fig.legends[0]
    assert {t.get_text() for t in legend.get_texts()} >= {"inlet port", "outlet port", "zero"}
    box, page = legend.get_window_extent(fig.canvas.get_renderer()), fig.bbox
    assert page.x0 <= box.x0 and box.x1 <= page.x1 and page.y0 <= box.y0 and box.y1 <= page.y1


def _port_centres_deg(fig) -> dict[str, float]:
    """The centre of each shaded port of Fig. 12's first panel, in degrees on its crank-angle axis."""
    ax = fig.axes[0]
    return {p.get_label().removesuffix(" port"): np.degrees(p.get_x() + p.get_width() / 2) for p in ax.patches}


def test_fig12_shades_the_ports_where_the_seal_passes_them(default_scene, default_functions):
    """Fig. 12's angle counts from the scene's start angle (as ``theta`` does), but the ports were shaded at their
    Table 1 angle: with ``operation.start_angle = 90 deg`` the seal's crossing of the groove (at the chamber
    pressures' switch, a fixed crank angle) moved 90 deg against the ports, and ``machine.ports.datum`` was not
    added at all. The crossing now keeps its place against the ports, and the datum turns them."""
    runs = {}
    for start in ("0 deg", "90 deg"):
        scene = default_scene.with_overrides(**{"operation.start_angle": start})
        run = apexseal.simulate(scene, samples_per_revolution=SAMPLES, flags="quick", functions=default_functions.sx)
        crossing = np.degrees(run.theta[np.argmin(run.state[1])])  # onto the negative wall, once a revolution
        runs[start] = crossing - _port_centres_deg(run.plot("fig12"))["inlet"]
    assert (runs["90 deg"] - runs["0 deg"] + 180) % 360 - 180 == pytest.approx(0, abs=1)  # one sample: 1 deg
    turned = default_scene.with_overrides(**{"machine.ports.datum": "10 deg"})
    for name, port in ports_of(turned).items():
        assert port["angle_deg"] == pytest.approx(ports_of(default_scene)[name]["angle_deg"] + 10)


def test_fig12_shows_negative_values_off_the_centre(result):
    """Negative displacements folded through the centre of the polar plot; now the radius starts below them."""
    fig = result.plot("fig12")
    ax = fig.axes[1]  # y, which goes negative
    assert result.state[1].min() < 0
    assert ax.get_rorigin() < ax.get_rmin() <= result.state[1].min() * 1e6


@pytest.mark.filterwarnings("ignore::apexseal.runtime.results.plausibility.PenetrationWarning")
def test_fig14_uses_log_axes_and_marks_distinct_peaks(soft_scene, default_functions):
    """A 1.5e4 rad/s peak sat in the left 5 % of a linear axis up to 2.8e5 rad/s.

    On the soft-contacts scene, whose groove mode gives that peak (on the metal default, the contact peaks lie near
    the Nyquist frequency at these samples)."""
    result = apexseal.simulate(soft_scene, samples_per_revolution=SAMPLES, flags="quick", rtol=1e-8,
                               functions=default_functions.sx)
    fig = result.plot("fig14")
    ax = fig.axes[0]
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
    peaks = result.summary()["housing_force_spectrum_peaks"]
    lo, hi = ax.get_xlim()
    main = max(peaks, key=lambda p: p["amplitude_N"] if p["omega_rad_s"] > 1e3 else 0)["omega_rad_s"]
    assert 0.2 < np.log(main / lo) / np.log(hi / lo) < 0.9


def test_spectral_peaks_list_a_rippled_hump_once():
    """Side lobes (ripples) on one hump were listed as separate peaks."""
    from apexseal.runtime.results.spectra import spectral_peaks

    w = np.linspace(0, 1e5, 4001)
    hump = 7 * np.exp(-(((w - 1.5e4) / 3e3) ** 2)) * (1 + 0.08 * np.sin(w / 300))
    other = 2 * np.exp(-(((w - 6e4) / 2e3) ** 2))
    peaks = spectral_peaks(w, hump + other + 0.01)
    assert len(peaks) == 2
    assert abs(peaks[0]["omega_rad_s"] - 1.5e4) < 1.5e3 and abs(peaks[1]["omega_rad_s"] - 6e4) < 1e3


def test_comparison_plot_of_two_results(result, default_scene, default_functions):
    other = apexseal.simulate(default_scene.with_overrides(**{"spring.ks": "2e4 N/m"}), samples_per_revolution=SAMPLES,
                              flags="quick", rtol=1e-8, functions=default_functions.sx)
    fig = apexseal.plot_comparison([result, other], ["y", "Pf_total"], labels=["a", "b"])
    assert len(fig.axes) == 2 and all(len(ax.lines) == 2 for ax in fig.axes)
    assert [t.get_text() for t in fig.legends[0].get_texts()] == ["a", "b"]


def test_saved_result_records_its_scene_and_no_machine_path(result, tmp_path):
    """result.json named the scene by an absolute path and nothing else."""
    import os

    folder = result.save(tmp_path / "run")
    back = SimulationResult.load(folder)
    assert back.scene is not None and back.scene.content_hash() == result.scene.content_hash()
    assert back.scene.solver.samples_per_revolution == SAMPLES  # the run's settings are in the scene
    info = json.loads((folder / "result.json").read_text())["info"]
    assert info["scene_hash"] == result.scene.content_hash() and len(info["model_hash"]) == 64
    assert {"apexseal", "casadi", "numpy"} <= set(info["versions"])
    for f in folder.iterdir():
        if f.suffix in (".json", ".toml", ".csv"):
            text = f.read_text()
            for path in (str(tmp_path), os.getcwd(), str(apexseal.__file__).rsplit("/", 3)[0]):
                assert path not in text, (f.name, path)


def test_output_columns_are_documented_and_the_csv_header_carries_units(result, tmp_path):

    doc = (REPO / "docs" / "outputs.md").read_text()
    assert markdown_table() in doc, "docs/outputs.md is stale: paste runtime.results.outputs.markdown_table()"
    result.save(tmp_path / "r", csv=True)
    first = (tmp_path / "r" / "trajectory.csv").read_text().splitlines()[1].split(",")  # after the run-id line
    assert first == header(documented_names())


def test_the_seal_s_displacement_columns_name_the_groove_frame_of_eq10():
    """x and y are the coordinates of the centre of gravity in the groove frame (Eq. 10: rc = x X̂ + y Ŷ), the frame
    the seal body declares its states in; the seal frame's axes Xs, Ys (Eq. 11) turn with phi and are not what x
    and y measure."""
    from apexseal.derive.submodels.seal import SealBody

    declared = {s.name: s.meaning for s in SealBody.states}
    for name, axis in (("x", "X"), ("y", "Y")):
        assert f"{axis}g" in declared[name]  # the seal body: along Xg, Yg
        meaning = describe(name).meaning
        assert "groove frame" in meaning and f"{axis}s" not in meaning, (name, meaning)


def test_the_state_columns_cite_the_equations_that_introduce_them():
    """phi cited Eq. 10 (rc = x X̂ + y Ŷ), but the paper introduces the seal's rotation with Eq. 11 (the seal frame
    turned by phi); theta cited Eq. 1 (the sliding s = 2 r sin theta), while theta is defined in the text of
    Section 2 with Fig. 1."""
    assert "Eq. 10)" in describe("x").meaning and "Eq. 10)" in describe("y").meaning
    assert "(Eq. 11)" in describe("phi").meaning
    assert "Section 2, Fig. 1" in describe("theta_deg").meaning and "Eq. 1)" not in describe("theta_deg").meaning


def test_the_recorded_pressures_are_the_scene_s_at_each_sample(result, default_scene):
    """With linear pressures (the default) each sample records the scene's chamber pressures at its own crank angle
    (values lagging one interval behind went unnoticed: runs at two output densities lag alike)."""
    at = default_scene.operation.start_angle + result.theta
    np.testing.assert_allclose(result.outputs["Pa"], default_scene.pressure.Pa(at), rtol=1e-12)
    np.testing.assert_allclose(result.outputs["Pb"], default_scene.pressure.Pb(at), rtol=1e-12)
    assert np.ptp(result.outputs["Pa"]) > 1e5  # a table that varies


def test_a_summary_holds_no_nan_but_null_as_json_has_no_nan():
    """A gas run with closed ports wrote "leaked_fraction_of_inducted": NaN, which strict JSON parsers refuse."""
    import json

    from apexseal.runtime.results.folder import _finite

    assert _finite({"a": float("nan"), "b": [1.0, float("inf")], "c": {"d": np.float64("nan"), "e": 2}}) == \
        {"a": None, "b": [1.0, None], "c": {"d": None, "e": 2}}

    def refuse(name):
        raise ValueError(f"{name} is no JSON")

    json.loads((REPO / "docs" / "results" / "summary.json").read_text(), parse_constant=refuse)


def test_the_columns_handed_out_cannot_change_the_result(result):
    """``x = r.column("x"); x *= 1e6`` (SI to µm for a plot) and ``ds["y"] *= 1e6`` changed the result's own arrays:
    its summary gave a 213792 µm extreme and its saved folder kept it. column() is read-only now, to_xarray() a
    copy; the summary is unchanged by either."""
    before = result.summary()["extremes"]
    x = result.column("x")
    with pytest.raises(ValueError, match="read-only"):
        x *= 1e6
    scaled = result.column("x") * 1e6  # the way that works: a new array
    assert scaled.max() == pytest.approx(1e6 * result.state[0].max())
    ds = result.to_xarray()
    ds["y"] *= 1e6
    assert result.summary()["extremes"] == before


def test_whole_degrees_of_the_pandas_index_are_whole(result):
    """``df.loc[183.0]`` was a KeyError: the index held 183.00000000000003 (radians' rounding)."""
    df = result.to_pandas()
    whole = [d for d in range(361) if d in set(np.round(df.index.to_numpy()))]
    assert whole and all(float(d) in df.index for d in whole)


@pytest.mark.slow  # 7 s of a 2-core test process: in the second step, to keep the default suite under 10 min
def test_runs_leave_no_thread_behind(default_scene, default_functions):
    """Each run defined its progress bar's class anew, and tqdm started a monitor thread per class: 300 runs in a
    notebook left 300 threads."""
    import threading

    apexseal.simulate(default_scene, functions=default_functions.sx, samples_per_revolution=72)
    before = threading.active_count()
    for _ in range(3):
        apexseal.simulate(default_scene, functions=default_functions.sx, samples_per_revolution=72)
    assert threading.active_count() == before


def test_plot_comparison_takes_quantities_by_that_name_and_names_the_result_without_one(result):
    """plot_comparison's keyword was ``quantities_`` (``quantities=["y"]`` a TypeError), and a column one result
    lacks (its spring off) was reported as a typo ("did you mean 'F_housing_X'?") without saying which result."""
    from dataclasses import replace

    from apexseal.runtime.results.plots import plot_comparison

    fig = plot_comparison([result, result], quantities=["y"], labels=["a", "b"])
    assert len(fig.axes) == 1
    springless = replace(result, outputs={k: v for k, v in result.outputs.items() if k != "F_spring_X"})
    with pytest.raises(ValueError, match="'F_spring_X' of result 'nospring': the other results have it") as info:
        plot_comparison([result, springless], quantities=["F_spring_X"], labels=["a", "nospring"])
    assert "did you mean" not in str(info.value)


def test_the_run_settings_and_their_ranges_are_public():
    """help(apexseal.simulate) named RunSettings for the settings' ranges, but apexseal.RunSettings did not exist and
    its docstring said "see the module docstring": it is public, and its docstring lists every range of LIMITS."""
    from apexseal.runtime.solving.settings import LIMITS, RunSettings

    assert apexseal.RunSettings is RunSettings and "RunSettings" in apexseal.__all__ and "RunSettings" in apexseal.__doc__
    from apexseal.runtime.solving.settings import SETTING_UNITS

    for name, (_, rng) in LIMITS.items():
        assert f"``{name}``: " in RunSettings.__doc__, name
        assert rng.describe(SETTING_UNITS.get(name, "")) in RunSettings.__doc__, name
    assert "``max_wall_time``: float, 0 < value <= 1e+07 s or None" in RunSettings.__doc__
