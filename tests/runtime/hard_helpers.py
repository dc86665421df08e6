"""Shared by the hard-case tests (tests/runtime/test_hard_*.py): the scenes, short runs, physical bounds."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

import apexseal
from apexseal.derive.symbols import PARAMETER_NAMES
from apexseal.generated.layout import HybridLayout
from apexseal.generated.scaling import to_physical, to_scaled
from apexseal.runtime.results.plausibility import PenetrationWarning
from apexseal.runtime.solving.run import RunSettings, initial_activations, make_engine

HARD_DIR = Path(__file__).resolve().parents[2] / "runtime" / "scenes" / "hard"
SCENES = sorted(p.stem for p in HARD_DIR.glob("*.toml"))
SAMPLES = 360  # output samples per revolution in every hard-case test
BUDGET = 60.0  # s: the wall-time budget of every hard-case run (so 36 integrator calls per revolution)


def scene_args(args: list[str], known) -> list[str]:
    """The scenes named on a table script's command line (all of ``known`` when none is): a name that is not one
    of them stops the script with the list of those that are."""
    unknown = [a for a in args if a not in known]
    if unknown:
        raise SystemExit(f"unknown scene(s) {', '.join(unknown)}; choose from: {', '.join(known)}")
    return list(args) or list(known)


def load(name: str):
    return apexseal.load_scene(HARD_DIR / f"{name}.toml")


def simulate(scene, functions, **kw):
    """One revolution, interpreted (no compiler in the loop), SAMPLES samples, the wall-time budget. The stress
    scenes' contacts are soft or their clearances tiny by design, so their penetration warnings are expected and
    not shown (the check itself: tests/runtime/test_plausibility.py)."""
    kw.setdefault("samples_per_revolution", SAMPLES)
    kw.setdefault("compile_c", False)
    kw.setdefault("max_wall_time", BUDGET)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PenetrationWarning)
        return apexseal.simulate(scene, revolutions=kw.pop("revolutions", 1), functions=functions, **kw)


def initial_z(scene, functions, pressures):
    p = scene.parameter_vector()
    X0 = np.array([getattr(scene.operation.initial_state, k) for k in ("x", "y", "phi", "xd", "yd", "phid")], float)
    closed = initial_activations(functions, scene.operation.start_angle, X0, p, pressures[:, 0])
    return np.r_[to_scaled(X0, p[PARAMETER_NAMES.index("omega")]), closed, np.zeros(closed.size)]


def short_run(scene, functions, method: str, degrees: float, *, rtol: float = 1e-8, samples: int = SAMPLES, **settings):
    """The first ``degrees`` of a scene with one engine call (interpreted): (thetas, physical states, closed, counts)."""
    m = int(round(degrees * samples / 360))
    th0 = scene.operation.start_angle
    edges = th0 + np.linspace(0.0, 2 * np.pi, samples + 1)[:m + 1]
    st = RunSettings(method=method, rtol=rtol, samples_per_revolution=samples, **settings)
    linear = st.pressure == "linear"  # the engine takes the values at the edges, else the interval means
    P = (np.asarray(scene.pressure(edges) if linear else scene.pressure.interval_means(edges), float)
         if scene.effects.chamber_pressure else np.zeros((2, m + linear)))
    engine = make_engine(functions, st, n_samples=m, span=edges[-1] - th0, compile_c=False)
    Z = engine.run(initial_z(scene, functions, P), scene.parameter_vector(), th0, P).z
    lay = HybridLayout.of(functions)
    return edges[1:], to_physical(Z[lay.x], scene.omega), lay.closed(Z), Z[lay.counts]


def allowed_penetrations(scene, result) -> dict[str, float]:
    """The deepest each contact may be pressed (m): 2 F/k + v sqrt(ms/k) + 1 nm.

    F bounds the loads that press the seal on the contact besides the contact forces: inertia ms w^2 (4 r + L), the
    spring's preload and travel, and the larger chamber pressure on the face that faces the contact (the tip's width
    Ws for the housing, the seal's flank ds1 + ds2 for the groove); the groove also carries the tip force with the
    lever of its friction (at most 3x the largest the run computed, whose penetration this bound checks; the bound's
    own tip force made the groove's 3-13x looser: 43 um, more than the side clearance, on the default result, whose
    deepest groove penetration is 2.1 um), and the housing the groove contacts' forces along the groove axis as the
    run computed them: a seal tilted in its groove is wedged between a mouth corner and the housing, and with friction
    coefficients of 0.6-0.8 the wedge pressed the tip with a hundredfold its preload (a random scene of the slow
    property test, half as deep again as the other loads allow). 2 F/k is the deflection under a
    suddenly applied F (twice the static one), v sqrt(ms/k) the deepest an impact at the seal's largest approach
    speed v goes (its kinetic energy stored in the contact spring). A contact missed by the event logic lets the
    seal pass through the wall and breaks this.
    """
    p = scene.parameters
    P = np.maximum(result.outputs["Pa"], result.outputs["Pb"]).max()
    inertia = p["ms"] * p["omega"] ** 2 * (4 * p["r"] + p["L"])
    spring = p["ks"] * (p["delta_s"] + 1e-3)
    xd, yd, phid = (np.abs(result.state[i]).max() for i in (3, 4, 5))

    def allowed(force, k, v):
        return 2 * force / k + v * np.sqrt(p["ms"] / k) + 1e-9

    groove_x = [result.outputs[f"F_{c}_X"] for c in ("i1", "c2", "i2", "c4") if f"F_{c}_X" in result.outputs]
    wedge = float(np.abs(np.sum(groove_x, axis=0)).max()) if groove_x else 0.0
    F_tip = inertia + spring + P * p["Ws"] * p["Bs"] + wedge
    out = {"xs5": allowed(F_tip, p["kw"], xd + phid * p["Ws"])}
    tip = float(np.hypot(result.outputs["F_housing_X"], result.outputs["F_housing_Y"]).max())
    F_groove = inertia + spring + P * (p["ds1"] + p["ds2"]) * p["Bs"] + 3 * tip
    v_groove = yd + phid * (p["ds1"] + p["ds2"])
    out.update({f"b{i}": allowed(F_groove, p[f"kg{i}"], v_groove) for i in range(1, 5)})
    return out


def bound_violations(scene, result) -> list[str]:
    """Penetrations beyond what the loads and the seal's speed allow (a missed contact breaks this by far)."""
    out = []
    for name, allowed in allowed_penetrations(scene, result).items():
        gap = result.outputs[name]
        pen = float(-gap.min() if name.startswith("b") else gap.max())
        if pen > allowed:
            out.append(f"{name}: penetration {pen * 1e6:.4g} um > {allowed * 1e6:.4g} um allowed")
    return out


def mode_mismatches(result, band: float = 1e-9) -> list[str]:
    """Samples where a contact is open in the integrator's mode although its gap is below -band (a missed event)."""
    out = []
    for i, g in enumerate(result.guard_names):
        gap = result.outputs[{"spring": "spring_compression"}.get(g, g)]
        penetrating = gap < -band if g.startswith("b") else gap > band
        bad = penetrating & ~result.closed[i]
        if bad.any():
            out.append(f"{g} open while penetrating at samples {np.nonzero(bad)[0][:5]}")
    return out
