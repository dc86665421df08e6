"""What the paper check knows about the rows that do not agree: the verified difference, its reason, what the
model does instead, and the notes and assumption points of the report."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import sympy as sp

from .. import paper
from ..symbols import P, Pb, theta
from .values import DEFAULTS, I, fmt

#: the apex's radial speed amplitude at the default speed (the example of Eq. 67)
_two_r_omega = 2 * DEFAULTS["r"] * DEFAULTS["omega"]
_damping_at_rest = float(f"{DEFAULTS['cw'] * _two_r_omega:.2g}")  # to 2 digits


@dataclass(frozen=True)
class Finding:
    """Why a row does not agree, and what the model does instead."""

    kind: str  # "physics" | "typesetting" | "assumption"
    difference: tuple  # printed - derived, in the paper's symbols (verified numerically by the check)
    difference_text: str
    reason: str
    model_uses: str
    example: dict = field(default_factory=dict)  # overrides of EXAMPLE_STATE for the numeric example


def _closing_velocities() -> dict[str, sp.Expr]:
    """Closing speeds -v.n at the groove contacts, from the printed Eqs. 51, 57, 59, 61."""
    v = {p.label: sp.Matrix(p.printed) for p in paper.equations() if p.label in ("51", "57", "59", "61")}
    return {"i1": -v["51"].dot(paper.Ys), "c2": -v["57"].dot(paper.Y), "i2": v["61"].dot(paper.Ys),
            "c4": v["59"].dot(paper.Y)}


def _friction_difference() -> tuple:
    closing = _closing_velocities()
    out = []
    for i, (name, t) in enumerate((("i1", paper.Xs), ("c2", paper.X), ("i2", paper.Xs), ("c4", paper.X)), 1):
        gap = I[f"b{i}"]
        extra = sp.Piecewise((P["mu2"] * I[f"gamma{i}"] * P["cr"] * sp.Max(closing[name], 0), gap < 0), (0, True))
        out += list(extra * t)
    return tuple(out)


def _open_damping_difference() -> tuple:
    vn = -_closing_velocities()["i1"]
    return tuple(sp.Piecewise((-P["cr"] * vn, (vn < 0) & (I["b1"] >= 0)), (0, True)) * paper.Ys)


def _findings() -> dict[str, Finding]:
    x_t, ao, lam = I["xs6_tilde"], I["ao"], I["lam"]
    ds1, ds2, ds0 = P["ds1"], P["ds2"], I["ds0"]
    v66x = next(p.printed[0] for p in paper.equations() if p.label == "66")
    two_r_omega = 2 * P["r"] * P["omega"] * sp.cos(theta)
    mid_point = ("{s} is the mid-point of {i} (at ds0 − {l} along X̂s, since {l} = ds2 + ds0 − {m}) and {c} (at ds0, "
                 "Eq. 24), i.e. at ds0 − {l}/2 along X̂s. With d = ds1 it would sit (ds1 − ds0) further out. Eq. 79 prints "
                 "ds0 − {l}/2 for the same moment arm.")
    return {
        "6.z": Finding(
            "assumption", (), "none: geometry.truncation_limacon is Eq. 6 with θ0 of Eq. 7",
            "Eqs. 6-7 take the groove edge on the housing limaçon in the fixed frame, where Yo = Wg/2. Near θ = 0 the "
            "housing bulges beyond the apex (Rh = L + 2 r sin θ > L), so x_p1(θ0) > L and z = L − x_p1(θ0) ≈ "
            "−r Wg/L + Wg²/(8 L) (to first order; the exact bound is a little below 8 r) is negative for grooves "
            "narrower than about 8 r, i.e. for every practical groove: the 'edge point' lies beyond the apex.",
            "ζ0 is a scene parameter (default scene: 7.1e-4 m), not Eq. 6's z",
            example={"r": DEFAULTS["r"], "L": DEFAULTS["L"], "Wg": DEFAULTS["Wg"]}),
        "9.F": Finding(
            "physics", (-2 * P["mu1"] * sp.sin(lam),), "−2 μ1 sin λ",
            "Eq. 9 and Algorithm 2 disagree on the sign of the friction term. The tip slides forward along the housing "
            "(the rotor turns counter-clockwise and the tip moves at about ω Rh, several m/s), so friction on the seal "
            "acts along −t̂ = −(sin λ X̂ + cos λ Ŷ). With the inward normal −cos λ X̂ + sin λ Ŷ the groove-axis "
            "component of the housing force is N (cos λ + μ1 sin λ) = N cos λ (1 + μ1 tan λ), which is what Algorithm 2's "
            "Fs5y = Fw (tan λ − μ1)/(1 + μ1 tan λ) implies (row A2 agrees). Eq. 9's (1 − μ1 tan λ) belongs to a tip "
            "sliding backwards.",
            "N = Fw / (cos λ + μ1 sign(v_slide) sin λ), Fw = kw xs5 the groove-axis component "
            "(derive/submodels/housing.py)"),
        "19.c4": Finding(
            "typesetting", (ds2 - ds1, 0), "(ds2 − ds1) X̂s",
            "c4 is the back corner on the +Ŷs side, on the back face at −ds2 X̂s like c2. The paper's own Eq. 43 "
            "(b4 = −y + ds2 sin ϕ − ...) uses ds2; with −ds1 the corner would sit at the tip.",
            "rcs4 = −ds2 X̂s + (Ws/2) Ŷs (seal_shape.corner)",
            example={"ds1": 5.0e-3}),  # the defaults have ds1 = ds2, where the slip is invisible
        "29": Finding(
            "typesetting", ((ds1 - ao) * (sp.sin(paper.phi) ** 2 - sp.sin(paper.phi)),), "(ds1 − ao) (sin²ϕ − sin ϕ)",
            "The Ŷ component of Eq. 26 is y + (ds1 − ao) sin ϕ + b5 cos ϕ; the repeated sin ϕ is a slip (Eq. 30, the "
            "next line, has a single sin ϕ, and row 30 agrees).",
            "Y(s5) = y + (ds1 − ro) sin ϕ + ro sin(β + ϕ) = 0 (contact_geometry.solve_tip_angle)"),
        "36": Finding(
            "physics", (-2 * (ds1 - ao + ds2) * sp.tan(paper.phi),), "−2 (ds1 − ao + ds2) tan ϕ",
            "s6 is where the back face crosses the groove axis: y − ds2 sin ϕ + s cos ϕ = 0 gives s = ds2 tan ϕ − "
            "y/cos ϕ from the face centre, so b6 = Ws/2 + ds2 tan ϕ − y/cos ϕ. With Eq. 30 (−y/cos ϕ = (ds1 − ao) tan ϕ "
            "+ b5) this is Ws/2 + b5 + (ds1 − ao) tan ϕ + ds2 tan ϕ: walking down the groove axis from s5 to the back "
            "face, (ds1 − ao + ds2) along X̂s, moves the crossing by +(ds1 − ao + ds2) tan ϕ along Ŷs. The print has "
            "both tan ϕ terms with the wrong sign: a seal turned counter-clockwise (ϕ > 0) has its back face cross the "
            "axis on the c4 side (b6 > Ws/2).",
            "b6 = Ws/2 + ds2 tan ϕ − y/cos ϕ (contact_geometry.build); s6 at −ds2 X̂s + (b6 − Ws/2) Ŷs from C"),
        "38": Finding(
            "physics", (ds1,), "ds1",
            "At rest (x = y = ϕ = 0, so β = ao = b5 = 0 and xs5 = δw) Eq. 37 gives xs6 = ds1 + ds2 − δw under every "
            "reading, so x̃s6 = ds1 and Eq. 39 would give a spring force ks (ds1 + δs) instead of the preload ks δs of "
            "Eq. 9. Measured like xs6 (from the undeformed wall line), the initial position of s6 is ds1 + ds2 − δw, "
            "not ds2 − δw. The deflection that follows from the geometry is the inward travel of s6 along the groove "
            "axis, −(X_s6 + ds2) with X_s6 = x − ds2/cos ϕ + y tan ϕ: it involves the back face only, not the tip or "
            "the housing penetration xs5.",
            "spring compression δs − (X_s6 + ds2), X_s6 = x − ds2/cos ϕ + y tan ϕ (contact_geometry.build)",
            example={"x": 0.0, "y": 0.0, "phi": 0.0}),
        "39": Finding(
            "physics",
            (sp.Piecewise((-P["ks"] * (x_t + P["delta_s"]), (x_t <= 0) & (x_t + P["delta_s"] > 0)), (0, True)),),
            "−ks (x̃s6 + δs) while −δs < x̃s6 ≤ 0, else 0",
            "With x̃s6 the inward travel of s6 (the corrected Eq. 38) the printed force ks (x̃s6 + δs) is right, but "
            "'exists only if x̃s6 > 0' switches the preloaded spring off as soon as the seal moves out by any amount: "
            "the force jumps from ks δs (10 N) to 0 at x̃s6 = 0. A compression spring pushes while its compression "
            "x̃s6 + δs is positive.",
            "Fsp = ks max(δs − (X_s6 + ds2), 0), acting while the compression is positive (guard 'spring'; "
            "derive/submodels/spring.py)"),
        "A1.friction": Finding(
            "physics", _friction_difference(),
            "μ2 γi cr max(v_close,i, 0) t̂i while bi < 0 (t̂ = X̂s at i1, i2 and X̂ at c2, c4; v_close = −v·n̂)",
            "Coulomb friction is μ times the whole normal force of the contact. Algorithm 1 takes the elastic part "
            "|bi| kgi only, although the damping of Eqs. 55 and 62 acts along the same normal (Eq. 63 adds them); the "
            "paper's own Eq. 73 uses the total normal force (Fsp − cs v·X̂) at the spring.",
            "friction −μ2 sign(v_slide) (kgi max(−bi, 0) + cr max(v_close, 0)) t̂ (derive/submodels/groove.py)",
            example={"y": -4.0e-5, "phi": -2.0e-3, "phid": 0.0}),
        "44": Finding(
            "typesetting", tuple((ds1 - ds0) * paper.Xs), "(ds1 − ds0) X̂s",
            mid_point.format(s="s1", i="i1", l="l1", m="l2", c="c1"), "rs1 = (ri1 + rcs1)/2 (contact_geometry.build)"),
        "46": Finding(
            "typesetting", tuple((ds1 - ds0) * paper.Xs), "(ds1 − ds0) X̂s",
            mid_point.format(s="s3", i="i2", l="l3", m="l4", c="c3"), "rs3 = (ri2 + rcs3)/2 (contact_geometry.build)"),
        "63": Finding(
            "assumption", _open_damping_difference(), "Fd_i1 of Eq. 55 while b1 ≥ 0 (contact open), else 0",
            "Eq. 63 adds the damping of Eq. 55 to Fg1 whatever b1 is (Eq. 55's condition is on the velocity only), so "
            "the print's damper acts across an open gap. The model applies contact damping only while the contact is "
            "closed (assumptions.damping = 'in-contact'; 'always' gives the print's rule). The same holds for Eqs. 62 "
            "and 73; Eq. 67 sits inside Algorithm 2's xs5 > 0 branch in the print too.",
            "F_i1 = (kg1 max(−b1, 0) + cr max(−v_i1·Ŷs, 0)) Ŷs while b1 < 0, else 0",
            example={"phid": 0.0}),
        "67": Finding(
            "physics", (-P["cw"] * (sp.Max(v66x, 0) - sp.Max(v66x - two_r_omega, 0)),),
            "−cw [max(v_ss5·X̂, 0) − max(v_ss5·X̂ − 2 r ω cos θ, 0)] (−2 cw r ω cos θ while both are positive)",
            "The model's housing wall is fixed in the groove frame: along the groove axis the housing stays at "
            "Rh(θ) − (2 r sin θ + Li) = L − Li from Og, so the tip approaches it only through its motion relative to "
            "the groove, and that relative velocity is what a contact damper resists. The print damps the absolute "
            "velocity v_ss5·X̂ of Eq. 66, which contains the rotor's radial following motion 2 r ω cos θ (the apex "
            "tracks the housing, so this motion is tangent to it, not an approach). Exactly, v_ss5·X̂ − v_rel·X̂ = "
            "2 r ω cos θ − ω Y(s5) = 2 r ω cos θ since s5 stays on the axis. At 1500 rpm 2 r ω = "
            f"{_two_r_omega:.3g} m/s: about {_damping_at_rest:.0f} N of damping on a seal at rest in its "
            f"groove, against a {DEFAULTS['ks'] * DEFAULTS['delta_s']:.3g} N preload.",
            "Fd = −cw max(v_rel·X̂, 0) X̂, v_rel the seal's velocity at s5 relative to the groove, in contact only "
            "(derive/submodels/housing.py)",
            example={"theta": 0.0, "x": 0.0, "y": 0.0, "phi": 0.0, "xd": 0.0, "yd": 0.0, "phid": 0.0}),
        "68": Finding(
            "physics", (paper.x * I["Fs5Y"] - paper.y * I["Fs5X"],), "x Fs5y − y Fs5x (= (rc × Fs5)·Ẑ)",
            "Eq. 25 defines rs5 = rc + (ds1 − ao) X̂s + b5 Ŷs, the position of s5 from Og, so rs5 × Fs5 is the moment "
            "about Og, not about the centre of gravity that Eq. 80 needs. The arm from C is rs5 − rc; the two differ by "
            "rc × Fs5. (Eq. 79 uses arms from C for the pressure forces.)",
            "Ms5 = ((ds1 − ao) X̂s + b5 Ŷs) × Fs5, about C (model output M_housing)",
            example={"x": 2.0e-5, "y": -3.0e-5}),
        "73.friction": Finding(
            "physics", (I["gamma_s6"] * P["mus"] * P["cs"] * sp.Max(I["v_s6X"], 0),),
            "sign(v_s6·Ŷ) μs cs max(v_s6·X̂, 0) (Ŷ component)",
            "The normal force at the spring is Fsp + cs max(−v_s6·X̂, 0) (Eq. 73's damping acts only while the seal moves "
            "down). The print's Fsp − cs v_s6·X̂ equals it while v_s6·X̂ < 0, but while the seal moves out it lowers the "
            "normal force by cs v_s6·X̂ although the damping is off (and can make it negative, reversing the friction).",
            "friction −μs sign(v_s6·Ŷ) (Fsp + cs max(−v_s6·X̂, 0)) Ŷ (derive/submodels/spring.py)"),
        "76.Pend": Finding(
            "assumption", (-Pb,), "−Pb",
            "The text says Pend is 'half that of the difference of Pa and Pb'. (Pa − Pb)/2 is not a pressure: it "
            "changes sign with the pressure difference and would pull on the back face whenever Pb > Pa. The groove "
            "bottom communicates with both chambers through the side gaps, so the model takes the mean.",
            "Pend = (Pa + Pb)/2 (assumptions.pend_rule = 'mean'; 'half-difference' reproduces the text)"),
        "76.Ps": Finding(
            "assumption", (), "",
            "No rule is printed ('will depend on the seal-groove relative positions'). The model: the gap between a "
            "seal side and the groove wall sees its own chamber while the mouth contact on that side is open, and the "
            "groove-bottom pressure once it closes.",
            "Ps2 = Pb while b1 > 0, else Pend; Ps4 = Pa while b3 > 0, else Pend (assumptions.gap_pressure = "
            "'open-side'; 'chamber' keeps the chamber's pressure)"),
    }


_INDEPENDENT = ("Derived independently: the seal's material point (two-point formula) less the rotor point coinciding with "
                "it (differentiated with x, y, ϕ frozen); kinematics.relative_velocity (ṙc + ϕ̇ × r) agrees with it.")
NOTES: dict[str, str] = {
    "6": "Symbolic θ0.",
    "6.z": "The derivation's Eq. 6-7 agree with the print; the row records that z < 0. See Assumptions.",
    "14": "Vector.dt in the fixed frame; its components are row 15.",
    "16": "seal_shape.ds = ds1 + ds2.",
    "35": "The derivation's spring contact s6 is where the back face meets the groove axis, −ds2 X̂s + (b6 − Ws/2) Ŷs "
          "from C with b6 of row 36 (s7 = −ds2 X̂s at rest). The printed reading's Ŷ component (Ws/2 − b6) cos ϕ = "
          "y − ds2 sin ϕ and its −x term fit neither a vector from C (Ŷ component −y) nor one from Og (Ŷ component 0).",
    "54": "sign(v) regularised as tanh(v/v_eps); see Assumptions.",
    "63": "See Assumptions (damping).",
    "74": "The print's rs6 is not defined (Eq. 35 gives rs7 with an −x term); the derivation takes the moment about C with "
          "the arm −ds2 X̂s + (b6 − Ws/2) Ŷs. If the print's rs6 is measured from Og, as Eq. 35's −x term suggests, "
          "Eq. 74 has the wrong arm that row 68 records as an erratum for the housing force.",
    "76.Pend": "See Assumptions (pend_rule).",
    "76.Ps": "See Assumptions (gap_pressure).",
    "7": "θ0 solves y_p1(θ0) = Wg/2, a quadratic in sin θ0 (geometry.truncation_angle).",
    "7.b": "Eq. 7 with r = b L.",
    "8": "From the lobe circle centred at (0, −k) meeting Y = Wg/2 (geometry.truncation_circular).",
    "9.init": "X balance at rest only (the groove-axis reading of kw xs5); see Assumptions.",
    "11": "Direction cosines of the seal frame (kinematics.frame_rotation).",
    "13": "Vector.dt of the position of C in the fixed frame.",
    "15": "Vector.dt twice in the fixed frame (kinematics.acceleration_rotor).",
    "25": "β free: the identity holds for any β.",
    "26": "β free.", "27": "β free.", "28": "β free.", "30": "β free: the constraint itself.",
    "31": "The branch with β → 0 for a centred seal (contact_geometry.solve_tip_angle); it satisfies Eq. 30.",
    "32": "With the derived β the Ŷ component of s5 vanishes identically.",
    "34": "Groove-axis reading of kw (assumptions.housing_stiffness); the contact acts while xs5 > 0.",
    "37": "Reading: xs6 is the distance along X̂ from the undeformed wall line X = ds1 − δw down to s6, i.e. "
          "(ds1 − δw) − X_s6 (not from the centre of gravity, as the text says).",
    "A1.elastic": "Contacts activated by their gaps (b < 0).",
    "48": _INDEPENDENT, "49": _INDEPENDENT, "50": _INDEPENDENT, "56": _INDEPENDENT, "58": _INDEPENDENT,
    "60": _INDEPENDENT, "69.s": _INDEPENDENT + " Derived b6.", "69.r": _INDEPENDENT + " Derived b6.",
    "70": _INDEPENDENT + " Derived b6.", "71": "Derived b6 (the printed b6 of Eq. 36 differs).",
    "72": "Derived b6 (the printed b6 of Eq. 36 differs).",
    "55": "Damping law with the contact closed; the contact condition is row 63.",
    "62.c2": "Contact closed.", "62.i2": "Contact closed.", "62.c4": "Contact closed.",
    "64": "The seal's material point at s5.",
    "A2": "For a given Fw and the tip sliding forward (sign +1): the derivation's normal N = Fw/(cos λ + μ1 sin λ) "
          "reproduces Fs5y. What Fw contains differs (Eq. 67).",
    "73.damping": "Contact closed.",
    "75": "Ps2 = Pb, Ps4 = Pa (gap_pressure 'chamber'), Pend as the model; |Fs8|, |Fs9| against Pb As8, Pa As9 "
          "(the print leaves f̂s8, f̂s9 unspecified).",
    "76": "Face areas from the derived pressure loads.",
    "77": "A uniform pressure on a circular arc has its resultant through the arc centre Co: the derivation applies "
          "Fs8 at Co, the print at the arc's mid-point on the same line of action, so the moments about C agree.",
    "78": "As Eq. 77, for Fs9.",
    "79": "d = ds0; the ± (Ws/2) Ŷs terms contribute nothing (Ŷs × Ŷs = 0).",
    "80.M": "Kane's method (eom.build).",
    "80.f": "Kane's generalised forces equal ΣF − ms (Ẍ1 − ẍ, Ÿ1 − ÿ) and ΣM_CG from the model's force and moment "
            "outputs, at random contact activations.",
}

CHOICE_NOTES: dict[str, str] = {
    "pend_rule": "See row 76.Pend.",
    "gap_pressure": "See row 76.Ps.",
    "damping": "See row 63.",
    "housing_stiffness": "Algorithm 2 prints Fs5x = −Fw X̂: the default.",
}


def assumption_points() -> list[tuple[str, str]]:
    """The points the paper leaves open, with numbers at the default scene's values."""
    v = DEFAULTS
    lam0 = math.atan(2 * v["r"] / v["L"])
    preload = v["ks"] * v["delta_s"]
    fy0 = preload * (math.tan(lam0) - v["mu1"]) / (1 + v["mu1"] * math.tan(lam0))
    centrifugal = v["ms"] * v["omega"] ** 2 * v["Li"]
    beta_o = math.degrees(v["beta_o"])  # Eq. 24, seal_shape.tip_half_angle (values.DEFAULTS)
    return [
        ("What Pend is (Eq. 76)", "the text says half the *difference* of Pa and Pb; the model takes the mean "
         "(Pa + Pb)/2, the physical reading (pend_rule; row 76.Pend)."),
        ("The rule for Ps2, Ps4 (Eq. 76)", "not printed; the model: the chamber's pressure while the mouth contact on "
         "that side is open (b1 > 0 for Ps2, b3 > 0 for Ps4), the groove-bottom pressure Pend once it closes "
         "(gap_pressure; row 76.Ps)."),
        ("Damping only while in contact (Eqs. 55, 62, 67, 73)", "the model's contact dampers act only while their "
         "contact is closed and the bodies approach (max(v_close, 0)); the print conditions Eqs. 55, 62, 73 on the "
         "velocity only (damping; row 63)."),
        ("When the spring force exists (Eq. 39)", "while the spring's compression δs − (X_s6 + ds2) is positive: the "
         "spring only pushes. The print's 'only if x̃s6 > 0' would drop the preload as soon as the seal moves out "
         "(rows 38, 39)."),
        ("Direction of housing friction (Eq. 9, Algorithm 2)", "opposite to the tip's absolute sliding velocity along "
         "the housing tangent (forward, along the rotation, in operation), so its groove-axis component adds to the "
         "normal force's: N (cos λ + μ1 sin λ), as Algorithm 2; Eq. 9's (1 − μ1 tan λ) has the opposite sign (row 9.F)."),
        ("Initial deflections (Eq. 9)", f"δw = ks δs / kw from the seal's X balance at rest (x = y = ϕ = 0): the preload "
         f"ks δs = {fmt(preload)} N against the housing's groove-axis component kw δw (geometry.initial_wall_deflection; "
         f"{fmt(v['delta_w'])} m at the defaults). Only X balances: at θ = 0 the housing's Ŷ component "
         f"Fw (tan λ0 − μ1)/(1 + μ1 tan λ0) = {fmt(fy0)} N is left to the groove, and with inertia the centrifugal load "
         f"ms ω² Li = {fmt(centrifugal)} N pushes outwards, so the seal does not start in equilibrium. The undeformed "
         "wall is at X = ds1 − δw in the groove frame; with the machine's geometry that means Li = L − ds1 + δw "
         "(with Li = L − ds1 the tip would only touch the wall, without the deflection δw of the preload)."),
        ("The tip point s5 stays on the groove axis (Eq. 29)", "as the paper: the tip contact is where the tip arc "
         "crosses the groove axis, the penetration xs5 is measured there along X̂ and the housing force acts there. "
         "A circular tip actually touches the tilted wall where the arc's normal is the wall's, at β + ϕ = −λ "
         f"(|λ| ≤ λ0 = {fmt(math.degrees(lam0))}° inside the arc's ±βo = ±{fmt(beta_o)}°), up to ro sin λ0 = "
         f"{fmt(v['ro'] * math.sin(lam0) * 1e3)} mm from the axis."),
        ("Friction sign regularised", "sign(v) is tanh(v / v_eps) in every Coulomb law "
         "(derive/submodels/laws.slip_sign, scene parameter v_eps); the check compares in the limit v_eps → 0."),
        ("Contacts never pull", "elastic forces are kg max(−b, 0), kw max(xs5, 0), ks max(compression, 0) on top of "
         "the activations, which is the print's |b| kg for b < 0."),
        ("Groove protrusion ζ0 (Eqs. 6-7)", "a scene parameter, because Eqs. 6-7 give a negative truncation z for "
         "every groove narrower than about 8 r (row 6.z)."),
    ]


@functools.lru_cache(maxsize=1)
def FINDINGS() -> dict[str, Finding]:  # noqa: N802
    return _findings()
