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
        Option("housing_stiffness", ("groove-axis", "normal", "tilted-wall"), "kw xs5 is the groove-axis (X) "
               "component of the housing force, as Algorithm 2 prints ('groove-axis'), or the normal force, kw times "
               "the normal penetration xs5 cos(lambda) ('normal'), or, not in the paper, kw times the penetration of "
               "the tip arc into the housing wall tilted by lambda, along its normal, with the force at the arc's "
               "contact point ('tilted-wall': the seal's slide y across its groove moves the tip towards the wall by "
               "-y sin(lambda)); cw damps the rate of the same penetration", table="assumptions"),
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
        from ..kinematics import plain, t, theta_t
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
        r_touch, guard = g.r_s5, -g.xs5
        if opts["housing_stiffness"] == "tilted-wall":
            depth, r_touch = tilted_wall_penetration(k, lam)
            closing, guard = plain(depth.diff(t)), -plain(depth)
            depth = plain(depth)
            v_abs = k.point_on_seal("s5", r_touch).vel(k.N)  # the seal's material point where the arc touches
            velocity_guards["v_s5_X"] = closing
        else:
            # the penetration and its rate along the direction kw and cw act: the groove axis, xs5 and v_rel . X
            # (Eq. 34, Algorithm 2), or the housing normal, whose depth in the wall tilted by lambda is xs5 cos(lambda)
            along = sp.S.One if groove_axis else sp.cos(lam)
            depth, closing = g.xs5 * along, closing * along
        Fw = laws.penalty(P["kw"], depth, act)  # Eq. 34: X component or normal force (a contact cannot pull)
        if opts.on("housing_damping"):
            Fw = laws.damped(Fw, P["cw"], closing, act, opts["damping"],
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
        load = Load("s5", r_touch, force, friction_power=power)
        return [ContactModel("housing", [load], guard_name="xs5", guard=guard, velocity_guards=velocity_guards,
                             slide=v_slide)]


def tilted_wall_penetration(k, lam):
    """(penetration, contact point from C) of the tip arc in the housing wall tilted by ``lam`` (lambda, Eq. 9), as
    time-dependent expressions (``housing_stiffness = "tilted-wall"``, not in the paper).

    The wall is the parallel curve of the arc's rest position (x = y = phi = 0) at the depth delta_w of Eq. 9: the
    housing the tip runs on without a stroke, as the paper's wall X = ds1 - delta_w (Eq. 33) is, but with its normal
    tilted by lambda from the groove axis as the force's (Algorithm 2). Its penetration is delta_w plus the
    displacement of the arc's centre Co (Eqs. 25, 77) from its rest position along the wall's normal into the wall,
    m = cos(lambda) X - sin(lambda) Y: the slide y across the groove moves the tip by -y sin(lambda), which the
    paper's wall, perpendicular to X, does not see. The arc touches where its normal is the wall's, ro along m from
    Co: the contact force passes through Co."""
    import sympy as sp

    from .. import seal_shape as shape
    from ..symbols import P

    G = k.G
    m = sp.cos(lam) * G.x - sp.sin(lam) * G.y
    r_Co = shape.tip_centre(k.S)
    Co_rest = (P["ds1"] - P["ro"]) * G.x
    depth = P["delta_w"] + (k.C.pos_from(k.Og) + r_Co - Co_rest).dot(m)
    return depth, r_Co + P["ro"] * m
