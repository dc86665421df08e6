"""The modelling choice assumptions.damping_law: the paper's contact dampers c max(v, 0) (Eqs. 55, 62, 67), which jump
from 0 to c v at the touch, or c max(v, 0) delta / delta_ref (Hunt-Crossley type, not in the paper), which starts
from 0 there; its parameter contacts.delta_ref is read under that choice only (derive/submodels/laws.py, seal.py)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import apexseal
from apexseal.derive import Effects, cached_model
from apexseal.derive.assumptions import Assumptions
from apexseal.derive.choices import Options
from apexseal.derive.parameters import Parameter
from apexseal.derive.submodels import registry
from apexseal.derive.submodels.base import Submodel
from apexseal.generated.functions import build_functions
from apexseal.runtime.scenes.errors import IgnoredValueWarning, SceneError
from apexseal.runtime.scenes.units import PlausibilityWarning

#: a crank angle, chamber pressures and a closing speed of the tip (m/s) at which the housing force is compared
THETA, U, XD = 0.3, np.array([3e5, 2e5]), 0.01


def _scene(law: str):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlausibilityWarning)
        return apexseal.load_scene().with_overrides(**{"contacts.zeta_w": 3, "assumptions.damping_law": law})


def _housing_force(law: str, depth: str) -> tuple[float, float]:
    """F_housing_X with every contact closed, the tip approaching the wall at XD with the penetration xs5 at 0
    ("touch") or at the default contacts.delta_ref ("ref"): (force, cw)."""
    scene = _scene(law)
    f = build_functions(cached_model(scene.effects, scene.assumptions))
    p = scene.parameter_vector(f.parameter_names)
    i = f.guard_names.index("xs5")

    def xs5(x: float) -> float:  # the guard is -xs5; xs5 is affine in the seal's x at fixed y, phi
        return -float(np.array(f.guards(THETA, np.array([x, 0, 0, 0, 0, 0.0]), p, U)).ravel()[i])

    target = 0.0 if depth == "touch" else registry.parameter("delta_ref").default
    x = (target - xs5(0.0)) * 1e-6 / (xs5(1e-6) - xs5(0.0))
    assert xs5(x) == pytest.approx(target, abs=1e-15)
    out = np.array(f.outputs(THETA, np.array([x, 0, 0, XD, 0, 0.0]), np.ones(len(f.guard_names)), p, U)).ravel()
    return float(out[f.output_names.index("F_housing_X")]), scene.parameters["cw"]


def test_the_penetration_law_starts_from_zero_at_the_touch_and_is_the_papers_at_delta_ref():
    """At the touch the paper's damper pushes c v at once and the penetration law nothing; at delta = delta_ref both
    give the elastic force plus c v (the same number)."""
    paper_touch, cw = _housing_force("velocity", "touch")
    law_touch, _ = _housing_force("penetration", "touch")
    assert paper_touch == pytest.approx(-cw * XD, rel=1e-9)  # the jump: c v with no penetration
    assert law_touch == 0.0
    paper_ref, _ = _housing_force("velocity", "ref")
    law_ref, _ = _housing_force("penetration", "ref")
    assert law_ref == pytest.approx(paper_ref, rel=1e-9) and abs(law_ref) > cw * XD


def test_the_housing_and_groove_dampers_read_delta_ref_and_the_spring_keeps_the_papers_law():
    """delta_ref enters the model under the choice; the preloaded spring (closed at rest) keeps c max(v, 0)."""
    paper = build_functions(cached_model(Effects(), Assumptions()))
    law = build_functions(cached_model(Effects(), Assumptions(damping_law="penetration")))
    assert "delta_ref" in law.parameters_read() and "delta_ref" not in paper.parameter_names
    for off in ({"housing_damping": "none", "groove_damping": "none"}, {"groove_damping": "none"},
                {"housing_damping": "none"}):
        # with the housing's or the groove's damping off, the other one still reads delta_ref
        one = build_functions(cached_model(Effects.from_mapping({k: False for k in off}),
                                           Assumptions(damping_law="penetration")))
        assert ("delta_ref" in one.parameters_read()) == (len(off) == 1)
    scene = _scene("penetration")
    p_law, p_paper = scene.parameter_vector(law.parameter_names), scene.parameter_vector(paper.parameter_names)
    x = np.array([1e-6, -1e-5, 2e-3, 0.02, -0.01, 5.0])
    a = np.ones(len(paper.guard_names))
    out_law = np.array(law.outputs(THETA, x, a, p_law, U)).ravel()
    out_paper = np.array(paper.outputs(THETA, x, a, p_paper, U)).ravel()
    spring = paper.output_names.index("F_spring_X")
    assert out_law[law.output_names.index("F_spring_X")] == out_paper[spring]
    housing = paper.output_names.index("F_housing_X")
    assert out_law[law.output_names.index("F_housing_X")] != out_paper[housing]


def test_delta_ref_is_read_only_under_its_choice(default_scene):
    """Under the default choice contacts.delta_ref has no slot, is unread (registry.is_read) and an out-of-range value
    only warns, naming the choice; under "penetration" it is read and range-checked as an error."""
    assert not registry.is_read("contacts.delta_ref", Effects())
    assert registry.is_read("delta_ref", Effects(), Assumptions(damping_law="penetration"))
    assert "delta_ref" not in registry.parameter_names()
    assert "delta_ref" in registry.parameter_names(opts=Options({"damping_law": "penetration"}))
    assert "delta_ref" not in default_scene.parameters
    with pytest.warns(IgnoredValueWarning, match=r"contacts\.delta_ref = -1\.0 \(not read while assumptions\."
                                                 r"damping_law is not 'penetration'; allowed: .*\); making the "
                                                 r"choice makes it an error"):
        default_scene.with_overrides(**{"contacts.delta_ref": -1.0})
    with pytest.raises(SceneError, match=r"contacts\.delta_ref = -1\.0: .* out of range; allowed: 0 < value"):
        default_scene.with_overrides(**{"contacts.delta_ref": -1.0, "assumptions.damping_law": "penetration"})
    law = default_scene.with_overrides(**{"assumptions.damping_law": "penetration", "contacts.delta_ref": "10 nm"})
    assert law.parameters["delta_ref"] == pytest.approx(1e-8)


def test_a_parameter_may_need_a_modelling_choice_with_a_default_only():
    """needs = "slot=choice" names a choice of [assumptions]; an unknown one, or such a parameter without a default
    (a scene making the choice need not give it), is refused."""
    def film(**kw):
        return type("Film", (Submodel,), {"name": "film", "__module__": "elsewhere",
                                          "parameters": (Parameter("eta", "1", "film ratio", key="friction.eta", ge=0,
                                                                   **kw),)})

    with pytest.raises(registry.RegistryError, match=r"need what is not an effect: parameter 'eta': "
                                                     r"needs='damping_law=bogus'"):
        registry.register(film(default=1.0, needs="damping_law=bogus"))
    with pytest.raises(registry.RegistryError, match=r"a modelling choice reads without a default: eta"):
        registry.register(film(needs="damping_law=penetration"))
    assert not registry.extended()
