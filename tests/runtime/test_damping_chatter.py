"""Contacts damped above critical: approach-only damping makes them chatter (runtime/scenes/damping.py).

The scene warns about such a damping ratio before a run, and a run that chatters on such a contact advises less
damping, with the key and the coefficient it may reach (the advice used to ask for more contact damping, which
makes it worse), or the damping law "penetration" (assumptions.damping_law), whose dampers start from 0 at the
touch: under it the same contacts complete. ``python tests/runtime/test_damping_chatter.py``: the table of
docs/hard-cases.md.
"""

from __future__ import annotations

import math
import warnings

import pytest
from hard_helpers import load

import apexseal
from apexseal.derive.numbers import damping_of_ratio
from apexseal.runtime.scenes.units import PlausibilityWarning

#: a housing damping ratio in the chatter regime of the default scene (the table below: it chatters from ~2.4)
HIGH = 3.0
#: the damping law continuous at the touch (assumptions.damping_law)
PENETRATION = {"assumptions.damping_law": "penetration"}


def _quietly(scene, **overrides):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlausibilityWarning)
        return scene.with_overrides(**overrides)


def _critical(scene) -> float:
    """The housing's critical damping coefficient, 2 sqrt(kw ms)."""
    return damping_of_ratio(1.0, scene.parameters["kw"], scene.parameters["ms"])


# ---------------------------------------------------------------- the advice of a run that chatters
@pytest.mark.parametrize("detector", [{}, {"samples_per_revolution": 36, "max_events_per_revolution": 100}],
                         ids=["switches-per-interval", "integrator-event-limit"])
def test_a_tip_damped_above_critical_is_advised_less_damping(default_scene, default_functions, detector):
    """zeta_w = 3 chatters on the tip within 2 deg; the advice names the ratio and says lower it (to 1, the
    coefficient that gives), not 'more contact damping'. Both detectors: the switches per output interval, and the
    integrator's own event limit (diagnosed by re-running the interval)."""
    scene = _quietly(default_scene, **{"contacts.zeta_w": HIGH})
    r = apexseal.simulate(scene, revolutions=1, functions=default_functions.c, **detector)
    assert r.status == "chattering" and "chattering on guard xs5" in r.stop.reason, r.stop
    reason = r.stop.reason
    assert f"contacts.zeta_w = {HIGH:g}" in reason and "lower contacts.zeta_w to 1 or less" in reason
    assert f"contacts.cw <= {_critical(default_scene):.4g} N*s/m" in reason
    assert "more damping makes it worse" in reason and "more contact damping" not in reason
    assert "assumptions.damping_law = 'penetration' damps in proportion to the penetration" in reason


@pytest.mark.slow  # 15 s of a 2-core test process: in the second step, to keep the default suite under 10 min
def test_a_tip_damped_above_critical_completes_under_the_penetration_law(default_scene, default_functions):
    """The same zeta_w = 3 that chatters on the tip within 2 deg under the paper's dampers completes two revolutions
    under the damping law "penetration" (the dampers start from 0 at the touch), with a few tip switches."""
    paper = apexseal.simulate(_quietly(default_scene, **{"contacts.zeta_w": HIGH}), revolutions=2,
                              samples_per_revolution=360, functions=default_functions.c)
    assert paper.status == "chattering" and "chattering on guard xs5" in paper.stop.reason, paper.stop
    law = apexseal.simulate(_quietly(default_scene, **{"contacts.zeta_w": HIGH, **PENETRATION}), revolutions=2,
                            samples_per_revolution=360)
    assert law.status == "completed" and math.degrees(law.theta[-1]) == pytest.approx(720.0), law.stop
    assert 0 < law.events[law.guard_names.index("xs5"), -1] < 100


@pytest.mark.filterwarnings("ignore::apexseal.runtime.results.plausibility.PenetrationWarning")  # soft by design
def test_an_undamped_tip_is_advised_damping_toward_the_default(default_functions):
    """tip-chatter (cw = 0) ends at its event budget per revolution (checked after each of 72 calls: one call
    would end at the integrator's event limit, slower to diagnose): damping toward the default ratio, named."""
    r = apexseal.simulate(load("tip-chatter"), revolutions=1, functions=default_functions.c,
                          samples_per_revolution=72, calls_per_revolution=72)
    assert r.status == "chattering" and "in less than one revolution" in r.stop.reason, r.stop
    assert "more damping on this contact, toward the default ratio" in r.stop.reason
    assert ("the housing contact's damping: contacts.zeta_w = 0, i.e. contacts.cw = 0 N*s/m, the default ratio 0.1"
            in r.stop.reason)
    assert "lower contacts.zeta_w" not in r.stop.reason


def test_the_advice_follows_the_chattering_contacts_damping(default_scene):
    """Below critical but above the default: less damping (a stiff contact under light loads chatters from there
    too); at the default: no damping advice; a groove guard: the groove's cr and zeta_g; an unknown guard or no
    parameters: the general advice."""
    from apexseal.runtime.solving.checks import CHATTER_ADVICE, chatter_advice

    p = dict(default_scene.parameters)

    def advice(guard, **changed):
        values = p | changed
        return chatter_advice(guard, tuple(values), list(values.values()))

    half = advice("xs5", cw=0.5 * _critical(default_scene))
    assert "less damping on this contact, toward the default ratio" in half and "contacts.zeta_w = 0.5" in half
    at_default = advice("xs5")
    assert "contacts.zeta_w = 0.1" in at_default and "damping on this contact" not in at_default
    groove_default = advice("b3")  # the parenthesis used to list two keys without saying what they were
    assert f"(the groove contact's damping: contacts.zeta_g = 0.1, i.e. contacts.cr = {p['cr']:.4g} N*s/m)" in groove_default
    groove = advice("b3", cr=2.0 * p["cr"] / 0.1)
    assert "contacts.zeta_g = 2" in groove and "lower contacts.zeta_g to 1 or less" in groove
    assert "damping_law = 'penetration'" in groove
    assert advice("nonesuch") == chatter_advice("xs5") == CHATTER_ADVICE
    spring = advice("spring", cs=3.0 * _critical(default_scene) * p["cs"] / p["cw"])  # the spring keeps its law
    assert "lower contacts.zeta_s to 1 or less" in spring and "damping_law" not in spring


def test_under_the_penetration_law_a_high_ratio_is_no_cause_of_chatter(default_scene):
    """Its dampers start from 0 at the touch: a ratio above critical is not advised lower (the jump it would cause
    is gone), nor is the law suggested again; too little damping is still advised more."""
    from apexseal.runtime.solving.checks import chatter_advice

    p = dict(_quietly(default_scene, **PENETRATION).parameters)

    def advice(guard, **changed):
        values = p | changed
        return chatter_advice(guard, tuple(values), list(values.values()))

    high = advice("xs5", cw=HIGH * _critical(default_scene))
    assert "contacts.zeta_w = 3" in high and "continuous at the touch" in high
    assert "lower contacts.zeta_w" not in high and "less damping" not in high and "damping_law" not in high
    assert "more damping on this contact" in advice("b1", cr=0.0)


# ---------------------------------------------------------------- the scene's warning before a run
def test_a_damping_ratio_above_critical_warns_with_key_value_and_range(default_scene):
    """Above 1 it warns, naming the key, the value and the plausible range; critical damping itself and a damping
    whose effect is off (no law reads it) do not."""
    with pytest.warns(PlausibilityWarning, match=r"contacts\.zeta_w = 3: a damping ratio above critical .*"
                                                 r"approach only.*plausible: 0 <= zeta_w <= 1"):
        default_scene.with_overrides(**{"contacts.zeta_w": 3})
    with pytest.warns(PlausibilityWarning, match=r"contacts\.zeta_g = 1\.5: .*plausible: 0 <= zeta_g <= 1"):
        default_scene.with_overrides(**{"contacts.zeta_g": 1.5})
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        assert math.isclose(default_scene.with_overrides(**{"contacts.zeta_w": 1.0}).parameters["cw"],
                            _critical(default_scene))
        off = default_scene.with_overrides(**{"contacts.zeta_w": HIGH, "effects.housing_damping": False})
    assert "cw" not in off.parameters


def test_under_the_penetration_law_a_ratio_above_critical_warns_only_for_the_spring(default_scene):
    """The housing and groove dampers start from 0 at the touch under the damping law "penetration": their ratios
    above critical no longer warn; the preloaded spring keeps the paper's damper and its warning, which names no
    damping law (none applies to it). Under the paper's law the warning names the law that removes the jump."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        default_scene.with_overrides(**{"contacts.zeta_w": HIGH, "contacts.zeta_g": HIGH, **PENETRATION})
    with pytest.warns(PlausibilityWarning) as record:
        default_scene.with_overrides(**{"contacts.zeta_s": HIGH, **PENETRATION})
    (spring,) = [str(w.message) for w in record]
    assert "contacts.zeta_s = 3.0: a damping ratio above critical" in spring and "damping_law" not in spring
    with pytest.warns(PlausibilityWarning, match=r"contacts\.zeta_w = 3\.0: .*assumptions\.damping_law = 'penetration'"):
        default_scene.with_overrides(**{"contacts.zeta_w": HIGH})


def test_a_coefficient_above_critical_warns_with_its_ratio(default_scene):
    """A scene that gives the coefficient is told its ratio and the largest coefficient, against contacts.cw."""
    critical = _critical(default_scene)
    with pytest.warns(PlausibilityWarning) as record:
        default_scene.with_overrides(**{"contacts.cw": 3e4})
    message = "\n".join(str(w.message) for w in record)
    assert f"contacts.cw = 30000.0: 3e+04 N*s/m is {3e4 / critical:.3g} times critical damping" in message
    assert f"plausible: 0 <= cw <= {critical:.4g} N*s/m (contacts.zeta_w <= 1)" in message


# ---------------------------------------------------------------- explicit Euler under the penetration law
def test_explicit_euler_counts_no_damper_that_vanishes_at_the_touch(default_scene, monkeypatch):
    """Under the damping law "penetration" the housing and groove dampers vanish at the touch and exceed critical
    damping many times over at depth (c delta / delta_ref), so the stability check counts on none of them (the
    spring's stays). It was counting them as the paper's: at 120000 steps per revolution it passed the model with
    delta_ref = 10 nm, whose run then went non-finite within the revolution; the paper's law runs there."""
    from apexseal.runtime.solving import preflight
    from apexseal.runtime.solving.contact_stability import contact_growth

    steps = 120000
    euler = {"solver.method": "euler", "solver.euler_steps_per_revolution": steps}
    law = default_scene.with_overrides(**euler, **PENETRATION, **{"contacts.delta_ref": "10 nm"})
    growth = {g.name: g for g in contact_growth(law.parameter_vector(), steps, tuple(law.parameters))}
    assert growth["kw"].zeta == growth["kg1"].zeta == 0 and growth["ks"].zeta > 0
    assert growth["kw"].steps_needed > 10 * steps
    refused = apexseal.simulate(law, revolutions=1, samples_per_revolution=360)
    assert refused.status == "failed" and refused.n == 1, refused.stop
    assert "amplifies the ringing of the seal in contact mode" in refused.stop.reason
    assert ("counting no damper that vanishes at the touch under assumptions.damping_law = 'penetration'"
            in refused.stop.reason)
    monkeypatch.setattr(preflight, "MAX_GROWTH", math.inf)  # what the check's old verdict let run
    blown = apexseal.simulate(law, revolutions=1, samples_per_revolution=360)
    assert blown.status == "failed" and "non-finite state" in blown.stop.reason, blown.stop
    paper = apexseal.simulate(default_scene.with_overrides(**euler), revolutions=1, samples_per_revolution=360)
    assert paper.status == "completed", paper.stop


def test_the_stability_message_says_why_a_penetration_damper_counts_as_none(default_scene):
    """The contact check names the contact's damping ratio: under the damping law "penetration" it said "damping
    ratio 0 on average" of the tip of a scene whose contacts.zeta_w is 0.1, without a word of why; it says that the
    damper vanishes at the touch under that law. The spring's damper, which keeps the paper's law, and the paper's
    law itself are named by their ratio as before."""
    from apexseal.runtime.solving.contact_stability import contact_growth

    def messages(scene) -> dict[str, str]:
        return {g.name: g.describe() for g in contact_growth(scene.parameter_vector(), 200000, tuple(scene.parameters))}

    law, paper = messages(default_scene.with_overrides(**PENETRATION)), messages(default_scene)
    assert "damping ratio 0 on average" not in law["kw"] and "damping ratio 0 on average" not in law["kg1"]
    assert "undamped: under assumptions.damping_law = 'penetration' its damper vanishes at the touch" in law["kw"]
    for text in (law["ks"], paper["kw"], paper["ks"]):
        assert "damping ratio 0.05 on average" in text and "damping_law" not in text


def damping_table(ratios=(0.1, 1.0, 2.0, 2.2, 2.4, 3.0, 5.0), laws=("velocity", "penetration"),
                  revolutions: int = 2) -> str:
    """The default scene with each housing damping ratio under each damping law: how far it runs, how often the
    contacts switch, and (for a run that completes) its mean friction power, largest housing force and deepest
    penetration of any contact."""
    scene = apexseal.load_scene()
    rows = ["| assumptions.damping_law | contacts.zeta_w | status | crank angle reached | tip (xs5) switches "
            "| all switches | mean friction power | largest housing force | deepest penetration |",
            "|---|---|---|---|---|---|---|---|---|"]
    for law in laws:
        for zeta in ratios:
            s = _quietly(scene, **{"contacts.zeta_w": zeta, "assumptions.damping_law": law})
            r = apexseal.simulate(s, revolutions=revolutions)
            tip = int(r.events[r.guard_names.index("xs5"), -1])
            row = f"| {law} | {zeta:g} | {r.status} | {math.degrees(r.theta[-1]):.1f} deg | {tip} | {r.n_events} |"
            if r.status != "completed":
                rows.append(row + " – | – | – |")
                continue
            summary = r.summary()
            deepest = max(summary["plausibility"]["penetration_um"].values())
            rows.append(row + f" {summary['mean_friction_power_W']['total']:.2f} W | "
                              f"{summary['housing_force_N']['max']:.0f} N | {deepest:.2f} µm |")
    return "\n".join(rows)


if __name__ == "__main__":  # python tests/runtime/test_damping_chatter.py: the table of hard-cases.md
    print(damping_table())


def test_the_advice_names_the_contact_from_the_submodel_that_declares_its_damping(default_scene, monkeypatch):
    """The advice named a damping by a hand-written table (cw: the housing contact's, cr: the groove's, cs: the
    spring's), so a user's contact was named wrongly or not at all: it now takes the declaring submodel's name."""
    from dataclasses import replace

    from apexseal.derive.submodels.registry import submodels
    from apexseal.runtime.scenes import damping
    from apexseal.runtime.solving import checks

    p = dict(default_scene.parameters)
    owners = {c: cls.name for cls in submodels() for c, _ in cls.damping_ratios}
    assert {c: d.owner for c, d in damping.contact_dampings(p).items()} == {c: owners[c] for c in
                                                                             damping.contact_dampings(p)}
    own = replace(damping.guard_damping("xs5", p), owner="vane")  # a user's submodel declaring this coefficient
    monkeypatch.setattr(checks, "guard_damping", lambda guard, values: own)
    text = checks.chatter_advice("xs5", tuple(p), list(p.values()))
    assert "(the vane contact's damping: contacts.zeta_w = " in text and "housing" not in text
