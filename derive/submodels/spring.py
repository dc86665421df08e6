"""Seal - spring contact at s6: Eqs. 35-39 and 69-74.

The spring sits on the groove axis and pushes along +X on the seal's back face,
at the point s6 where the face crosses the axis (Eq. 36). Its force is
ks times its compression, delta_s at rest less the outward travel of s6
(Eq. 38); it exists while the compression is positive (the spring can only push).

The law is written once, :meth:`SpringContact.push`: the model's contact force (:meth:`SpringContact.contacts`),
the spring's force at rest (:meth:`SpringContact.rest_force`), which the housing wall's rest deflection delta_w
balances (Eq. 9, ``SealBody.derived``), and the preload study's spring force all call it.
"""

from __future__ import annotations

from ..options import NONE, ON, Option
from ..parameters import Parameter
from .base import ContactModel, Context, Friction, Guard, Load, Submodel


class SpringContact(Submodel):
    name = "spring"
    summary = "the groove-bottom spring and its preload (Eqs. 35-39, 69-74)"
    switch = "spring"
    contact_meanings = {"spring": "groove-bottom spring Fs6 (Eqs. 37-39, 73)"}
    parameters = (
        Parameter("ks", "N/m", "spring stiffness (Eq. 39)", key="spring.ks", plausible=(100.0, 1e8, "N/m"), gt=0),
        Parameter("delta_s", "m", "spring preload deflection (Eq. 9)", key="spring.delta_s",
                  plausible=(0.0, 30e-3, "mm"), ge=0, sign="real", schedulable=True),
        Parameter("cs", "N*s/m", "seal-spring contact damping (Eq. 73); default 2 zeta_s sqrt(ks ms)",
                  key="contacts.cs", ge=0, optional=True, needs="spring_damping"),
        Parameter("zeta_s", "1", "damping ratio of the seal-spring contact: cs = 2 zeta_s sqrt(ks ms) unless "
                  "contacts.cs is given", key="contacts.zeta_s", default=0.1, ge=0, le=5, in_vector=False,
                  needs="spring_damping"),
        Parameter("mus", "1", "seal-spring friction coefficient (Eq. 73)", key="friction.mus", ge=0, lt=1,
                  needs="spring_friction"),
    )
    options = (
        Option("spring", (ON, NONE), "the groove-bottom spring and its preload, Eqs. 37-39"),
        Option("spring_damping", (ON, NONE), "damping at the seal-spring contact, Eq. 73", parent="spring"),
        Option("spring_friction", (ON, NONE), "Coulomb friction at the seal-spring contact, Eq. 73", parent="spring"),
    )
    guards = (Guard("spring", "s_sp", "minus the spring's compression (Eq. 38)", output="spring_compression",
                    sign=-1, closed_label="s", open_label="s0", closed_at_rest=True),)
    oscillators = (("ks", "cs"),)
    #: the back face slides across the spring at s6, ds2 behind the centre of gravity (Eq. 36), and sticks there
    #: whenever the seal's lateral motion reverses
    frictions = (Friction("mus", ("spring",), offsets=((-1.0, "ds2"),), slide="the seal's back face across the spring"),)
    damping_ratios = (("cs", "zeta_s"),)

    @staticmethod
    def push(compression, p):
        """Eq. 39: the spring's force (N, along +X) at a compression >= 0 (m), ks compression.

        ``p`` maps parameter names to values: the parameters' sympy symbols (``ctx.P``) in the model, numbers (or
        CasADi symbols) in a scene. The one place of the spring's law: a changed law (a progressive spring,
        ``p["ks"] * compression + p["k3"] * compression**3`` with a parameter k3 declared above) changes the model,
        the rest deflection delta_w of Eq. 9 and the preload study's spring force together.
        """
        return p["ks"] * compression

    @classmethod
    def rest_force(cls, p):
        """The spring's force at rest (Eq. 39 at the compression delta_s of Eq. 38, x = y = phi = 0), which the
        housing's rest deflection delta_w balances (Eq. 9). ``p`` as in :meth:`push`."""
        return cls.push(p["delta_s"], p)

    def contacts(self, ctx: Context) -> list[ContactModel]:
        """Fs6 = Fsp X + Fd_s6 + Ff_s6 (Eq. 74)."""
        import sympy as sp

        from . import laws

        k, g, P, opts = ctx.k, ctx.g, ctx.P, ctx.options
        G = k.G
        act = ctx.activation(self.guards[0])
        v = k.relative_velocity(g.r_s6)  # Eqs. 70-72
        closing = -v.dot(G.x)  # > 0 while the seal moves down into the spring
        guards = {"v_s6_n": closing}
        normal = act * self.push(sp.Max(g.spring_compression, 0), P)  # Eq. 39 (a spring cannot pull)
        if opts.on("spring_damping"):
            depth = laws.damper_depth(ctx, self.guards[0], g.spring_compression)  # 1: closed at rest
            normal = laws.damped(normal, P["cs"], closing, act, opts["damping"], depth)  # Eq. 73
        force, power = normal * G.x, sp.S.Zero
        v_slide = v.dot(G.y)  # the back face across the spring (Eqs. 70-72 along Y)
        if opts.on("spring_friction"):
            friction, power = laws.coulomb(P["mus"], normal, v_slide, P["v_eps"])  # Eq. 73
            force = force + friction * G.y
            guards["v_s6_slide"] = v_slide
        return [ContactModel("spring", [Load("s6", g.r_s6, force, friction_power=power)], guard_name="spring",
                             guard=-g.spring_compression, velocity_guards=guards, slide=v_slide)]
