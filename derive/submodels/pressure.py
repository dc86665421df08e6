"""Chamber gas pressure on the seal: Eqs. 75-79.

Chamber a (pressure Pa) lies on the seal's +Ys side, chamber b (Pb) on its -Ys
side. Each face carries its pressure times its area; the tip arcs are integrated
over the arc (their resultants pass through the arc centre Co, which fixes their
lines of action, Eqs. 77-78). The groove-bottom pressure Pend and the side-gap
pressures Ps2, Ps4 follow the options ``pend_rule`` and ``gap_pressure``.
"""

from __future__ import annotations

from ..options import NONE, ON, Option
from .base import ContactModel, Context, Submodel


def groove_bottom_pressure(Pa, Pb, rule: str, closed=None):
    """Pend under the seal's back face (Eq. 75 and the text after Eq. 76).

    ``rule`` "mean": (Pa + Pb)/2; "half-difference": the text's literal (Pa - Pb)/2; "open-side": the pressure of
    the chamber whose side of the groove is open from the mouth to the back corner, so that its gas reaches the
    groove bottom (chamber b on the seal's negative side, gaps b1 and b2 open; chamber a on its positive side, b3
    and b4 open), the mean when both sides or neither are open. ``closed``: the activations (1 while closed) of
    b1..b4, by guard name, which "open-side" needs (without the groove's contacts it is the mean)."""
    if rule == "half-difference":
        return (Pa - Pb) / 2
    mean = (Pa + Pb) / 2
    if rule == "mean" or closed is None:
        return mean
    open_b = (1 - closed["b1"]) * (1 - closed["b2"])
    open_a = (1 - closed["b3"]) * (1 - closed["b4"])
    only_a, only_b = open_a * (1 - open_b), open_b * (1 - open_a)
    return only_a * Pa + only_b * Pb + (1 - only_a - only_b) * mean


def tip_arc_force(k, P, pressure, a0, a1):
    """Resultant of a pressure on the tip arc between arc angles a0 < a1 (Eqs. 75-78).

    -integral of p n(alpha) ro Bs d(alpha), n the outward normal (cos alpha, sin alpha) in Xs Ys.
    """
    import sympy as sp

    alpha = sp.Symbol("alpha", real=True)
    S = k.S
    fx = -pressure * P["ro"] * P["Bs"] * sp.integrate(sp.cos(alpha), (alpha, a0, a1))
    fy = -pressure * P["ro"] * P["Bs"] * sp.integrate(sp.sin(alpha), (alpha, a0, a1))
    return fx * S.x + fy * S.y


class ChamberPressure(Submodel):
    name = "pressure"
    summary = "the gas pressures of the two chambers on the seal's faces and tip (Eqs. 75-79)"
    switch = "chamber_pressure"
    #: the constant chamber pressures (the model's input u of pressure.source = "constant"), read while it acts
    scene_inputs = ("pressure.Pa", "pressure.Pb")
    contact_meanings = {"pressure": "chamber pressure on the seal (Eq. 75)"}
    options = (
        Option("chamber_pressure", (ON, NONE), "gas pressure of the two chambers on the seal, Eqs. 75-79"),
        Option("pend_rule", ("mean", "half-difference", "open-side"), "groove-bottom pressure Pend under the seal "
               "(Eq. 75): the mean (Pa + Pb)/2, the text's literal 'half the difference' (Pa - Pb)/2, or 'open-side': "
               "the pressure of the chamber whose side of the groove is open from mouth to back corner (b1, b2 > 0: "
               "Pb; b3, b4 > 0: Pa), the mean when both or neither are", table="assumptions"),
        Option("gap_pressure", ("open-side", "chamber"), "side-gap pressures Ps2, Ps4 (Eq. 75, no rule printed): "
               "'open-side' = the chamber's pressure while the mouth contact on that side is open (b1 > 0, b3 > 0), "
               "else Pend; 'chamber' = always the chamber's", table="assumptions"),
    )

    def contacts(self, ctx: Context) -> list[ContactModel]:
        """Fs1..Fs4, Fs7, Fs8, Fs9 (Eq. 75) at s1..s4, s7 and on the arcs through Co."""
        from .. import seal_shape as shape
        from .base import Load
        from .registry import guard

        k, g, P, opts, Pa, Pb = ctx.k, ctx.g, ctx.P, ctx.options, ctx.Pa, ctx.Pb
        S, Bs = k.S, P["Bs"]
        grooved = opts.on("groove_contact")
        closed = {b: ctx.activation(guard(b)) for b in ("b1", "b2", "b3", "b4")} if grooved else None
        Pend = groove_bottom_pressure(Pa, Pb, opts["pend_rule"], closed)
        if opts["gap_pressure"] == "open-side" and grooved:
            # the gap between seal side and groove sees its chamber while the mouth is open, else the groove bottom
            Ps2 = (1 - closed["b1"]) * Pb + closed["b1"] * Pend
            Ps4 = (1 - closed["b3"]) * Pa + closed["b3"] * Pend
        else:
            Ps2, Ps4 = Pb, Pa
        beta, beta_o = g.beta, shape.beta_o
        r_Co = shape.tip_centre(S)
        loads = [
            Load("s1", g.r_s1, Pb * g.l1 * Bs * S.y),  # Eqs. 75-76
            Load("s2", g.r_s2, Ps2 * g.l2 * Bs * S.y),
            Load("s3", g.r_s3, -Pa * g.l3 * Bs * S.y),
            Load("s4", g.r_s4, -Ps4 * g.l4 * Bs * S.y),
            Load("s7", -P["ds2"] * S.x, Pend * P["Ws"] * Bs * S.x),
            Load("s8", r_Co, tip_arc_force(k, P, Pb, -beta_o, beta)),  # chamber b: arc from c1 to s5
            Load("s9", r_Co, tip_arc_force(k, P, Pa, beta, beta_o)),  # chamber a: arc from s5 to c3
        ]
        return [ContactModel("pressure", loads)]
