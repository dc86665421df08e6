"""The model's sliding velocities v_<contact> (derive/model.py, ContactModel.slide): the outputs the wear numbers
of a run read (runtime/results/wear.py). The model had no sliding speed among its outputs, only the friction
power, from which a speed beyond the law's saturation cannot be read back."""

from __future__ import annotations

import numpy as np

PRESSURES = np.array([1e5, 1e5])


def _outputs(f, p, theta, X):
    y = np.asarray(f.outputs(theta, np.asarray(X, float), np.ones(len(f.guard_names)), p, PRESSURES), float).ravel()
    return dict(zip(f.output_names, y, strict=True))


def test_the_tip_at_rest_slides_at_the_apex_speed_on_the_limacon(default_scene, default_functions):
    """With the seal at rest in its groove the tip is carried along the housing Rh = L + 2 r sin(theta)
    (Eqs. 1-2) at omega sqrt(Rh^2 + Rh'^2), less omega delta_w: it rests delta_w inside the wall (Eq. 9)."""
    f = default_functions.sx
    p, P = default_scene.parameter_vector(f.parameter_names), default_scene.parameters
    L, r, w = P["L"], P["r"], P["omega"]
    theta = np.radians(np.arange(0.0, 360.0, 7.5))
    v = np.array([_outputs(f, p, th, np.zeros(6))["v_housing"] for th in theta])
    apex = w * np.hypot(L + 2 * r * np.sin(theta), 2 * r * np.cos(theta))
    assert np.all(np.abs(v - apex) <= w * P["delta_w"] * (1 + 1e-6))
    assert v.min() > 0  # along the rotation


def test_the_seal_s_own_motion_adds_its_slide_on_each_wall(default_scene, default_functions):
    """The seal moving in its groove (phi = 0) at xd, yd: its flanks slide on the groove walls at xd (Eqs. 50-61),
    its back face across the spring at yd (Eqs. 70-72), and its tip along the housing tangent
    (sin lambda, cos lambda) by xd sin(lambda) + yd cos(lambda) more (Eqs. 9, 64-66)."""
    f = default_functions.sx
    p, P = default_scene.parameter_vector(f.parameter_names), default_scene.parameters
    theta, xd, yd = 0.3, 0.5, 0.2
    rest, moving = _outputs(f, p, theta, np.zeros(6)), _outputs(f, p, theta, [0, 0, 0, xd, yd, 0])
    lam = np.arctan2(2 * P["r"] * np.cos(theta), P["L"] + 2 * P["r"] * np.sin(theta))  # Eq. 9: tan = Rh' / Rh
    assert abs(moving["v_housing"] - rest["v_housing"] - (xd * np.sin(lam) + yd * np.cos(lam))) < 1e-12
    for c in ("i1", "c2", "i2", "c4"):
        assert abs(moving[f"v_{c}"] - rest[f"v_{c}"] - xd) < 1e-12
    assert abs(moving["v_spring"] - rest["v_spring"] - yd) < 1e-12
