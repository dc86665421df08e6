"""A completed run close to the chatter limit is said, with the contact, where and how many switches
(runtime/solving/near_chatter.py)."""

from __future__ import annotations

import json
import warnings
from types import SimpleNamespace

import numpy as np
import pytest

import apexseal
from apexseal.runtime.results.summary import summarise
from apexseal.runtime.solving.checks import interval_limit
from apexseal.runtime.solving.near_chatter import NearChatterWarning, SwitchClusters

SAMPLES = 360  # the integrator of tests/runtime/test_simulate.py: compiled once per session
SETTINGS = SimpleNamespace(chatter_events=50, chatter_window=1e-3, max_events_per_revolution=10000)
DTH = np.radians(0.1)


def _counts(per_interval: np.ndarray, before: np.ndarray) -> np.ndarray:
    return before[:, None] + np.cumsum(per_interval, axis=1)


def test_a_cluster_across_two_calls_is_one_cluster_with_its_range_switches_and_peak():
    """A user's expander completed with 2888 switches of guard b3 in a few degrees, 70 % of the chatter detector's
    limit in one interval, and chattered at rtol 1e-8: nothing said how close it was. The densest cluster is kept
    across the integrator's calls (here split in the middle), with its crank angles, switches and peak."""
    per = np.zeros((2, 20))
    per[1, 8:14] = [1, 5, 20, 61, 30, 2]  # guard "b3": a cluster from interval 8 to 13
    per[0, 2] = 1  # a lone switch of the other guard
    thetas = DTH * np.arange(1, 21)
    watch = SwitchClusters(("xs5", "b3"), SETTINGS, omega=157.0, dth=DTH)
    before = np.zeros(2)
    for part in (slice(0, 11), slice(11, 20)):  # two calls, the cluster on their boundary
        counts = _counts(per[:, part], before)
        watch.add(before, counts, thetas[part], np.zeros(2))
        before = counts[:, -1]
    rec = watch.record()
    assert rec["guard"] == "b3" and rec["switches"] == 119 and rec["peak_per_interval"] == 61
    assert rec["from_deg"] == pytest.approx(0.8) and rec["to_deg"] == pytest.approx(1.4)
    assert rec["peak_at_deg"] == pytest.approx(1.2)
    assert rec["interval_limit"] == pytest.approx(interval_limit(SETTINGS, DTH, 157.0))
    assert rec["revolution_switches"] == 120 and rec["near"]  # 61 of 87.3 in one interval


def test_few_switches_are_not_near_and_a_run_without_switches_has_no_cluster():
    watch = SwitchClusters(("b3",), SETTINGS, omega=157.0, dth=DTH)
    assert watch.record() is None
    watch.add(np.zeros(1), np.array([[0.0, 3.0, 3.0]]), DTH * np.arange(1, 4), np.zeros(1))
    assert watch.record()["near"] is False


@pytest.mark.slow  # 6 s of a 2-core test process: in the second step, to keep the default suite under 10 min
def test_a_completed_run_near_the_event_budget_warns_naming_the_contact_and_records_it(default_scene,
                                                                                        default_functions):
    """The default scene with max_events_per_revolution just above its own switches completes, and now says that it
    was close to the limit (a warning from simulate, the cluster in summary.json); with the default budget it says
    nothing."""
    def run(**settings):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            r = apexseal.simulate(default_scene, samples_per_revolution=SAMPLES, functions=default_functions.sx,
                                  **settings)
        return r, [w for w in caught if issubclass(w.category, NearChatterWarning)]

    free, said = run()
    assert free.ok and not said and free.info["switch_cluster"]["near"] is False
    tight, said = run(max_events_per_revolution=free.n_events + 1)
    assert tight.ok and tight.n_events == free.n_events and len(said) == 1
    rec = json.loads(json.dumps(summarise(tight)))["run"]["switch_cluster"]
    assert rec["near"] and rec["revolution_switches"] == free.n_events
    text = str(said[0].message)
    for part in (f"guard {rec['guard']}", f"{rec['switches']} times", f"{rec['from_deg']:.1f}°",
                 "max_events_per_revolution", "close to the chatter limit", "event_list()"):
        assert part in text, (part, text)


def test_the_pivoting_corner_of_the_hard_scene_completes_and_says_it_is_close_to_the_limit(default_functions):
    """runtime/scenes/hard/pivot-near-chatter.toml (a user's expander: a seal corner pivoting on its groove wall)
    completed with thousands of switches of one groove gap in a few degrees and chattered at rtol 1e-8, and nothing
    said how close it was: now a revolution warns, naming that gap, where it switched and against which limit."""
    from hard_helpers import load, simulate

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = simulate(load("pivot-near-chatter"), default_functions.sx, samples_per_revolution=3600)  # its own
    said = [w for w in caught if issubclass(w.category, NearChatterWarning)]
    rec = r.info["switch_cluster"]
    assert r.status == "completed" and len(said) == 1 and rec["near"], rec
    assert rec["guard"] == "b3" and 280 < rec["from_deg"] < rec["to_deg"] < 300, rec
    assert rec["switches"] > 1000 and rec["peak_per_interval"] >= 0.5 * rec["interval_limit"], rec
    text = str(said[0].message)  # the guard with its contact and what it is, from the submodels' declarations
    assert "guard b3 (the groove contact i2: gap at g3" in text and f"switched {rec['switches']} times" in text


def test_the_note_names_the_guards_contact_as_the_chattering_message_does(monkeypatch):
    """The note named the guard with its contact's bare output prefix (``guard b3 (contact i2: ...)``), not as the
    chattering message names a contact (``the groove contact's damping``): it names the declaring submodel, and a
    user's contact by its own submodel's name."""
    from apexseal.derive.options import NONE, ON, Option
    from apexseal.derive.submodels import registry
    from apexseal.derive.submodels.base import Guard, Submodel
    from apexseal.runtime.solving.near_chatter import describe_near_chatter

    record = {"guard": "b3", "peak_per_interval": 30, "interval_limit": 40, "revolution_switches": 600,
              "max_events_per_revolution": 1000, "switches": 1200, "from_deg": 280.0, "to_deg": 300.0,
              "peak_at_deg": 290.0}
    assert "guard b3 (the groove contact i2: gap at g3" in describe_near_chatter(record)
    assert "guard xs5 (the housing contact: minus the tip's" in describe_near_chatter(record | {"guard": "xs5"})
    vane = type("Vane", (Submodel,), {"name": "vane", "__module__": "elsewhere", "switch": "vane",
                                      "options": (Option("vane", (NONE, ON), "a vane"),),
                                      "guards": (Guard("gv", "s_gv", "gap of the vane", output="vane_gap"),)})
    with registry.registered(vane):
        assert "guard gv (the vane contact: gap of the vane)" in describe_near_chatter(record | {"guard": "gv"})
