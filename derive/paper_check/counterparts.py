"""The derived counterpart of each printed quantity, built from the derivation's own building blocks (frames and
points, contact geometry, the submodels' force laws, the derived model)."""

from __future__ import annotations

import functools

import sympy as sp

from .. import contact_geometry, geometry, kinematics, paper
from .. import seal_shape as shape
from ..assumptions import Assumptions
from ..cache import cached_model
from ..effects import Effects
from ..kinematics import plain
from ..model import options_of, submodel_contacts
from ..symbols import P, Pa, Pb, theta
from .values import ACTIVATIONS, I, groove_bottom_pressure, phid, xd, yd


class Derived:
    """The derivation's building blocks and the derived value of each printed quantity."""

    def __init__(self) -> None:
        self._pressure: dict = {}
        self._cache: dict = {}
        self.model = cached_model()
        self.k = k = kinematics.build()
        self.g = g = contact_geometry.build(k)
        self.q = self.model.quantities
        self.beta_free = I["beta"]
        beta_d = plain(g.beta)
        X_s6 = plain(g.X_s6)
        self.guard_rule = {
            ACTIVATIONS["s_b1"]: sp.Piecewise((1, plain(g.gaps["b1"]) < 0), (0, True)),
            ACTIVATIONS["s_b2"]: sp.Piecewise((1, plain(g.gaps["b2"]) < 0), (0, True)),
            ACTIVATIONS["s_b3"]: sp.Piecewise((1, plain(g.gaps["b3"]) < 0), (0, True)),
            ACTIVATIONS["s_b4"]: sp.Piecewise((1, plain(g.gaps["b4"]) < 0), (0, True)),
            ACTIVATIONS["s_h"]: sp.Piecewise((1, plain(g.xs5) > 0), (0, True)),
            ACTIVATIONS["s_sp"]: sp.Piecewise((1, plain(g.spring_compression) > 0), (0, True)),
        }
        housing = self.housing(Effects())
        arcs = self.pressure(Assumptions(gap_pressure="chamber"))
        outputs = self.model.outputs
        self.subs: dict[sp.Symbol, sp.Expr] = {
            I["beta"]: beta_d,
            I["ao"]: P["ro"] * (1 - sp.cos(beta_d)),  # Eq. 27
            I["b5"]: P["ro"] * sp.sin(beta_d),  # Eq. 28
            I["beta_o"]: shape.beta_o,
            I["ds0"]: shape.ds0,
            I["l1"]: plain(g.l1), I["l2"]: plain(g.l2), I["l3"]: plain(g.l3), I["l4"]: plain(g.l4),
            I["b6"]: plain(g.b6),
            I["xs5"]: plain(g.xs5),
            I["xs6"]: P["ds1"] - P["delta_w"] - X_s6,
            I["xs6_tilde"]: -(X_s6 + P["ds2"]),
            I["lam"]: geometry.housing_normal_angle(),
            I["Fw"]: -housing[0],
            I["Fs5X"]: housing[0], I["Fs5Y"]: housing[1],
            I["Fsp"]: P["ks"] * sp.Max(plain(g.spring_compression), 0),
            I["Pend"]: groove_bottom_pressure(),
            I["Ps2"]: Pb, I["Ps4"]: Pa,
            I["vOgX"]: self.G(k.Og.vel(k.N))[0], I["vOgY"]: self.G(k.Og.vel(k.N))[1],
            I["v_s6X"]: self.G(k.relative_velocity(g.r_s6))[0],
            I["gamma_s6"]: sp.sign(self.G(k.relative_velocity(g.r_s6))[1]),
            I["Fs8X"]: arcs["s8"][0][0], I["Fs8Y"]: arcs["s8"][0][1],
            I["Fs9X"]: arcs["s9"][0][0], I["Fs9Y"]: arcs["s9"][0][1],
            I["SumFx"]: sum((e for n, e in outputs.items() if n.startswith("F_") and n.endswith("_X")), sp.S.Zero),
            I["SumFy"]: sum((e for n, e in outputs.items() if n.startswith("F_") and n.endswith("_Y")), sp.S.Zero),
            I["SumM"]: sum((e for n, e in outputs.items() if n.startswith("M_")), sp.S.Zero),
        }
        for i, (name, r) in enumerate((("i1", g.r_i1), ("c2", g.r_c2), ("i2", g.r_i2), ("c4", g.r_c4)), 1):
            tangent = k.S.x if name.startswith("i") else k.G.x
            self.subs[I[f"gamma{i}"]] = sp.sign(plain(k.relative_velocity(r).dot(tangent)))
            self.subs[I[f"b{i}"]] = plain(g.gaps[f"b{i}"])

    # -- helpers
    def G(self, vec) -> tuple[sp.Expr, ...]:
        return self.k.components(vec)

    def S(self, vec) -> tuple[sp.Expr, ...]:
        return self.k.components(vec, self.k.S)

    def seal_point_velocity(self, r) -> tuple[sp.Expr, ...]:
        """Absolute velocity of the seal's material point at r (from C)."""
        return self.G(self.k.point_on_seal("p", r).vel(self.k.N))

    def rotor_point_velocity(self, r) -> tuple[sp.Expr, ...]:
        """Absolute velocity of the rotor's point coinciding with C + r: differentiate with x, y, phi frozen."""
        v = (self.k.C.pos_from(self.k.o) + r).dt(self.k.N)
        return tuple(e.subs({xd: 0, yd: 0, phid: 0}) for e in self.G(v))

    def independent_relative_velocity(self, r) -> tuple[sp.Expr, ...]:
        return tuple(a - b for a, b in zip(self.seal_point_velocity(r), self.rotor_point_velocity(r), strict=True))

    def _cached(self, kind: str, effects: Effects, build):
        key = (kind, tuple(sorted(effects.as_dict().items())))
        if key not in self._cache:
            self._cache[key] = build()
        return self._cache[key]

    def groove(self, effects: Effects) -> dict[str, tuple[sp.Expr, ...]]:
        return self._cached("groove", effects, lambda: {
            c.name: self.G(c.loads[0].force)
            for c in submodel_contacts("groove", self.k, self.g, options_of(effects, Assumptions()))})

    def housing(self, effects: Effects) -> tuple[sp.Expr, ...]:
        return self._cached("housing", effects, lambda: self.G(
            submodel_contacts("housing", self.k, self.g, options_of(effects, Assumptions()))[0].loads[0].force))

    def spring(self, effects: Effects) -> tuple[sp.Expr, ...]:
        return self._cached("spring", effects, lambda: self.G(
            submodel_contacts("spring", self.k, self.g, options_of(effects, Assumptions()))[0].loads[0].force))

    def pressure(self, assumptions: Assumptions) -> dict[str, tuple[tuple[sp.Expr, ...], object]]:
        key = tuple(sorted(assumptions.as_dict().items()))
        if key not in self._pressure:
            model = submodel_contacts("pressure", self.k, self.g, options_of(Effects(), assumptions))[0]
            self._pressure[key] = {ld.name: (self.G(ld.force), ld.r_CP) for ld in model.loads}
        return self._pressure[key]

    def moment_about_C(self, r, force: tuple[sp.Expr, ...]) -> sp.Expr:
        rx, ry = self.G(r)
        return rx * force[1] - ry * force[0]

    # -- the derived counterpart of each label
    def counterpart(self, label: str) -> tuple[sp.Expr, ...]:
        return tuple(sp.sympify(e) for e in _COUNTERPARTS[label](self))


def difference(a: tuple, b: tuple) -> tuple:
    return tuple(p - q for p, q in zip(a, b, strict=True))


def _effects(**values: bool) -> Effects:
    """The paper's effects with some switched off (children follow their parents)."""
    return Effects.from_mapping(values)


def _frozen_s5(d: Derived):
    """rc + tip point at a free beta (Eqs. 25-30): the derivation's tip, before beta is solved for."""
    return d.k.C.pos_from(d.k.Og) + shape.tip_point(d.k.S, d.beta_free)


def _groove_part(d: Derived, label: str) -> tuple[sp.Expr, ...]:
    """Damping or friction part of a groove force: full law minus the law without that effect."""
    name = {"55": "i1", "62.c2": "c2", "62.i2": "i2", "62.c4": "c4"}.get(label)
    if name:
        with_d = d.groove(_effects(groove_friction=False))[name]
        without = d.groove(_effects(groove_friction=False, groove_damping=False))[name]
        return difference(with_d, without)
    full, nofric = d.groove(Effects()), d.groove(_effects(groove_friction=False))
    return tuple(c for n in ("i1", "c2", "i2", "c4") for c in difference(full[n], nofric[n]))


def _pressure_faces(d: Derived) -> tuple[sp.Expr, ...]:
    loads = d.pressure(Assumptions(gap_pressure="chamber"))
    faces = tuple(c for n in ("s1", "s2", "s3", "s4", "s7") for c in loads[n][0])
    mags = tuple(sp.sqrt(loads[n][0][0] ** 2 + loads[n][0][1] ** 2) for n in ("s8", "s9"))
    return faces + mags


def _areas(d: Derived) -> tuple[sp.Expr, ...]:
    loads = d.pressure(Assumptions(gap_pressure="chamber"))
    S = d.k.S
    Pend = groove_bottom_pressure()

    def along(name, axis):
        return plain(d.k.G.x.dot(axis)) * loads[name][0][0] + plain(d.k.G.y.dot(axis)) * loads[name][0][1]

    mag = {n: sp.sqrt(loads[n][0][0] ** 2 + loads[n][0][1] ** 2) for n in ("s8", "s9")}
    return (along("s1", S.y) / Pb, along("s2", S.y) / Pb, -along("s3", S.y) / Pa, -along("s4", S.y) / Pa,
            along("s7", S.x) / Pend, mag["s8"] / Pb, mag["s9"] / Pa)


def _face_moments(d: Derived) -> tuple[sp.Expr, ...]:
    loads = d.pressure(Assumptions(gap_pressure="chamber"))
    return tuple(d.moment_about_C(loads[n][1], loads[n][0]) for n in ("s1", "s2", "s3", "s4", "s7"))


def _case_table(d: Derived) -> tuple[sp.Expr, ...]:
    """Algorithm 3 from the naming rule: back letter n (b2 <= 0), q (b4 <= 0), p; front digit 1 (b1), 3 (b3), 2."""
    out = []
    for name in paper.CASES:
        back, front = name[0], name[1]
        out += [int(front == "1"), int(back == "n"), int(front == "3"), int(back == "q")]
    return tuple(sp.Integer(v) for v in out)


_COUNTERPARTS = {
    "1": lambda d: (geometry.stroke,),
    "2": lambda d: (geometry.Rh,),
    "3": lambda d: geometry.housing_point(theta),
    "4": lambda d: geometry.housing_point_aspect(theta),
    "4.b": lambda d: (geometry.looping_free_limit(),),
    "5": lambda d: (geometry.lobe_radius(),),
    "6": lambda d: (geometry.truncation_limacon(),),
    "6.z": lambda d: (geometry.truncation_limacon().subs(paper.theta0, geometry.truncation_angle()),),
    "7": lambda d: (geometry.truncation_angle(),),
    "7.b": lambda d: (geometry.truncation_angle().subs(P["r"], geometry.b * P["L"]),),
    "8": lambda d: (geometry.truncation_circular(),),
    "9.lambda": lambda d: (geometry.housing_normal_angle(),),
    "9.lambda0": lambda d: (geometry.housing_normal_angle().subs(theta, 0),),
    "9.F": lambda d: _housing_ratio(d),
    "9.init": lambda d: (geometry.initial_wall_deflection(),),
    "10": lambda d: d.G(d.k.C.pos_from(d.k.Og)),
    "11": lambda d: tuple(kinematics.frame_rotation(d.k)),
    "12": lambda d: (d.q["12.i"], d.q["12.j"]),
    "13": lambda d: (d.q["13.i"], d.q["13.j"]),
    "15": lambda d: (d.q["15.X1"], d.q["15.Y1"]),
    "17": lambda d: d.G(d.g.r_g1),
    "18": lambda d: d.G(d.g.r_g3),
    "19.c2": lambda d: d.S(d.g.r_c2),
    "19.c4": lambda d: d.S(d.g.r_c4),
    "20": lambda d: (d.q["20.X"], d.q["20.Y"]),
    "21": lambda d: (d.q["21.X"], d.q["21.Y"]),
    "22": lambda d: (d.q["22"],),
    "23": lambda d: (d.q["23"],),
    "24": lambda d: d.S(shape.corner(d.k.S, "c1")) + d.S(shape.corner(d.k.S, "c3")),
    "25": lambda d: d.G(_frozen_s5(d)),
    "26": lambda d: d.G(_frozen_s5(d)),
    "27": lambda d: (P["ds1"] - plain(shape.tip_point(d.k.S, d.beta_free).dot(d.k.S.x)),),
    "28": lambda d: (plain(shape.tip_point(d.k.S, d.beta_free).dot(d.k.S.y)),),
    "29": lambda d: (d.G(_frozen_s5(d))[1],),
    "30": lambda d: (d.G(_frozen_s5(d))[1],),
    "31": lambda d: (d.q["31"],),
    "32": lambda d: d.G(d.k.C.pos_from(d.k.Og) + d.g.r_s5),
    "33": lambda d: (d.q["33"],),
    "34": lambda d: (-d.housing(_effects(housing_damping=False, housing_friction=False))[0],),
    "36": lambda d: (d.q["36"],),
    "37": lambda d: (P["ds1"] - P["delta_w"] - d.q["37"],),
    "38": lambda d: (-(d.q["37"] + P["ds2"]),),
    "39": lambda d: (d.spring(_effects(spring_damping=False, spring_friction=False))[0],),
    "40": lambda d: (d.q["40"],),
    "41": lambda d: (d.q["41"],),
    "42": lambda d: (d.q["42"],),
    "43": lambda d: (d.q["43"],),
    "A1.elastic": lambda d: tuple(
        c for n in ("i1", "c2", "i2", "c4") for c in d.groove(_effects(groove_damping=False, groove_friction=False))[n]),
    "A1.friction": lambda d: _groove_part(d, "A1.friction"),
    "44": lambda d: (d.q["44.X"], d.q["44.Y"]),
    "45": lambda d: (d.q["45.X"], d.q["45.Y"]),
    "46": lambda d: (d.q["46.X"], d.q["46.Y"]),
    "47": lambda d: (d.q["47.X"], d.q["47.Y"]),
    "48": lambda d: d.seal_point_velocity(d.g.r_i1),
    "49": lambda d: d.rotor_point_velocity(d.g.r_i1),
    "50": lambda d: d.independent_relative_velocity(d.g.r_i1),
    "51": lambda d: (d.q["51.X"], d.q["51.Y"]),
    "52": lambda d: (d.q["52"],),
    "53": lambda d: (d.q["53"],),
    "55": lambda d: _groove_part(d, "55"),
    "56": lambda d: d.independent_relative_velocity(d.g.r_c2),
    "57": lambda d: (d.q["57.X"], d.q["57.Y"]),
    "58": lambda d: d.independent_relative_velocity(d.g.r_c4),
    "59": lambda d: (d.q["59.X"], d.q["59.Y"]),
    "60": lambda d: d.independent_relative_velocity(d.g.r_i2),
    "61": lambda d: (d.q["61.X"], d.q["61.Y"]),
    "62.c2": lambda d: _groove_part(d, "62.c2"),
    "62.i2": lambda d: _groove_part(d, "62.i2"),
    "62.c4": lambda d: _groove_part(d, "62.c4"),
    "63": lambda d: d.groove(_effects(groove_friction=False))["i1"],
    "64": lambda d: d.seal_point_velocity(d.g.r_s5),
    "65": lambda d: (d.q["66.X"], d.q["66.Y"]),
    "66": lambda d: (d.q["66.X"], d.q["66.Y"]),
    "67": lambda d: (d.housing(_effects(housing_friction=False))[0]
                     - d.housing(_effects(housing_friction=False, housing_damping=False))[0],),
    "A2": lambda d: d.housing(Effects()),
    "68": lambda d: (d.moment_about_C(d.g.r_s5, d.housing(Effects())),),
    "69.s": lambda d: d.seal_point_velocity(d.g.r_s6),
    "69.r": lambda d: d.rotor_point_velocity(d.g.r_s6),
    "70": lambda d: d.independent_relative_velocity(d.g.r_s6),
    "71": lambda d: (d.q["72.X"], d.q["72.Y"]),
    "72": lambda d: (d.q["72.X"], d.q["72.Y"]),
    "73.damping": lambda d: (d.spring(_effects(spring_friction=False))[0]
                             - d.spring(_effects(spring_friction=False, spring_damping=False))[0],),
    "73.friction": lambda d: (d.spring(Effects())[1],),
    "75": _pressure_faces,
    "76": _areas,
    "76.Pend": lambda d: (groove_bottom_pressure(),),
    "77": lambda d: (d.moment_about_C(d.pressure(Assumptions())["s8"][1], d.pressure(Assumptions())["s8"][0]),),
    "78": lambda d: (d.moment_about_C(d.pressure(Assumptions())["s9"][1], d.pressure(Assumptions())["s9"][0]),),
    "79": _face_moments,
    "80.M": lambda d: tuple(d.model.mass_matrix),
    "80.f": lambda d: tuple(d.model.forcing),
    "A3": _case_table,
}


def _housing_ratio(d: Derived) -> tuple[sp.Expr]:
    """Groove-axis component of the housing force per unit normal force (Eq. 9), forward sliding."""
    fx, fy = d.housing(Effects())
    lam = geometry.housing_normal_angle()
    normal = -fx * sp.cos(lam) + fy * sp.sin(lam)  # component along the inward normal
    return (-fx / normal,)


@functools.lru_cache(maxsize=1)
def cached_derived() -> Derived:
    return Derived()
