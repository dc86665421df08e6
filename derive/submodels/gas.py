"""The chamber gas: mass and energy of the two chambers, flow through the ports and leakage past the seal.

Off by default; ``[pressure] source = "chamber"`` switches it on (``"chamber+leakage"`` also the leakage),
through the modelling choice ``pressure_model`` ("input": the pressures are the input u).
Each chamber (a on the seal's +Ys side, b on its -Ys side, Eq. 75) holds an ideal gas with constant specific
heats (air: gamma = 1.4, R = 287 J/(kg K), scene keys ``gas.gamma``, ``gas.R``); its states are its mass m and
internal energy U = m cv T, so that

    dm/dt = sum of the mass flows in,     dU/dt = sum of the enthalpy flows in - p dV/dt,
    p = (gamma - 1) U / V,                T = U / (m cv),

with V(theta) the chamber volume (derive/chambers.py, Eqs. 1-8) and dV/dt = omega dV/dtheta. The ports
(Table 1, derive/ports.py) connect each chamber to the supply (p_supply, T_supply) and to the exhaust
(p_exhaust, T_exhaust) through isentropic orifices (subsonic and choked, :func:`orifice_flow`); a flow
carries the enthalpy of where it comes from. With ``leakage`` on, the chambers exchange gas past the seal
through two orifices of depth H (Algorithm 4): the seal-groove gap b_gap (the smallest groove gap while every
groove contact is open, else 0) and the gap over the tip while it is lifted off the housing (-xs5, Eq. 33).
Both follow the seal's motion and its contact modes, so pressures and seal are one hybrid system.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..chambers import chamber_volume, lobe_area, symbolic
from ..numbers import housing_radius
from ..options import Option
from ..parameters import ABSOLUTE_PRESSURE, GAS_TEMPERATURE, Parameter
from .base import Context, State, Submodel

#: regularisation of the orifice law's square root near equal pressures: sqrt(x) ~ x / sqrt(x + X_EPS)
#: (finite slope at x = 0 for the Jacobians of the implicit methods; below 1e-6 relative to any ratio < 0.9999)
X_EPS = 1e-10


def orifice_flow(cd_area, p_up, T_up, p_down, gamma, R):
    """Mass flow (kg/s) through an isentropic orifice from p_up, T_up to p_down <= p_up (sympy).

    mdot = Cd A p_up / sqrt(R T_up) * sqrt(2 gamma / (gamma - 1) (pr^(2/gamma) - pr^((gamma + 1)/gamma))),
    pr = max(p_down / p_up, pr_crit), pr_crit = (2 / (gamma + 1))^(gamma / (gamma - 1)) (choked below it).
    """
    import sympy as sp

    from .laws import Max_, Min_  # never evaluated: sympy's Max compared these large arguments in every rebuild,
    # most of a cold derivation (docs/gas.md: 59 s, 11 s with these), for the same functions

    crit = (2 / (gamma + 1)) ** (gamma / (gamma - 1))
    pr = Max_(Min_(p_down / p_up, 1), crit)
    x = Max_(2 * gamma / (gamma - 1) * (pr ** (2 / gamma) - pr ** ((gamma + 1) / gamma)), 0)
    return cd_area * p_up / sp.sqrt(R * T_up) * x / sp.sqrt(x + X_EPS)


def signed_flow(cd_area, p1, T1, p2, T2, gamma, R):
    """Mass flow from side 1 to side 2 (negative: from 2 to 1), sympy."""
    import sympy as sp

    return sp.Piecewise((orifice_flow(cd_area, p1, T1, p2, gamma, R), p1 >= p2),
                        (-orifice_flow(cd_area, p2, T2, p1, gamma, R), True))


def enthalpy_flow(mdot, T1, T2, cp):
    """Enthalpy carried from side 1 to side 2 by ``mdot`` (from 1 to 2 when positive), at its source's T."""
    from .laws import Max_, Min_

    return cp * (T1 * Max_(mdot, 0) + T2 * Min_(mdot, 0))


class ChamberGas(Submodel):
    name = "gas"
    enters_with = ("pressure_model=chamber", "pressure_model=chamber+leakage")
    summary = "ideal gas in the two chambers: ports, leakage past the seal, Pa and Pb for Eq. 75"
    scene_inputs = ("machine.ports",)
    parameters = (
        Parameter("H_gas", "m", "machine depth H (machine.H) in the gas model's parameters: chamber volumes, "
                  "leakage areas"),
        Parameter("gamma", "1", "ratio of specific heats (air 1.4)", key="gas.gamma", default=1.4, gt=1, lt=2,
                  # 5/3 (a monatomic gas: helium, argon) is an ideal gas's largest (1.67: 5/3 rounded passes);
                  # heavy organic vapours of ORC expanders come close to 1 (siloxane MDM about 1.02)
                  plausible=(1.02, 1.67, "1")),
        Parameter("R_gas", "J/(kg*K)", "specific gas constant (air 287)", key="gas.R", default=287.0, gt=0,
                  # 8.314 J/(mol K) over the molar mass: hydrogen's 4124 down to about 24 for perfluorocarbons of
                  # 350 g/mol; the molar constant 8.314 itself, or 0.287 (air in kJ/(kg K)), is a unit slip
                  plausible=(20.0, 4200.0, "J/(kg*K)")),
        Parameter("p_supply", "Pa", "supply (inlet) pressure", key="gas.p_supply", default=6.0e5, gt=0,
                  plausible=ABSOLUTE_PRESSURE),
        Parameter("T_supply", "K", "supply (inlet) temperature", key="gas.T_supply", default=300.0, gt=0,
                  plausible=GAS_TEMPERATURE),
        Parameter("p_exhaust", "Pa", "exhaust (outlet) pressure", key="gas.p_exhaust", default=1.013e5, gt=0,
                  plausible=ABSOLUTE_PRESSURE),
        Parameter("T_exhaust", "K", "exhaust temperature (of gas flowing back in, and the chambers at the start)",
                  key="gas.T_exhaust", default=300.0, gt=0,
                  plausible=GAS_TEMPERATURE),
        Parameter("Cd_port", "1", "discharge coefficient of the ports (0 closes them)", key="gas.Cd_port",
                  default=0.8, ge=0, le=1),
        Parameter("Cd_leak", "1", "discharge coefficient of the leakage gaps past the seal", key="gas.Cd_leak",
                  default=0.8, ge=0, le=1),
        Parameter("A_lobe", "m^2", "area between the chord and a rotor lobe (derive/chambers.py)"),
        Parameter("housing_circle", "1", "1 for the circolimaçon's circular housing, 0 for the limaçon (Eq. 2)"),
        Parameter("port_in_angle", "rad", "inlet centre from the Xo axis: machine.ports datum + inlet angle",
                  sign="real"),
        Parameter("port_in_width", "rad", "inlet angular width (Table 1)"),
        Parameter("port_in_area", "m^2", "inlet full open area: length x housing radius x width"),
        Parameter("port_out_angle", "rad", "outlet centre from the Xo axis: machine.ports datum + outlet angle",
                  sign="real"),
        Parameter("port_out_width", "rad", "outlet angular width (Table 1)"),
        Parameter("port_out_area", "m^2", "outlet full open area: length x housing radius x width"),
    )
    options = (
        Option("pressure_model", ("input", "chamber", "chamber+leakage"), "where Pa, Pb come from: the input u "
               "(pressure.source none, constant, table), the chamber gas model, or the gas model with flow past the "
               "seal (Algorithm 4, tip lift-off); set by pressure.source", table="assumptions",
               set_by="pressure.source"),
    )
    states = (
        State("ma", "kg", "mass of the gas in chamber a", 1e-3, display="mg", display_scale=1e6),
        State("Ua", "J", "internal energy of the gas in chamber a", 1e2),
        State("mb", "kg", "mass of the gas in chamber b", 1e-3, display="mg", display_scale=1e6),
        State("Ub", "J", "internal energy of the gas in chamber b", 1e2),
    )
    #: its outputs besides the chamber pressures Pa and Pb (the run's inputs otherwise: runtime/results/outputs.py)
    output_columns = (
        ("Va", "m^3", "volume of chamber a (Eqs. 1-8; gas model, formulas in derive/chambers.py)", "cm^3", 1e6),
        ("Vb", "m^3", "volume of chamber b (Eqs. 1-8; gas model, formulas in derive/chambers.py)", "cm^3", 1e6),
        ("Ta", "K", "temperature of the gas in chamber a"),
        ("Tb", "K", "temperature of the gas in chamber b"),
        ("mdot_in_a", "kg/s", "mass flow from the supply through the inlet port into chamber a", "g/s", 1e3),
        ("mdot_in_b", "kg/s", "mass flow from the supply through the inlet port into chamber b", "g/s", 1e3),
        ("mdot_out_a", "kg/s", "mass flow from chamber a through the outlet port to the exhaust", "g/s", 1e3),
        ("mdot_out_b", "kg/s", "mass flow from chamber b through the outlet port to the exhaust", "g/s", 1e3),
        ("mdot_leak_groove", "kg/s", "leakage from chamber a to b through the seal-groove gap b_gap*H (Algorithm 4)",
         "g/s", 1e3),
        ("mdot_leak_tip", "kg/s", "leakage from chamber a to b over the seal tip while it is lifted off the housing",
         "g/s", 1e3),
    )

    @classmethod
    def derived(cls, values: dict[str, float], inputs: Mapping[str, Any], options) -> dict[str, float]:
        """The lobe area and housing kind of the embodiment, and each port's angle, width and full area."""
        m = inputs["machine"]
        circle = m.embodiment == "circolimacon"
        out = {"H_gas": values["H"],
               "A_lobe": lobe_area(m.embodiment, r=values["r"], L=values["L"], Cr=values["Cr"], k=values["k"]),
               "housing_circle": 1.0 if circle else 0.0}
        ports = getattr(m, "ports", None)
        for short, name in (("in", "inlet"), ("out", "outlet")):
            port = getattr(ports, name, None) if ports is not None else None
            if port is None:  # no ports given: closed
                out.update({f"port_{short}_angle": 0.0, f"port_{short}_width": 1.0, f"port_{short}_area": 0.0})
                continue
            angle = port.angle + ports.datum
            rho = housing_radius(angle, r=values["r"], L=values["L"], circle=circle)
            out.update({f"port_{short}_angle": angle, f"port_{short}_width": port.width,
                        f"port_{short}_area": port.length * rho * port.width})
        return out

    @classmethod
    def initial_state(cls, values: Mapping[str, float], theta: float) -> dict[str, float]:
        """Both chambers at the exhaust pressure and temperature."""
        out = {}
        g, R, p, T = values["gamma"], values["R_gas"], values["p_exhaust"], values["T_exhaust"]
        for side, c in ((1, "a"), (-1, "b")):
            V = chamber_volume(side, theta, r=values["r"], L=values["L"], H=values["H_gas"], A_lobe=values["A_lobe"],
                               housing_circle=values["housing_circle"])
            out[f"m{c}"] = p * V / (R * T)
            out[f"U{c}"] = p * V / (g - 1)
        return out

    # -- the equations (sympy) -------------------------------------------------

    def _gas(self, ctx: Context) -> dict[str, Any]:
        """Every quantity of the gas model, by name (sympy, memoised per context)."""
        memo = getattr(self, "_memo", None)
        if memo is not None and memo[0] is ctx:
            return memo[1]
        import sympy as sp

        from .. import ports
        from ..symbols import theta

        P, X = ctx.P, ctx.X
        g, R = P["gamma"], P["R_gas"]
        cv, cp = R / (g - 1), g * R / (g - 1)
        H = P["H_gas"]
        q: dict[str, Any] = {}
        for side, c in ((1, "a"), (-1, "b")):
            V = chamber_volume(side, theta, r=P["r"], L=P["L"], H=H, A_lobe=P["A_lobe"],
                               housing_circle=P["housing_circle"], ops=symbolic())  # Eqs. 1-8
            q[f"V{c}"], q[f"dV{c}"] = V, P["omega"] * sp.diff(V, theta)
            q[f"P{c}"] = (g - 1) * X[f"U{c}"] / V
            q[f"T{c}"] = X[f"U{c}"] / (X[f"m{c}"] * cv)
        ps, Ts, pe, Te = P["p_supply"], P["T_supply"], P["p_exhaust"], P["T_exhaust"]
        fin = ports.open_fractions(theta, P["port_in_angle"], P["port_in_width"])
        fout = ports.open_fractions(theta, P["port_out_angle"], P["port_out_width"])
        for i, c in enumerate("ab"):
            a_in = P["Cd_port"] * P["port_in_area"] * fin[i]
            a_out = P["Cd_port"] * P["port_out_area"] * fout[i]
            q[f"mdot_in_{c}"] = signed_flow(a_in, ps, Ts, q[f"P{c}"], q[f"T{c}"], g, R)  # supply -> chamber
            q[f"mdot_out_{c}"] = signed_flow(a_out, q[f"P{c}"], q[f"T{c}"], pe, Te, g, R)  # chamber -> exhaust
            q[f"H_in_{c}"] = enthalpy_flow(q[f"mdot_in_{c}"], Ts, q[f"T{c}"], cp)
            q[f"H_out_{c}"] = enthalpy_flow(q[f"mdot_out_{c}"], q[f"T{c}"], Te, cp)
        q["mdot_leak_groove"] = q["mdot_leak_tip"] = sp.S.Zero
        if ctx.options["pressure_model"] == "chamber+leakage":
            b_gap, b_tip = self._gaps(ctx)
            for path, gap in (("groove", b_gap), ("tip", b_tip)):
                q[f"mdot_leak_{path}"] = signed_flow(P["Cd_leak"] * gap * H, q["Pa"], q["Ta"], q["Pb"], q["Tb"], g, R)
        leak = q["mdot_leak_groove"] + q["mdot_leak_tip"]  # from a to b
        q["H_leak"] = enthalpy_flow(leak, q["Ta"], q["Tb"], cp)
        q["dma"] = q["mdot_in_a"] - q["mdot_out_a"] - leak
        q["dmb"] = q["mdot_in_b"] - q["mdot_out_b"] + leak
        q["dUa"] = q["H_in_a"] - q["H_out_a"] - q["H_leak"] - q["Pa"] * q["dVa"]
        q["dUb"] = q["H_in_b"] - q["H_out_b"] + q["H_leak"] - q["Pb"] * q["dVb"]
        self._memo = (ctx, q)
        return q

    @staticmethod
    def _gaps(ctx: Context):
        """b_gap of Algorithm 4 (0 while any groove contact is closed) and the tip's lift-off (0 while it touches)."""
        from ..modes import GROOVE_GUARDS
        from .laws import Max_, Min_
        from .registry import guard

        g, opts = ctx.g, ctx.options
        b_gap = Max_(Min_(*[g.gaps[n] for n in GROOVE_GUARDS]), 0)
        if opts.on("groove_contact"):
            for n in GROOVE_GUARDS:
                b_gap = b_gap * (1 - ctx.activation(guard(n)))
        b_tip = Max_(-g.xs5, 0)
        if opts.on("housing_contact"):
            b_tip = b_tip * (1 - ctx.activation(guard("xs5")))
        return b_gap, b_tip

    def rates(self, ctx: Context) -> dict[str, Any]:
        q = self._gas(ctx)
        return {n: q["d" + n] for n in ("ma", "Ua", "mb", "Ub")}

    def chamber_pressures(self, ctx: Context):
        q = self._gas(ctx)
        return q["Pa"], q["Pb"]

    def outputs(self, ctx: Context) -> dict[str, Any]:
        q = self._gas(ctx)
        return {n: q[n] for n in ("Pa", "Pb", *(c[0] for c in self.output_columns))}

