"""The seal body: the machine and seal geometry, the seal's mass, the rotor's inertial loads (Eqs. 1-31, 80).

Always on. It owns the parameters every contact shares (geometry, mass, speed), the parameters derived
from them (plain numeric functions, no sympy: the rotor speed, the seal's mass and inertia, the tip arc's
half-angle, the groove truncation, the housing wall's initial deflection and the seal's rest position), the
``inertia`` effect (Eq. 15) and the rules of the shared contact laws (the damping rule, the damping law and its
reference penetration, the width of the friction regularisation).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from ..numbers import (
    initial_wall_deflection,
    initial_wall_deflection_normal,
    initial_wall_deflection_tilted,
    machine_numbers,
    outline_mass,
    tip_half_angle,
)
from ..options import NONE, ON, Option
from ..parameters import Parameter
from .base import State, Submodel
from .damping_rule import DAMPING_LAWS
from .spring import SpringContact

#: the largest tilt (rad) of the seal in its groove that the model's geometry describes: Eqs. 20-43 hold for a seal
#: tilted by a few degrees (the paper's nine contact cases end near 11 deg); 45 deg is a seal turned over. A run
#: stops past it (runtime/solving/checks.py, RunChecks.tilt), and a scene's initial tilt must lie within it
MAX_TILT = math.pi / 4
#: kg/m^3: the density of osmium, the densest material; the bound of seal.density, and with the seal's outline of
#: its mass seal.ms (runtime/scenes/checks.py)
DENSEST = 22590.0


def rest_force(values, options) -> Any:
    """The force along the groove axis that the model's laws put on the seal at rest, which the housing balances
    (Eq. 9): the spring's (``SpringContact.rest_force``, Eq. 39) and every other submodel's of the model of
    ``options`` (``Submodel.rest_force``: 0 but for a load of one's own that acts at rest). ``values``: the
    parameters by name (numbers, or CasADi or sympy symbols)."""
    from .registry import submodels

    return SpringContact.rest_force(values) + sum(cls.rest_force(values) for cls in submodels()
                                                  if cls is not SpringContact and cls.active(options))


class SealBody(Submodel):
    name = "seal"
    summary = "the seal as a rigid body in its groove: geometry, mass, the rotor's inertial loads (Eqs. 1-31, 80)"
    parameters = (
        Parameter("omega", "rad/s", "rotor angular speed, constant (Eq. 13); from operation.rpm"),
        Parameter("r", "m", "radius of the limaçon base circle (Eq. 1)", key="machine.r",
                  plausible=(0.5e-3, 0.5, "mm"), gt=0),
        Parameter("L", "m", "half chord of the rotor (Eq. 2)", key="machine.L", plausible=(2e-3, 2.0, "mm"), gt=0),
        Parameter("H", "m", "machine depth along the axis (Algorithm 4)", key="machine.H",
                  plausible=(2e-3, 2.0, "mm"), gt=0, in_vector=False),
        Parameter("Cr", "m", "rotor-housing clearance: of circular lobes (Eqs. 5, 8), and of every lobe in the gas "
                  "model's chamber volumes", key="machine.Cr", default=0.0,
                  ge=0, in_vector=False),
        Parameter("k", "m", "offset of a circular lobe's centre on the Yr axis (Eq. 5)", key="machine.k",
                  default=0.0, sign="real", in_vector=False),
        Parameter("Li", "m", "distance from the chord centre to the seal's centre of gravity at rest (Eq. 12): "
                  "L - ds1 + delta_w"),
        Parameter("delta_w", "m", "initial deflection of the housing wall (Eq. 9): the spring's force at rest "
                  "(Eq. 39) / kw", sign="real"),
        Parameter("Ws", "m", "seal width (Eq. 19)", key="seal.Ws", plausible=(0.3e-3, 30e-3, "mm"), gt=0),
        Parameter("Wg", "m", "groove width (Eq. 17)", key="seal.Wg", plausible=(0.3e-3, 30e-3, "mm"), gt=0),
        Parameter("ds1", "m", "centre of gravity to the seal tip along Xs (Eq. 16)", key="seal.ds1",
                  plausible=(0.2e-3, 50e-3, "mm"), gt=0),
        Parameter("ds2", "m", "centre of gravity to the seal back face along Xs (Eq. 16)", key="seal.ds2",
                  plausible=(0.2e-3, 50e-3, "mm"), gt=0),
        Parameter("ro", "m", "radius of the seal's tip arc (Eq. 27)", key="seal.ro", gt=0,
                  plausible=(0.2e-3, 10.0, "mm")),  # a tip radius of metres stands for a flat tip
        Parameter("beta_o", "rad", "half-angle of the tip arc, asin(Ws / (2 ro)) (Eqs. 24, 76-78)"),
        Parameter("Bs", "m", "seal length along the machine axis (Eq. 76)", key="seal.Bs",
                  plausible=(2e-3, 2.0, "mm"), gt=0),
        Parameter("density", "kg/m^3", "seal material density", key="seal.density", gt=0, optional=True,
                  le=DENSEST, in_vector=False,  # no material is denser than osmium
                  plausible=(500.0, 20000.0, "kg/m^3")),  # polymers and carbon to carbides
        Parameter("ms", "kg", "seal mass (Eq. 80); default density Ws (ds1 + ds2) Bs", key="seal.ms",
                  plausible=(1e-4, 2.0, "g"), gt=0, optional=True),
        Parameter("Icg", "kg*m^2", "seal moment of inertia about its centre of gravity (Eq. 80); default "
                  "ms (Ws^2 + (ds1 + ds2)^2) / 12", key="seal.Icg", gt=0, optional=True),
        Parameter("zeta0", "m", "initial protrusion of the seal out of the groove (Eq. 17); default the groove "
                  "truncation z of Eqs. 6-8", key="seal.zeta0", plausible=(1e-6, 30e-3, "mm"), ge=0, optional=True,
                  sign="real"),
        Parameter("v_eps", "m/s", "sliding-speed width of the friction regularisation tanh(v / v_eps)",
                  key="friction.v_eps", default=1e-3, gt=0,
                  needs=("housing_friction", "groove_friction", "spring_friction")),
        Parameter("delta_ref", "m", "reference penetration of the damping law 'penetration': a contact's damper is "
                  "c max(v, 0) delta / delta_ref, the paper's c max(v, 0) at delta = delta_ref (Hunt-Crossley type, "
                  "not in the paper)", key="contacts.delta_ref", default=30e-9, gt=0, le=1e-3, show="nm",
                  plausible=(1e-10, 1e-5, "nm"), needs=f"damping_law={DAMPING_LAWS[1]}"),
    )
    #: the mass stated two ways: seal.density only gives ms (Icg follows from ms), so a given ms makes it unread (a
    #: scene that gives both warns), and an override of one replaces the other (a scene's density and an ms set on
    #: top of it disagreed silently)
    supersedes = (("seal.ms", "seal.density"),)
    #: the scene's operation.initial_state takes one key per state (runtime/scenes/schema.py); its limits refuse only
    #: the absurd (a unit slip, an overflow): a seal displaced by a metre, tilted beyond MAX_TILT, or moving faster
    #: than 1 km/s in its groove
    states = (
        State("x", "m", "the seal's centre of gravity along the groove axis Xg, out of the groove (Eq. 10)", 1e-6,
              initial_limit=1.0),
        State("y", "m", "the seal's centre of gravity across the groove, along Yg (Eq. 10)", 1e-6, initial_limit=1.0),
        State("phi", "rad", "the seal's tilt from the groove axis (Eq. 11)", 1e-3, show="deg",
              initial_limit=MAX_TILT),
        State("xd", "m/s", "dx/dt", 1e-6, rate=True, initial_limit=1e3),
        State("yd", "m/s", "dy/dt", 1e-6, rate=True, initial_limit=1e3),
        State("phid", "rad/s", "dphi/dt", 1e-3, rate=True, initial_limit=1e6),
    )
    options = (
        Option("inertia", (ON, NONE), "rotor-motion inertial loads on the seal: centrifugal, Coriolis, chord "
               "translation (Eq. 15)"),
        Option("damping", ("in-contact", "always"), "contact damping (Eqs. 55, 62, 67, 73) acts on approach only; "
               "'in-contact' also requires the contact to be closed, 'always' applies the printed velocity rule alone",
               table="assumptions"),
        Option("damping_law", DAMPING_LAWS, "the contact dampers of the housing and groove contacts: the paper's "
               "c max(v, 0) (Eqs. 55, 62, 67), which jumps from 0 to c v at the touch ('velocity'), or c max(v, 0) "
               "delta / delta_ref, delta the penetration (contacts.delta_ref; of the Hunt-Crossley family: Hunt & "
               "Crossley, J. Appl. Mech. 42(2), 1975; not in the paper), continuous at the touch ('penetration'); "
               "the preloaded spring keeps the paper's law (Eq. 73)",
               table="assumptions"),
    )

    @classmethod
    def derived(cls, values: dict[str, float], inputs: Mapping[str, Any], options) -> dict[str, float]:
        """omega, ms, Icg, beta_o (Eq. 24), zeta0 (Eqs. 6-8), delta_w (Eq. 9) and Li (Eq. 12), as numbers.

        ``Li = L - ds1 + delta_w``: the seal tip, ds1 above C, then presses delta_w into the housing at
        Rh - 2 r sin(theta) = L from the chord centre, as Eq. 33 assumes. ``delta_w`` balances the spring's
        preload on the housing at rest when both are on, else 0 (nothing presses the seal on the housing): with the
        groove-axis component of the housing force (Eq. 9), or, under housing_stiffness = "normal", with the X
        component of the normal force and its friction at theta = 0 (numbers.initial_wall_deflection_normal; under
        "tilted-wall", numbers.initial_wall_deflection_tilted).
        """
        v = values
        out: dict[str, float] = {"omega": inputs["operation"].omega}
        ds = v["ds1"] + v["ds2"]
        ms = v["ms"] if v.get("ms") is not None else outline_mass(v["density"], Ws=v["Ws"], ds1=v["ds1"],
                                                                  ds2=v["ds2"], Bs=v["Bs"])
        out["ms"] = ms
        out["Icg"] = v["Icg"] if v.get("Icg") is not None else ms * (v["Ws"] ** 2 + ds**2) / 12
        out["beta_o"] = tip_half_angle(v["Ws"], v["ro"])
        if v.get("zeta0") is None:
            m = inputs["machine"]
            out["zeta0"] = machine_numbers(m.embodiment, r=v["r"], L=v["L"], Wg=v["Wg"], Cr=v["Cr"], k=v["k"]).truncation
        out["delta_w"] = cls.rest_wall_deflection(v, options)
        out["Li"] = v["L"] - v["ds1"] + out["delta_w"]
        return out

    @staticmethod
    def rest_wall_deflection(values, options):
        """delta_w, Eq. 9: the housing wall's deflection that balances the spring's force at rest
        (``SpringContact.rest_force``, Eq. 39), and that of any other submodel of the model whose laws act at rest
        (``Submodel.rest_force``: a package's load), when the spring and the housing contact are both on, else 0.

        With the groove-axis component of the housing force kw delta_w, or, under housing_stiffness = "normal", the
        X component of the normal force and its friction at theta = 0 (numbers.initial_wall_deflection_normal; under
        "tilted-wall", the arc's penetration, numbers.initial_wall_deflection_tilted).
        ``values``: the parameters by name (numbers; delta_s, ks may be CasADi symbols). The derivation checks that
        the model's laws balance at rest with it (derive/rest_balance.py)."""
        v = values
        if not (options.on("spring") and options.on("housing_contact")):
            return 0.0
        force = rest_force(v, options)
        stiffness = options["housing_stiffness"]
        if stiffness in ("normal", "tilted-wall"):  # kw on a normal penetration: its X component balances
            mu1 = v["mu1"] if options.on("housing_friction") else 0.0
            deflection = initial_wall_deflection_normal if stiffness == "normal" else initial_wall_deflection_tilted
            return deflection(spring_force=force, kw=v["kw"], r=v["r"], L=v["L"], mu1=mu1)
        return initial_wall_deflection(spring_force=force, kw=v["kw"])
