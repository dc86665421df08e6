"""Seal tip - housing contact: Eqs. 33-34, 64-68 and Algorithm 2.

Normal and friction follow from the housing curve: the inward normal of the
limaçon at the apex leans from -X by lambda (Eq. 9), its tangent points along the
rotation. The elastic law is the paper's: kw xs5 is the groove-axis component of
the contact force (``housing_stiffness = "groove-axis"``), or the normal force from
the normal penetration xs5 cos(lambda) (``"normal"``); the damper cw acts on the rate
of the same penetration.
"""

from __future__ import annotations

from ..options import NONE, ON, Option
from ..parameters import CONTACT_STIFFNESS, Parameter
from .base import ContactModel, Context, Guard, Load, Submodel


class HousingContact(Submodel):
    name = "housing"
    summary = "the seal tip on the housing wall (Eqs. 33-34, 64-68, Algorithm 2)"
    switch = "housing_contact"
    contact_meanings = {"housing": "seal-housing contact Fs5 (Algorithm 2, Eq. 68)"}
    parameters = (
        Parameter("kw", "N/m", "equivalent housing stiffness along the groove axis (Eq. 34)", key="contacts.kw",
                  plausible=CONTACT_STIFFNESS, gt=0),
        Parameter("cw", "N*s/m", "housing contact damping (Eq. 67); default 2 zeta_w sqrt(kw ms)", key="contacts.cw",
                  ge=0, optional=True, needs="housing_damping"),
        Parameter("zeta_w", "1", "damping ratio of the housing contact: cw = 2 zeta_w sqrt(kw ms) unless "
                  "contacts.cw is given", key="contacts.zeta_w", default=0.1, ge=0, le=5, in_vector=False,
                  needs="housing_damping"),
        Parameter("mu1", "1", "seal-housing friction coefficient (Algorithm 2)", key="friction.mu1", ge=0, lt=1,
                  needs="housing_friction"),
    )
    options = (
        Option("housing_contact", (ON, NONE), "elastic seal tip-housing contact, Eqs. 33-34"),
        Option("housing_damping", (ON, NONE), "damping of the tip-housing contact, Eq. 67", parent="housing_contact"),
        Option("housing_friction", (ON, NONE), "Coulomb friction at the tip, Algorithm 2", parent="housing_contact"),
        Option("housing_stiffness", ("groove-axis", "normal"), "kw xs5 is the groove-axis (X) component of the "
               "housing force, as Algorithm 2 prints ('groove-axis'), or the normal force, kw times the normal "
               "penetration xs5 cos(lambda) ('normal'); cw damps the rate of the same penetration",
               table="assumptions"),
    )
    guards = (Guard("xs5", "s_h", "minus the tip's penetration into the housing wall (Eq. 33)", output="xs5",
                    sign=-1, closed_label="h", open_label="h0"),)
    oscillators = (("kw", "cw"),)
    #: no friction law that sticks: the tip slides along the housing at (L - 2 r) omega to (L + 2 r) omega (4.7 to
    #: 11 m/s in the default scene), never near 0, where tanh(v / v_eps) is steep (docs/hard-cases.md)
    frictions = ()
    damping_ratios = (("cw", "zeta_w"),)

    def contacts(self, ctx: Context) -> list[ContactModel]:
        """Fs5 = Fs5x + Fs5y at s5 (Eq. 68); its moment follows from where it acts."""
        import sympy as sp

        from ..geometry import housing_normal_angle
        from ..kinematics import theta_t
        from ..symbols import theta
        from . import laws

        k, g, P, opts = ctx.k, ctx.g, ctx.P, ctx.options
        G = k.G
        act = ctx.activation(self.guards[0])
        lam = housing_normal_angle().subs(theta, theta_t)
        n_in = -sp.cos(lam) * G.x + sp.sin(lam) * G.y  # housing normal, pointing into the seal
        t_fwd = sp.sin(lam) * G.x + sp.cos(lam) * G.y  # housing tangent, along the rotation

        s5 = k.point_on_seal("s5", g.r_s5)
        v_abs = s5.vel(k.N)  # Eqs. 64-66: absolute velocity of the seal's point at s5
        v_rel = k.relative_velocity(g.r_s5)  # the same point relative to the groove (and the model's wall)
        # the model's wall is fixed in the groove frame at X = ds1 - delta_w, so the tip
        # approaches it at v_rel . X (Eq. 67 prints the absolute velocity instead: see errata)
        closing = v_rel.dot(G.x)
        velocity_guards = {"v_s5_X": closing}

        groove_axis = opts["housing_stiffness"] == "groove-axis"
        # the penetration and its rate along the direction kw and cw act: the groove axis, xs5 and v_rel . X (Eq. 34,
        # Algorithm 2), or the housing normal, whose depth in the wall tilted by lambda is xs5 cos(lambda)
        along = sp.S.One if groove_axis else sp.cos(lam)
        depth = g.xs5 * along
        Fw = laws.penalty(P["kw"], depth, act)  # Eq. 34: X component or normal force (a contact cannot pull)
        if opts.on("housing_damping"):
            Fw = laws.damped(Fw, P["cw"], closing * along, act, opts["damping"],
                             laws.damper_depth(ctx, self.guards[0], depth))

        v_slide = v_abs.dot(t_fwd)  # the tip along the housing (Eqs. 64-66 on the tangent), > 0 along the rotation
        if opts.on("housing_friction"):
            velocity_guards["v_s5_slide"] = v_slide
            if groove_axis:
                # X component of N n_in - mu1 sigma N t_fwd equals -Fw (Algorithm 2)
                normal = Fw / (sp.cos(lam) + P["mu1"] * laws.slip_sign(v_slide, P["v_eps"]) * sp.sin(lam))
            else:
                normal = Fw
            friction, power = laws.coulomb(P["mu1"], normal, v_slide, P["v_eps"])
            force = normal * n_in + friction * t_fwd
        else:
            normal = Fw / sp.cos(lam) if groove_axis else Fw
            force, power = normal * n_in, sp.S.Zero
        load = Load("s5", g.r_s5, force, friction_power=power)
        return [ContactModel("housing", [load], guard_name="xs5", guard=-g.xs5, velocity_guards=velocity_guards,
                             slide=v_slide)]
