"""The paper's printed forms as data: Eqs. 1-80 and Algorithms 1-4.

Phung, Sultan, Appuhamillage, "On the apex seal analysis of limaçon positive
displacement machines", Mech. Mach. Theory 127 (2018) 126-145, transcribed
equation by equation from the paper's Sections 2-4 (Eqs. 1-80, Algorithms 1-4;
the paper's PDF text garbles some equations, so each unclear one records the
reading checked and its alternative).

Each :class:`Printed` holds what the paper *prints*, as sympy in the symbols of
:mod:`derive.symbols` (vectors as component tuples in one frame). Printed forms
use the paper's own intermediate quantities (ao, b5, l1, b6, ...), given here as
symbols in :data:`INTERMEDIATES`; the check (:mod:`derive.paper_check`) replaces
them by the derived values, so every row tests one printed equation on its own
and a misprint never propagates into the rows that use it.

Nothing here is used by the derivation: this module is the reference the
derivation is compared with, never a source of it.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from . import geometry
from .symbols import P, Pa, Pb, qs, theta, udots, us

#: statuses a row can have (decided by the check, except "structural" and "assumption")
CLOSED_FORM = "closed-form"  # compared with the derivation, symbolically or numerically
STRUCTURAL = "structural"  # a definition or statement: the derivation implements it (``implemented_by``)
ASSUMPTION = "assumption"  # the paper is silent, ambiguous or unphysical: a documented modelling choice

x, y, phi = qs
xd, yd, phid = us
xdd, ydd, phidd = udots
omega, r, L, Li = P["omega"], P["r"], P["L"], P["Li"]
zeta0, delta_w, delta_s = P["zeta0"], P["delta_w"], P["delta_s"]
Ws, Wg, ds1, ds2, ro, Bs = P["Ws"], P["Wg"], P["ds1"], P["ds2"], P["ro"], P["Bs"]
ks, kw, cw, cr, cs = P["ks"], P["kw"], P["cw"], P["cr"], P["cs"]
mu1, mu2, mus, ms, Icg = P["mu1"], P["mu2"], P["mus"], P["ms"], P["Icg"]
b, Cr, k = geometry.b, geometry.Cr, geometry.k
theta0 = sp.Symbol("theta0", real=True)  # as in geometry.truncation_limacon


def _sym(name: str, **assumptions) -> sp.Symbol:
    return sp.Symbol(name, real=True, **assumptions)


#: the paper's intermediate quantities; the check substitutes the derived value of each
INTERMEDIATES: dict[str, sp.Symbol] = {
    n: _sym(n)
    for n in (
        "ao", "b5", "beta", "beta_o", "ds0", "l1", "l2", "l3", "l4", "b6", "xs5", "xs6", "xs6_tilde",
        "lam", "Fw", "Fsp", "Pend", "Ps2", "Ps4", "vOgX", "vOgY", "gamma1", "gamma2", "gamma3",
        "gamma4", "gamma_s6", "v_s6X", "Fs5X", "Fs5Y", "Fs8X", "Fs8Y", "Fs9X", "Fs9Y", "b1", "b2", "b3", "b4",
        "SumFx", "SumFy", "SumM",
    )
}
I = INTERMEDIATES  # noqa: E741  (short alias for the tables below)

# groove-frame components of the unit vectors (Eq. 11 gives the seal's)
X = sp.Matrix([1, 0])
Y = sp.Matrix([0, 1])
Xs = sp.Matrix([sp.cos(phi), sp.sin(phi)])
Ys = sp.Matrix([-sp.sin(phi), sp.cos(phi)])
rc = x * X + y * Y  # Eq. 10
rc_dot = xd * X + yd * Y


def cross_z(w: sp.Expr, v: sp.Matrix) -> sp.Matrix:
    """(w Z) x v for a planar vector v (groove components)."""
    return w * sp.Matrix([-v[1], v[0]])


def moment(r_: sp.Matrix, f: sp.Matrix) -> sp.Expr:
    """Z component of r x f."""
    return r_[0] * f[1] - r_[1] * f[0]


def _t(m: sp.Matrix) -> tuple[sp.Expr, ...]:
    return tuple(m)


@dataclass(frozen=True)
class Printed:
    """One printed equation (or one part of it)."""

    label: str  # "15.X1": equation number, then the part
    title: str
    text: str  # the print as transcribed from the paper
    kind: str = CLOSED_FORM
    frame: str = "scalar"  # components: "scalar", "G" (X, Y), "S" (Xs, Ys), "R" (i, j), "list"
    printed: tuple[sp.Expr, ...] = ()
    #: where the PDF text is unclear or a term looks misprinted: the reading ``printed`` takes ...
    reading: str = ""
    #: ... and the other one, in words and (if comparable) as sympy
    alternative: str = ""
    alternative_printed: tuple[sp.Expr, ...] = ()
    #: intermediates left free (not replaced by derived values), e.g. beta in Eqs. 25-30
    free: tuple[str, ...] = ()
    #: for structural and assumption rows: what in the derivation implements it (module:function)
    implemented_by: str = ""

    @property
    def equation(self) -> str:
        return self.label.split(".")[0]


def _geometry() -> list[Printed]:
    """Eqs. 1-9 (Section 2 and the initial forces)."""
    s0 = sp.sqrt(L**2 / (4 * r) ** 2 + Wg / (4 * r))
    return [
        Printed("1", "chord centre offset s", "s = 2 r sin θ", printed=(2 * r * sp.sin(theta),)),
        Printed("2", "housing radius Rh", "Rh = 2 r sin θ + L", printed=(2 * r * sp.sin(theta) + L,)),
        Printed("3", "housing point p1 (Cartesian)",
                "x_p1 = r sin 2θ + L cos θ, y_p1 = r (1 − cos 2θ) + L sin θ", frame="list",
                printed=(r * sp.sin(2 * theta) + L * sp.cos(theta), r * (1 - sp.cos(2 * theta)) + L * sp.sin(theta))),
        Printed("4", "housing point p1 with b = r/L",
                "x_p1 = L (b sin 2θ + cos θ), y_p1 = L [b (1 − cos 2θ) + sin θ]", frame="list",
                printed=(L * (b * sp.sin(2 * theta) + sp.cos(theta)), L * (b * (1 - sp.cos(2 * theta)) + sp.sin(theta)))),
        Printed("4.b", "looping- and dimple-free limit of b", "b = r/L ≤ 0.25", printed=(sp.Rational(1, 4),)),
        Printed("5", "radius of a circular rotor lobe", "Rlc = sqrt((L − C)² + k²)",
                printed=(sp.sqrt((L - Cr) ** 2 + k**2),)),
        Printed("6", "truncation z, limaçon-to-limaçon", "z = L − (r sin 2θ0 + L cos θ0)",
                printed=(L - (r * sp.sin(2 * theta0) + L * sp.cos(theta0)),)),
        Printed("6.z", "sign of the truncation z of Eqs. 6-7 (the groove protrusion ζ0)",
                "z = L − (r sin 2θ0 + L cos θ0) with θ0 of Eq. 7", kind=ASSUMPTION,
                printed=(L - (r * sp.sin(2 * sp.asin(-L / (4 * r) + s0)) + L * sp.cos(sp.asin(-L / (4 * r) + s0))),),
                implemented_by="derive.symbols:PARAMETERS (zeta0 is a scene parameter)"),
        Printed("7", "truncation angle θ0 (in r, L)", "θ0 = asin(−L/(4r) + sqrt(L²/(4r)² + Wg/(4r)))",
                printed=(sp.asin(-L / (4 * r) + s0),),
                reading="radicand L²/(4r)² + Wg/(4r)", alternative="the radicand is garbled in the paper's PDF text; "
                "this is the reading for which the two printed forms agree"),
        Printed("7.b", "truncation angle θ0 (in b, L)", "θ0 = asin(−1/(4b) + sqrt(1/(4b)² + Wg/(4 L b)))",
                printed=(sp.asin(-1 / (4 * b) + sp.sqrt(1 / (4 * b) ** 2 + Wg / (4 * L * b))),),
                reading="radicand 1/(4b)² + Wg/(4Lb)", alternative="scrambled radicand, as Eq. 7"),
        Printed("8", "truncation z, circular lobes", "z = L − Cr − sqrt(Rlc² − (k + Wg/2)²)",
                printed=(L - Cr - sp.sqrt((L - Cr) ** 2 + k**2 - (k + Wg / 2) ** 2),),
                reading="(k + Wg/2)²", alternative="k² + (Wg/2)²",
                alternative_printed=(L - Cr - sp.sqrt((L - Cr) ** 2 + k**2 - k**2 - (Wg / 2) ** 2),)),
        Printed("9.lambda", "housing normal angle λ", "λ = atan(2 r cos θ / (2 r sin θ + L))",
                printed=(sp.atan(2 * r * sp.cos(theta) / (2 * r * sp.sin(theta) + L)),)),
        Printed("9.lambda0", "λ at θ = 0", "λ0 = atan(2 r / L)", printed=(sp.atan(2 * r / L),)),
        Printed("9.F", "groove-axis component of the housing force per unit normal force",
                "F cos λ (1 − μ1 tan λ) = kw δw", printed=(sp.cos(I["lam"]) * (1 - mu1 * sp.tan(I["lam"])),)),
        Printed("9.init", "initial housing deflection", "initially ks δs = kw δw", printed=(ks * delta_s / kw,)),
    ]


def _kinematics() -> list[Printed]:
    """Eqs. 10-16."""
    return [
        Printed("10", "position of C in the groove frame", "rc = x X̂ + y Ŷ", frame="G", printed=_t(rc)),
        Printed("11", "seal frame from the groove frame (rows Xs, Ys)", "X̂s = cos ϕ X̂ + sin ϕ Ŷ, Ŷs = −sin ϕ X̂ + cos ϕ Ŷ",
                frame="list", printed=(sp.cos(phi), sp.sin(phi), -sp.sin(phi), sp.cos(phi))),
        Printed("12", "position of C in the rotor frame", "rc1 = (2 r sin θ + Li + x) î + y ĵ", frame="R",
                printed=(2 * r * sp.sin(theta) + Li + x, y)),
        Printed("13", "absolute velocity of C", "v1c = (2ωr cos θ + ẋ − ωy) î + (2ωr sin θ + ωLi + ωx + ẏ) ĵ", frame="R",
                printed=(2 * omega * r * sp.cos(theta) + xd - omega * y,
                         2 * omega * r * sp.sin(theta) + omega * Li + omega * x + yd)),
        Printed("14", "absolute acceleration of C", "a1c = Ẍ1 î + Ÿ1 ĵ", kind=STRUCTURAL,
                implemented_by="derive.kinematics:acceleration_rotor"),
        Printed("15", "absolute acceleration of C (components)",
                "Ẍ1 = ẍ − 4rω² sin θ − ω² Li − ω² x − 2ωẏ, Ÿ1 = ÿ + 4rω² cos θ − ω² y + 2ωẋ", frame="R",
                printed=(xdd - 4 * r * omega**2 * sp.sin(theta) - omega**2 * Li - omega**2 * x - 2 * omega * yd,
                         ydd + 4 * r * omega**2 * sp.cos(theta) - omega**2 * y + 2 * omega * xd)),
        Printed("16", "seal height", "ds = ds1 + ds2", kind=STRUCTURAL, implemented_by="derive.seal_shape:ds"),
    ]


def _contact_points() -> list[Printed]:
    """Eqs. 17-39 (Section 4.1)."""
    l2, l4, ds0, ao, b5 = I["l2"], I["l4"], I["ds0"], I["ao"], I["b5"]
    beta, xs5 = I["beta"], I["xs5"]
    Xg = ds1 - zeta0 - delta_w
    rs5 = rc + (ds1 - ao) * Xs + b5 * Ys
    xs6 = (ds1 - ao + ds2) / sp.cos(phi) - xs5
    return [
        Printed("17", "groove mouth corner g1", "rg1 = (ds1 − ζ0 − δw) X̂ − (Wg/2) Ŷ", frame="G", printed=(Xg, -Wg / 2)),
        Printed("18", "groove mouth corner g3", "rg3 = (ds1 − ζ0 − δw) X̂ + (Wg/2) Ŷ", frame="G", printed=(Xg, Wg / 2)),
        Printed("19.c2", "back corner c2", "rcs2 = −ds2 X̂s − (Ws/2) Ŷs", frame="S", printed=(-ds2, -Ws / 2)),
        Printed("19.c4", "back corner c4", "rcs4 = −ds1 X̂s + (Ws/2) Ŷs (PDF text)", frame="S", printed=(-ds1, Ws / 2),
                reading="−ds1 X̂s, as the PDF text reads", alternative="−ds2 X̂s (the back face)",
                alternative_printed=(-ds2, Ws / 2)),
        Printed("20", "contact point i1 (from C)",
                "ri1 = [(l2 − ds2) cos ϕ + (Ws/2) sin ϕ] X̂ + [(l2 − ds2) sin ϕ − (Ws/2) cos ϕ] Ŷ", frame="G",
                printed=((l2 - ds2) * sp.cos(phi) + Ws / 2 * sp.sin(phi), (l2 - ds2) * sp.sin(phi) - Ws / 2 * sp.cos(phi))),
        Printed("21", "contact point i2 (from C)",
                "ri2 = [(l4 − ds2) cos ϕ − (Ws/2) sin ϕ] X̂ + [(l4 − ds2) sin ϕ + (Ws/2) cos ϕ] Ŷ", frame="G",
                printed=((l4 - ds2) * sp.cos(phi) - Ws / 2 * sp.sin(phi), (l4 - ds2) * sp.sin(phi) + Ws / 2 * sp.cos(phi))),
        Printed("22", "c2 to i1 along Xs", "l2 = −x cos ϕ − y sin ϕ + ds2 + (ds1 − ζ0 − δw) cos ϕ − (Wg/2) sin ϕ",
                printed=(-x * sp.cos(phi) - y * sp.sin(phi) + ds2 + Xg * sp.cos(phi) - Wg / 2 * sp.sin(phi),)),
        Printed("23", "c4 to i2 along Xs", "l4 = −x cos ϕ − y sin ϕ + ds2 + (ds1 − ζ0 − δw) cos ϕ + (Wg/2) sin ϕ",
                printed=(-x * sp.cos(phi) - y * sp.sin(phi) + ds2 + Xg * sp.cos(phi) + Wg / 2 * sp.sin(phi),)),
        Printed("24", "tip corners c1, c3", "rcs1 = ds0 X̂s − (Ws/2) Ŷs, rcs3 = ds0 X̂s + (Ws/2) Ŷs", frame="list",
                printed=(ds0, -Ws / 2, ds0, Ws / 2)),
        Printed("25", "tip contact point s5 (from Og), any β", "rs5 = rc + (ds1 − ao) X̂s + b5 Ŷs", frame="G",
                printed=_t(rs5), free=("beta",)),
        Printed("26", "s5 in groove components, any β",
                "rs5 = (x + (ds1 − ao) cos ϕ − b5 sin ϕ) X̂ + (y + (ds1 − ao) sin ϕ + b5 cos ϕ) Ŷ", frame="G",
                printed=(x + (ds1 - ao) * sp.cos(phi) - b5 * sp.sin(phi), y + (ds1 - ao) * sp.sin(phi) + b5 * sp.cos(phi)),
                free=("beta",)),
        Printed("27", "ao", "ao = ro (1 − cos β)", printed=(ro * (1 - sp.cos(beta)),), free=("beta",)),
        Printed("28", "b5", "b5 = ro sin β", printed=(ro * sp.sin(beta),), free=("beta",)),
        Printed("29", "s5 stays on the groove axis", "y + (ds1 − ao) sin ϕ sin ϕ + b5 cos ϕ = 0 (PDF text)",
                printed=(y + (ds1 - ao) * sp.sin(phi) ** 2 + b5 * sp.cos(phi),), free=("beta",),
                reading="(ds1 − ao) sin ϕ sin ϕ, as the PDF text reads",
                alternative="(ds1 − ao) sin ϕ (Eq. 26's Ŷ component, as Eq. 30 uses)",
                alternative_printed=(y + (ds1 - ao) * sp.sin(phi) + b5 * sp.cos(phi),)),
        Printed("30", "Eq. 29 with Eqs. 27-28", "y + ds1 sin ϕ − ro (1 − cos β) sin ϕ + ro sin β cos ϕ = 0",
                printed=(y + ds1 * sp.sin(phi) - ro * (1 - sp.cos(beta)) * sp.sin(phi) + ro * sp.sin(beta) * sp.cos(phi),),
                free=("beta",)),
        Printed("31", "tip angle β", "β = asin((1 − ds1/ro) sin ϕ − y/ro) − ϕ",
                printed=(sp.asin((1 - ds1 / ro) * sp.sin(phi) - y / ro) - phi,)),
        Printed("32", "s5 on the groove axis (from Og)", "rs5 = (x + (ds1 − ao) cos ϕ − b5 sin ϕ) X̂", frame="G",
                printed=(x + (ds1 - ao) * sp.cos(phi) - b5 * sp.sin(phi), 0)),
        Printed("33", "housing penetration xs5", "xs5 = x + (ds1 − ao) cos ϕ − b5 sin ϕ − ds1 + δw",
                printed=(x + (ds1 - ao) * sp.cos(phi) - b5 * sp.sin(phi) - ds1 + delta_w,)),
        Printed("34", "elastic housing force (groove-axis component)", "Fw = kw xs5 if xs5 > 0, else 0",
                printed=(sp.Piecewise((kw * xs5, xs5 > 0), (0, True)),)),
        Printed("35", "spring contact point at rest s7 / s6", "rs7 = (−x − ds2/cos ϕ − (Ws/2 − b6) sin ϕ) X̂ + "
                "(Ws/2 − b6) cos ϕ Ŷ", kind=STRUCTURAL,
                reading="as the paper's PDF text reads (badly garbled; only ds2, x, Ws/2, "
                "b6, sin ϕ, cos ϕ are certain)", alternative="not comparable: no reading puts the point on the back "
                "face and on the groove axis", implemented_by="derive.contact_geometry:build (r_s6)"),
        Printed("36", "c2 to s6 along the back face", "b6 = Ws/2 + b5 − (ds1 − ao) tan ϕ − ds2 tan ϕ",
                printed=(Ws / 2 + b5 - (ds1 - ao) * sp.tan(phi) - ds2 * sp.tan(phi),)),
        Printed("37", "xs6: from the undeformed wall line down to s6, along X", "xs6 = ((ds1 − ao) + ds2 − xs5) / cos ϕ",
                printed=(xs6,), reading="((ds1 − ao) + ds2)/cos ϕ − xs5 (cos ϕ divides the tip-to-back length only)",
                alternative="((ds1 − ao) + ds2 − xs5)/cos ϕ, or cos ϕ multiplying",
                alternative_printed=((ds1 - ao + ds2 - xs5) / sp.cos(phi),)),
        Printed("38", "spring deflection x̃s6", "x̃s6 = xs6 − (ds2 − δw)", printed=(I["xs6"] - (ds2 - delta_w),),
                reading="xs6 as Eq. 37", alternative="every reading of Eq. 37 gives x̃s6 = ds1 at rest"),
        Printed("39", "spring force Fsp and when it exists", "Fsp = ks (x̃s6 + δs), exists only if x̃s6 > 0",
                printed=(sp.Piecewise((ks * (I["xs6_tilde"] + delta_s), I["xs6_tilde"] > 0), (0, True)),)),
    ]


def _groove_forces() -> list[Printed]:
    """Eqs. 40-47 and Algorithm 1."""
    l1, l2, l3, l4, ds0 = I["l1"], I["l2"], I["l3"], I["l4"], I["ds0"]
    Xg = ds1 - zeta0 - delta_w
    c, s = sp.cos(phi), sp.sin(phi)
    elastic = []
    friction = []
    for i, (kg, n, t) in enumerate(((P["kg1"], Ys, Xs), (P["kg2"], Y, X), (P["kg3"], -Ys, Xs), (P["kg4"], -Y, X)), 1):
        gap = I[f"b{i}"]
        elastic += list(sp.Piecewise((sp.Abs(gap) * kg, gap < 0), (0, True)) * n)
        friction += list(sp.Piecewise((sp.Abs(gap) * kg, gap < 0), (0, True)) * (-I[f"gamma{i}"] * mu2) * t)
    return [
        Printed("40", "gap b1 at g1", "b1 = (rc + rcs2 − rg1)·Ŷs = −x sin ϕ + y cos ϕ − Ws/2 + (ds1 − ζ0 − δw) sin ϕ "
                "+ (Wg/2) cos ϕ", printed=(-x * s + y * c - Ws / 2 + Xg * s + Wg / 2 * c,),
                reading="order of the Ws/2, Wg/2 terms as the dot product gives",
                alternative="the paper's PDF text garbles the order of the Ws/2 and Wg/2 terms"),
        Printed("41", "gap b2 at g2", "b2 = (rc + rcs2 − rg1)·Ŷ = y − ds2 sin ϕ − (Ws/2) cos ϕ + Wg/2",
                printed=(y - ds2 * s - Ws / 2 * c + Wg / 2,), reading="as Eq. 40", alternative="as Eq. 40"),
        Printed("42", "gap b3 at g3", "b3 = −(rc + rcs4 − rg3)·Ŷs = x sin ϕ − y cos ϕ − Ws/2 − (ds1 − ζ0 − δw) sin ϕ "
                "+ (Wg/2) cos ϕ", printed=(x * s - y * c - Ws / 2 - Xg * s + Wg / 2 * c,),
                reading="as Eq. 40", alternative="as Eq. 40"),
        Printed("43", "gap b4 at g4", "b4 = −(rc + rcs4 − rg3)·Ŷ = −y + ds2 sin ϕ − (Ws/2) cos ϕ + Wg/2",
                printed=(-y + ds2 * s - Ws / 2 * c + Wg / 2,), reading="as Eq. 40", alternative="as Eq. 40"),
        Printed("A1.elastic", "Algorithm 1: elastic groove forces Fg1..Fg4 (groove components)",
                "Fgi = |bi| kgi (± Ŷs or ± Ŷ) if bi < 0, else 0", frame="list", printed=tuple(elastic)),
        Printed("A1.friction", "Algorithm 1: groove friction, proportional to |bi| kgi",
                "Fgi friction = −γi μ2 |bi| kgi (X̂s or X̂) if bi < 0", frame="list", printed=tuple(friction)),
        Printed("44", "pressure point s1 (mid i1-c1)", "rs1 = [(d − l1/2) cos ϕ + (Ws/2) sin ϕ] X̂ + "
                "[(d − l1/2) sin ϕ − (Ws/2) cos ϕ] Ŷ, d = ds1 (PDF text)", frame="G",
                printed=((ds1 - l1 / 2) * c + Ws / 2 * s, (ds1 - l1 / 2) * s - Ws / 2 * c),
                reading="d = ds1, as the PDF text reads", alternative="d = ds0 (as Eq. 79 prints)",
                alternative_printed=((ds0 - l1 / 2) * c + Ws / 2 * s, (ds0 - l1 / 2) * s - Ws / 2 * c)),
        Printed("45", "pressure point s2 (mid c2-i1)", "rs2 = [(l2/2 − ds2) cos ϕ + (Ws/2) sin ϕ] X̂ + "
                "[(l2/2 − ds2) sin ϕ − (Ws/2) cos ϕ] Ŷ", frame="G",
                printed=((l2 / 2 - ds2) * c + Ws / 2 * s, (l2 / 2 - ds2) * s - Ws / 2 * c)),
        Printed("46", "pressure point s3 (mid i2-c3)", "rs3 = [(d − l3/2) cos ϕ − (Ws/2) sin ϕ] X̂ + "
                "[(d − l3/2) sin ϕ + (Ws/2) cos ϕ] Ŷ, d = ds1 (PDF text)", frame="G",
                printed=((ds1 - l3 / 2) * c - Ws / 2 * s, (ds1 - l3 / 2) * s + Ws / 2 * c),
                reading="d = ds1, as the PDF text reads", alternative="d = ds0 (as Eq. 79 prints)",
                alternative_printed=((ds0 - l3 / 2) * c - Ws / 2 * s, (ds0 - l3 / 2) * s + Ws / 2 * c)),
        Printed("47", "pressure point s4 (mid c4-i2)", "rs4 = [(l4/2 − ds2) cos ϕ − (Ws/2) sin ϕ] X̂ + "
                "[(l4/2 − ds2) sin ϕ + (Ws/2) cos ϕ] Ŷ", frame="G",
                printed=((l4 / 2 - ds2) * c - Ws / 2 * s, (l4 / 2 - ds2) * s + Ws / 2 * c)),
    ]


def _velocities() -> list[Printed]:
    """Eqs. 48-63: relative velocities at the groove contacts and their damping."""
    l1, l3, ds0 = I["l1"], I["l3"], I["ds0"]
    vOg = sp.Matrix([I["vOgX"], I["vOgY"]])
    r_i1 = (ds0 - l1) * Xs - Ws / 2 * Ys
    r_i2 = (ds0 - l3) * Xs + Ws / 2 * Ys
    r_c2 = ds2 * Xs + Ws / 2 * Ys  # Eq. 56 prints  -phid x (ds2 Xs + Ws/2 Ys)
    r_c4 = -ds2 * Xs + Ws / 2 * Ys
    v_i1 = rc_dot + Ws / 2 * phid * Xs + (ds0 - l1) * phid * Ys
    v_c2 = rc_dot + Ws / 2 * phid * Xs - ds2 * phid * Ys
    v_c4 = rc_dot - Ws / 2 * phid * Xs - ds2 * phid * Ys
    v_i2 = rc_dot - Ws / 2 * phid * Xs + (ds0 - l3) * phid * Ys

    def damping(v: sp.Matrix, n: sp.Matrix, when: str) -> tuple[sp.Expr, ...]:
        vn = v.dot(n)
        cond = vn < 0 if when == "<" else vn > 0
        return _t(sp.Piecewise((-cr * vn, cond), (0, True)) * n)

    return [
        Printed("48", "absolute velocity of the seal at i1",
                "v_si1 = v_Og + ω×rc + ṙc + (ω + ϕ̇)×((ds0 − l1) X̂s − (Ws/2) Ŷs)", frame="G",
                printed=_t(vOg + cross_z(omega, rc) + rc_dot + cross_z(omega + phid, r_i1))),
        Printed("49", "velocity of the rotor point at i1", "v_ri1 = v_Og + ω×rc + ω×((ds0 − l1) X̂s − (Ws/2) Ŷs)",
                frame="G", printed=_t(vOg + cross_z(omega, rc) + cross_z(omega, r_i1))),
        Printed("50", "relative velocity at i1", "v_i1 = ṙc + ϕ̇×((ds0 − l1) X̂s − (Ws/2) Ŷs)", frame="G",
                printed=_t(rc_dot + cross_z(phid, r_i1))),
        Printed("51", "relative velocity at i1 (expanded)", "v_i1 = ẋ X̂ + ẏ Ŷ + (Ws/2) ϕ̇ X̂s + (ds0 − l1) ϕ̇ Ŷs",
                frame="G", printed=_t(v_i1)),
        Printed("52", "v_i1 · X̂s", "v_i1·X̂s = ẋ cos ϕ + ẏ sin ϕ + (Ws/2) ϕ̇",
                printed=(xd * sp.cos(phi) + yd * sp.sin(phi) + Ws / 2 * phid,)),
        Printed("53", "v_i1 · Ŷs", "v_i1·Ŷs = −ẋ sin ϕ + ẏ cos ϕ + (ds0 − l1) ϕ̇",
                printed=(-xd * sp.sin(phi) + yd * sp.cos(phi) + (ds0 - l1) * phid,)),
        Printed("54", "friction direction γ1", "γ1 = sign(v_i1·X̂s)", kind=STRUCTURAL,
                implemented_by="derive.submodels.laws:slip_sign"),
        Printed("55", "damping at i1", "Fd_i1 = −cr (v_i1·Ŷs) Ŷs if v_i1·Ŷs < 0, else 0", frame="G",
                printed=damping(v_i1, Ys, "<")),
        Printed("56", "relative velocity at c2", "v_c2 = ṙc − ϕ̇×(ds2 X̂s + (Ws/2) Ŷs)", frame="G",
                printed=_t(rc_dot - cross_z(phid, r_c2))),
        Printed("57", "relative velocity at c2 (expanded)", "v_c2 = ẋ X̂ + ẏ Ŷ + (Ws/2) ϕ̇ X̂s − ds2 ϕ̇ Ŷs", frame="G",
                printed=_t(v_c2)),
        Printed("58", "relative velocity at c4", "v_c4 = ṙc + ϕ̇×(−ds2 X̂s + (Ws/2) Ŷs)", frame="G",
                printed=_t(rc_dot + cross_z(phid, r_c4))),
        Printed("59", "relative velocity at c4 (expanded)", "v_c4 = ẋ X̂ + ẏ Ŷ − (Ws/2) ϕ̇ X̂s − ds2 ϕ̇ Ŷs", frame="G",
                printed=_t(v_c4)),
        Printed("60", "relative velocity at i2", "v_i2 = ṙc + ϕ̇×((ds0 − l3) X̂s + (Ws/2) Ŷs)", frame="G",
                printed=_t(rc_dot + cross_z(phid, r_i2))),
        Printed("61", "relative velocity at i2 (expanded)", "v_i2 = ẋ X̂ + ẏ Ŷ − (Ws/2) ϕ̇ X̂s + (ds0 − l3) ϕ̇ Ŷs",
                frame="G", printed=_t(v_i2)),
        Printed("62.c2", "damping at c2", "Fd_c2 = −cr (v_c2·Ŷ) Ŷ if v_c2·Ŷ < 0", frame="G", printed=damping(v_c2, Y, "<")),
        Printed("62.i2", "damping at i2", "Fd_i2 = −cr (v_i2·Ŷs) Ŷs if v_i2·Ŷs > 0", frame="G",
                printed=damping(v_i2, Ys, ">")),
        Printed("62.c4", "damping at c4", "Fd_c4 = −cr (v_c4·Ŷ) Ŷ if v_c4·Ŷ > 0", frame="G", printed=damping(v_c4, Y, ">")),
        Printed("63", "groove contact force at i1, whether or not b1 < 0", "F_i1 = Fg1 + Fd_i1 (Fd_i1 of Eq. 55 has "
                "no contact condition)", kind=ASSUMPTION, frame="G",
                printed=_t(sp.Piecewise((-I["b1"] * P["kg1"], I["b1"] < 0), (0, True)) * Ys
                           + sp.Matrix(damping(v_i1, Ys, "<"))),
                implemented_by="derive.assumptions:CHOICES['damping']"),
    ]


def _housing() -> list[Printed]:
    """Eqs. 64-68 and Algorithm 2."""
    ao, b5, lam, Fw = I["ao"], I["b5"], I["lam"], I["Fw"]
    vOg = sp.Matrix([I["vOgX"], I["vOgY"]])
    r_s5 = (ds1 - ao) * Xs + b5 * Ys
    v65 = (sp.Matrix([2 * r * omega * sp.cos(theta) + xd - omega * y, yd + 2 * r * omega * sp.sin(theta) + omega * Li
                      + omega * x]) - (omega + phid) * b5 * Xs + (omega + phid) * (ds1 - ao) * Ys)
    v66 = (2 * r * omega * sp.cos(theta) + xd - omega * y - (omega + phid) * ((ds1 - ao) * sp.sin(phi) + b5 * sp.cos(phi)),
           yd + 2 * r * omega * sp.sin(theta) + omega * (Li + x) + (omega + phid) * ((ds1 - ao) * sp.cos(phi)
                                                                                      - b5 * sp.sin(phi)))
    Fs5 = sp.Matrix([I["Fs5X"], I["Fs5Y"]])
    return [
        Printed("64", "absolute velocity of the seal at s5", "v_ss5 = v_Og + ω×rc + ṙc + (ω + ϕ̇)×((ds1 − ao) X̂s + b5 Ŷs)",
                frame="G", printed=_t(vOg + cross_z(omega, rc) + rc_dot + cross_z(omega + phid, r_s5))),
        Printed("65", "v_ss5 (expanded)", "v_ss5 = (2rω cos θ + ẋ − ωy) X̂ + (ẏ + 2rω sin θ + ωLi + ωx) Ŷ − (ω + ϕ̇) b5 X̂s "
                "+ (ω + ϕ̇)(ds1 − ao) Ŷs", frame="G", printed=_t(v65)),
        Printed("66", "v_ss5 in groove components", "v_ss5 = [2rω cos θ + ẋ − ωy − (ω + ϕ̇)((ds1 − ao) sin ϕ + b5 cos ϕ)] X̂ "
                "+ [ẏ + 2rω sin θ + ω(Li + x) + (ω + ϕ̇)((ds1 − ao) cos ϕ − b5 sin ϕ)] Ŷ", frame="G", printed=v66),
        Printed("67", "housing damping (X component)", "Fd_s5 = −cw (v_ss5·X̂) X̂ if v_ss5·X̂ > 0, else 0",
                printed=(sp.Piecewise((-cw * v66[0], v66[0] > 0), (0, True)),)),
        Printed("A2", "Algorithm 2: housing force components for a given Fw", "Fs5x = −Fw X̂, "
                "Fs5y = Fw (tan λ − μ1)/(1 + μ1 tan λ) Ŷ", frame="G",
                printed=(-Fw, Fw * (sp.tan(lam) - mu1) / (1 + mu1 * sp.tan(lam)))),
        Printed("68", "moment of the housing force about C", "Ms5 = rs5 × Fs5 (rs5 of Eq. 25, from Og)",
                printed=(moment(rc + r_s5, Fs5),)),
    ]


def _spring() -> list[Printed]:
    """Eqs. 69-74."""
    b6 = I["b6"]
    vOg = sp.Matrix([I["vOgX"], I["vOgY"]])
    r_s6 = -ds2 * Xs - (Ws / 2 - b6) * Ys
    v72 = sp.Matrix([xd + phid * ds2 * sp.sin(phi) + phid * (Ws / 2 - b6) * sp.cos(phi),
                     yd - phid * ds2 * sp.cos(phi) + phid * (Ws / 2 - b6) * sp.sin(phi)])
    vX, Fsp = I["v_s6X"], I["Fsp"]
    return [
        Printed("69.s", "absolute velocity of the seal at s6",
                "v_ss6 = v_Og + ω×rc + ṙc + (ω + ϕ̇)×(−ds2 X̂s − (Ws/2 − b6) Ŷs)", frame="G",
                printed=_t(vOg + cross_z(omega, rc) + rc_dot + cross_z(omega + phid, r_s6))),
        Printed("69.r", "velocity of the rotor point at s6", "v_rs6 = v_Og + ω×rc + ω×(−ds2 X̂s − (Ws/2 − b6) Ŷs)",
                frame="G", printed=_t(vOg + cross_z(omega, rc) + cross_z(omega, r_s6))),
        Printed("70", "relative velocity at s6", "v_s6 = ṙc − ϕ̇×(ds2 X̂s + (Ws/2 − b6) Ŷs)", frame="G",
                printed=_t(rc_dot - cross_z(phid, ds2 * Xs + (Ws / 2 - b6) * Ys))),
        Printed("71", "relative velocity at s6 (expanded)", "v_s6 = ẋ X̂ + ẏ Ŷ + ϕ̇ (Ws/2 − b6) X̂s − ϕ̇ ds2 Ŷs", frame="G",
                printed=_t(rc_dot + phid * (Ws / 2 - b6) * Xs - phid * ds2 * Ys)),
        Printed("72", "relative velocity at s6 in groove components", "v_s6 = [ẋ + ϕ̇ ds2 sin ϕ + ϕ̇ (Ws/2 − b6) cos ϕ] X̂ "
                "+ [ẏ − ϕ̇ ds2 cos ϕ + ϕ̇ (Ws/2 − b6) sin ϕ] Ŷ", frame="G", printed=_t(v72)),
        Printed("73.damping", "spring damping", "Fd_s6 = −cs (v_s6·X̂) X̂ if v_s6·X̂ < 0, else 0",
                printed=(sp.Piecewise((-cs * vX, vX < 0), (0, True)),)),
        Printed("73.friction", "spring friction", "Ff_s6 = −sign(v_s6·Ŷ) μs (Fsp − cs v_s6·X̂) Ŷ",
                printed=(-I["gamma_s6"] * mus * (Fsp - cs * vX),)),
        Printed("74", "spring contact force and moment", "Fs6 = Fsp X̂ + Fd_s6 + Ff_s6, Ms6 = rs6 × Fs6", kind=STRUCTURAL,
                implemented_by="derive.submodels.spring:SpringContact"),
    ]


def _pressure() -> list[Printed]:
    """Eqs. 75-79."""
    l1, l2, l3, l4, ds0, beta, beta_o = I["l1"], I["l2"], I["l3"], I["l4"], I["ds0"], I["beta"], I["beta_o"]
    As8 = 2 * ro * sp.sin((beta_o + beta) / 2) * Bs
    As9 = 2 * ro * sp.sin((beta_o - beta) / 2) * Bs
    faces = (Pb * l1 * Bs * Ys, I["Ps2"] * l2 * Bs * Ys, -Pa * l3 * Bs * Ys, -I["Ps4"] * l4 * Bs * Ys,
             I["Pend"] * Ws * Bs * Xs)
    Co = (ds1 - ro) * Xs
    r8 = Co + ro * (sp.cos((beta - beta_o) / 2) * Xs + sp.sin((beta - beta_o) / 2) * Ys)
    r9 = Co + ro * (sp.cos((beta + beta_o) / 2) * Xs + sp.sin((beta + beta_o) / 2) * Ys)
    r8_alt = Co + ro * (sp.cos((beta + beta_o) / 2) * Xs + sp.sin((beta + beta_o) / 2) * Ys)
    r9_alt = Co + ro * (sp.cos((beta - beta_o) / 2) * Xs + sp.sin((beta - beta_o) / 2) * Ys)
    F8 = sp.Matrix([I["Fs8X"], I["Fs8Y"]])
    F9 = sp.Matrix([I["Fs9X"], I["Fs9Y"]])
    d = ds0
    arms = ((d - l1 / 2) * Xs - Ws / 2 * Ys, (l2 / 2 - ds2) * Xs - Ws / 2 * Ys, (d - l3 / 2) * Xs - Ws / 2 * Ys,
            (l4 / 2 - ds2) * Xs - Ws / 2 * Ys, -ds2 * Xs)
    return [
        Printed("75", "pressure forces on the faces Fs1..Fs4, Fs7 (groove components) and |Fs8|, |Fs9|",
                "Fs1 = Pb As1 Ŷs, Fs2 = Ps2 As2 Ŷs, Fs3 = −Pa As3 Ŷs, Fs4 = −Ps4 As4 Ŷs, Fs7 = Pend As7 X̂s, "
                "Fs8 = Pb As8 f̂s8, Fs9 = Pa As9 f̂s9", frame="list",
                printed=tuple(c for f in faces for c in f) + (Pb * As8, Pa * As9)),
        Printed("76", "areas As1..As4, As7, As8, As9", "As1 = l1 Bs, As2 = l2 Bs, As3 = l3 Bs, As4 = l4 Bs, As7 = Ws Bs, "
                "As8 = 2 ro sin((βo + β)/2) Bs, As9 = 2 ro sin((βo − β)/2) Bs", frame="list",
                printed=(l1 * Bs, l2 * Bs, l3 * Bs, l4 * Bs, Ws * Bs, As8, As9)),
        Printed("76.Pend", "groove-bottom pressure Pend", "\"Pend is assumed to be half that of the difference of Pa and "
                "Pb\"", kind=ASSUMPTION, printed=((Pa - Pb) / 2,),
                implemented_by="derive.submodels.pressure:groove_bottom_pressure"),
        Printed("76.Ps", "side-gap pressures Ps2, Ps4", "\"Ps2 and Ps4 will depend on the seal-groove relative positions\" "
                "(no rule printed)", kind=ASSUMPTION, implemented_by="derive.submodels.pressure:ChamberPressure"),
        Printed("77", "point s8 of Fs8 (moment of Fs8 about C)", "rs8 = (ds1 − ro) X̂s + ro e^{j(β − βo)/2}",
                printed=(moment(r8, F8),), reading="each point at the middle of its arc: (β − βo)/2 for s8",
                alternative="(β + βo)/2 for s8 (the paper's PDF text mixes the two)",
                alternative_printed=(moment(r8_alt, F8),)),
        Printed("78", "point s9 of Fs9 (moment of Fs9 about C)", "rs9 = (ds1 − ro) X̂s + ro e^{j(β + βo)/2}",
                printed=(moment(r9, F9),), reading="(β + βo)/2 for s9", alternative="(β − βo)/2 for s9",
                alternative_printed=(moment(r9_alt, F9),)),
        Printed("79", "moments Ms1..Ms4, Ms7 of the face pressures about C",
                "Ms1 = ((d − l1/2) X̂s − (Ws/2) Ŷs) × Fs1, ..., Ms7 = −ds2 X̂s × Fs7, d = ds0", frame="list",
                printed=tuple(moment(a, f) for a, f in zip(arms, faces, strict=True)),
                reading="d = ds0 and − (Ws/2) Ŷs in Ms3, Ms4",
                alternative="± (Ws/2) Ŷs in Ms3, Ms4: immaterial, Ŷs × Ŷs = 0"),
    ]


def _motion() -> list[Printed]:
    """Eq. 80 and Algorithms 3-4."""
    X1 = xdd - 4 * r * omega**2 * sp.sin(theta) - omega**2 * Li - omega**2 * x - 2 * omega * yd
    Y1 = ydd + 4 * r * omega**2 * sp.cos(theta) - omega**2 * y + 2 * omega * xd
    SF = [I[n] for n in ("SumFx", "SumFy", "SumM")]
    return [
        Printed("80.M", "mass matrix", "diag(ms, ms, ICG)", frame="list",
                printed=(ms, 0, 0, 0, ms, 0, 0, 0, Icg)),
        Printed("80.f", "forcing: ms Ẍ1 = ΣFx, ms Ÿ1 = ΣFy, ICG ϕ̈ = ΣM, less the M u̇ terms",
                "diag(ms, ms, ICG) [Ẍ1, Ÿ1, ϕ̈] = [ΣFx, ΣFy, ΣM_CG]", frame="list",
                printed=(SF[0] - ms * (X1 - xdd), SF[1] - ms * (Y1 - ydd), SF[2])),
        Printed("A3", "Algorithm 3: the nine contact cases from the gap signs",
                "q1, n3, p1, n2, p3, q2, q3, n1, p2 (Section 4.4 table)", kind=CLOSED_FORM, frame="list",
                printed=tuple(sp.Integer(v) for case in CASES.values() for v in case),
                implemented_by="derive.modes:CASES"),
        Printed("A4", "Algorithm 4: the seal-groove gap", "bgap = min(b1, b2, b3, b4) if all bi > 0, else 0",
                kind=STRUCTURAL, implemented_by="derive.modes:gap_width"),
    ]


#: Section 4.4 as printed: case -> (b1 <= 0, b2 <= 0, b3 <= 0, b4 <= 0); 1 = that contact closed
CASES: dict[str, tuple[int, int, int, int]] = {
    "q1": (1, 0, 0, 1),
    "n3": (0, 1, 1, 0),
    "p1": (1, 0, 0, 0),
    "n2": (0, 1, 0, 0),
    "p3": (0, 0, 1, 0),
    "q2": (0, 0, 0, 1),
    "q3": (0, 0, 1, 1),
    "n1": (1, 1, 0, 0),
    "p2": (0, 0, 0, 0),
}


def equations() -> tuple[Printed, ...]:
    """Every printed equation, in the paper's order."""
    rows = (_geometry() + _kinematics() + _contact_points() + _groove_forces() + _velocities() + _housing()
            + _spring() + _pressure() + _motion())
    labels = [p.label for p in rows]
    assert len(labels) == len(set(labels)), "duplicate labels"
    return tuple(rows)
