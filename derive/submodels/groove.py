"""Seal - groove contacts at g1..g4: Algorithm 1 and Eqs. 48-63.

Contact i1 (g1 on the seal's negative side) and i2 (g3 on its positive side) push
along -+Ys, normal to the seal's sides; c2 and c4 (the back corners) push along
-+Y, normal to the groove walls. Sliding is measured relative to the groove
(Eqs. 50-61); friction opposes it with the normal force of the contact. The four
guards b1..b4 name the paper's nine contact cases together (Algorithm 3).
"""

from __future__ import annotations

from typing import Any

from ..options import NONE, ON, Option
from ..parameters import CONTACT_STIFFNESS, Parameter
from .base import ContactModel, Context, Friction, Guard, Load, Submodel

#: contact -> (seal point, stiffness, normal direction (frame, axis, sign), tangent direction (frame, axis)); its
#: gap is the guard that names it as its contact
_CONTACTS = {
    "i1": ("r_i1", "kg1", ("S", "y", +1), ("S", "x")),
    "c2": ("r_c2", "kg2", ("G", "y", +1), ("G", "x")),
    "i2": ("r_i2", "kg3", ("S", "y", -1), ("S", "x")),
    "c4": ("r_c4", "kg4", ("G", "y", -1), ("G", "x")),
}


def _gap(name: str, contact: str, where: str, eq: str) -> Guard:
    return Guard(name, "s_" + name, f"gap at {where} (Eq. {eq})", output=name, sign=1, contact=contact)


class GrooveContacts(Submodel):
    name = "groove"
    summary = "the seal's corners and sides on the groove walls at g1..g4 (Algorithm 1, Eqs. 48-63)"
    switch = "groove_contact"
    contact_names = tuple(_CONTACTS)
    parameters = (
        *(Parameter(f"kg{i}", "N/m", f"groove stiffness at g{i} (Algorithm 1)", key=f"contacts.kg{i}", gt=0,
                    plausible=CONTACT_STIFFNESS)
          for i in range(1, 5)),
        Parameter("cr", "N*s/m", "seal-groove contact damping (Eq. 55); default 2 zeta_g sqrt(kg ms), kg the mean "
                  "of kg1..kg4", key="contacts.cr", ge=0, optional=True, needs="groove_damping"),
        Parameter("zeta_g", "1", "damping ratio of the seal-groove contacts: cr = 2 zeta_g sqrt(kg ms), kg the mean "
                  "of kg1..kg4, unless contacts.cr is given", key="contacts.zeta_g", default=0.1, ge=0, le=5,
                  in_vector=False, needs="groove_damping"),
        Parameter("mu2", "1", "seal-groove friction coefficient (Algorithm 1)", key="friction.mu2", ge=0, lt=1,
                  needs="groove_friction"),
    )
    options = (
        Option("groove_contact", (ON, NONE), "elastic seal-groove contacts at g1..g4, Algorithm 1"),
        Option("groove_damping", (ON, NONE), "damping of the seal-groove contacts, Eqs. 55, 62",
               parent="groove_contact"),
        Option("groove_friction", (ON, NONE), "Coulomb friction at the seal-groove contacts, Algorithm 1",
               parent="groove_contact"),
    )
    contact_meanings = {
        "i1": "seal-groove contact i1 (corner g1, seal's -Ys side; Algorithm 1, Eq. 63)",
        "c2": "seal-groove contact c2 (back corner g2 on the -Y groove wall; Algorithm 1, Eq. 63)",
        "i2": "seal-groove contact i2 (corner g3, seal's +Ys side; Algorithm 1, Eq. 63)",
        "c4": "seal-groove contact c4 (back corner g4 on the +Y groove wall; Algorithm 1, Eq. 63)",
    }
    guards = (_gap("b1", "i1", "g1, the mouth corner on the seal's negative side", "40"),
              _gap("b2", "c2", "g2, the back corner c2 on the negative wall", "41"),
              _gap("b3", "i2", "g3, the mouth corner on the seal's positive side", "42"),
              _gap("b4", "c4", "g4, the back corner c4 on the positive wall", "43"))
    oscillators = tuple((f"kg{i}", "cr") for i in range(1, 5))
    #: the seal slides along the groove walls at its corners, Ws/2 on either side of its centre of gravity (Eqs. 19-20;
    #: i1 and c2 on its -Ys side), and sticks there whenever its radial motion reverses
    frictions = (Friction("mu2", tuple(_CONTACTS), offsets=((-0.5, "Ws"), (-0.5, "Ws"), (0.5, "Ws"), (0.5, "Ws")),
                          slide="the seal along the groove walls"),)
    damping_ratios = (("cr", "zeta_g"),)
    #: where the mouth corners g1, g3 meet the seal's sides (Eqs. 20-23): both contacts i1, i2 act on its flat
    #: sides while all four are positive (the run's start is checked on them: runtime/solving/preflight.py)
    output_columns = (
        ("l1", "m", "distance along the seal from the mouth corner g1's foot i1 to the tip arc's end c1 (after Eq. 47)",
         "mm", 1e3),
        ("l2", "m", "distance along the seal from its back corner c2 to the mouth corner g1's foot i1 (Eq. 22)", "mm", 1e3),
        ("l3", "m", "distance along the seal from the mouth corner g3's foot i2 to the tip arc's end c3 (after Eq. 47)",
         "mm", 1e3),
        ("l4", "m", "distance along the seal from its back corner c4 to the mouth corner g3's foot i2 (Eq. 23)", "mm", 1e3),
    )

    def outputs(self, ctx: Context) -> dict[str, Any]:
        """l1..l4 of Eqs. 22-23 and after Eq. 47 (derive/contact_geometry.py)."""
        return {name: getattr(ctx.g, name) for name, *_ in self.output_columns}

    def contacts(self, ctx: Context) -> list[ContactModel]:
        """Fi1, Fc2, Fi2, Fc4 of Eq. 63: elastic (Algorithm 1) + damping (Eqs. 55, 62) + friction."""
        import sympy as sp

        from . import laws

        k, g, P, opts = ctx.k, ctx.g, ctx.P, ctx.options
        frames = {"S": k.S, "G": k.G}
        guard_of = {gd.contact: gd for gd in self.guards}
        models = []
        for point, (r_name, k_name, (nf, na, sgn), (tf, ta)) in _CONTACTS.items():
            gap_name = guard_of[point].name
            gap = g.gaps[gap_name]
            act = ctx.activation(guard_of[point])
            r = getattr(g, r_name)
            n = sgn * getattr(frames[nf], na)  # direction the groove pushes the seal
            tangent = getattr(frames[tf], ta)
            v = k.relative_velocity(r)  # Eqs. 50-61
            closing = -v.dot(n)  # > 0 while the seal moves into the groove wall
            guards = {f"v_{point}_n": closing}
            normal = laws.penalty(P[k_name], -gap, act)  # |b| kg while b < 0 (a contact cannot pull)
            if opts.on("groove_damping"):
                normal = laws.damped(normal, P["cr"], closing, act, opts["damping"],
                                     laws.damper_depth(ctx, guard_of[point], -gap))
            force, power = normal * n, sp.S.Zero
            v_slide = v.dot(tangent)  # along the wall (Eqs. 50-61 on its tangent)
            if opts.on("groove_friction"):
                friction, power = laws.coulomb(P["mu2"], normal, v_slide, P["v_eps"])  # gamma_i of Algorithm 1
                force = force + friction * tangent
                guards[f"v_{point}_slide"] = v_slide
            models.append(ContactModel(point, [Load(point, r, force, friction_power=power)], guard_name=gap_name,
                                       guard=gap, velocity_guards=guards, slide=v_slide))
        return models
