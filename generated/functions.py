"""The model's CasADi Functions, built from a :class:`~apexseal.derive.model.DerivedModel`.

``build_functions(model)`` lowers the sympy expressions to SX once and returns a
:class:`ModelFunctions`: the right-hand side with the contact activations as an
input (``rhs``) and its Jacobian (``rhs_jac``, named ``jac_rhs`` so that
``casadi.external("rhs", so)`` finds it), one smooth right-hand side per mode of
the hybrid model with the activations fixed (``mode_<label>``, each with its
Jacobian), the contact and velocity guards, the named outputs, and
``rhs_switched``, which computes the activations from the guards (for fixed-step
methods). Argument order everywhere: crank angle ``theta``, state ``x`` (6),
[activations ``a``], parameters ``p`` (named: ``parameter_names``, the submodels' declarations),
chamber pressures ``u = [Pa, Pb]``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import casadi as ca
import sympy as sp

from ..derive import symbols as sym
from ..derive.modes import GAP_GUARDS, Mode, Ops, gap_width, modes
from .lower import Lowering


@dataclass
class Arguments:
    """The SX symbols of the Functions' inputs and the sympy -> SX lowering that uses them."""

    theta: ca.SX
    x: ca.SX
    a: ca.SX
    p: ca.SX
    u: ca.SX
    lower: Lowering

    @classmethod
    def for_model(cls, model) -> Arguments:
        theta = ca.SX.sym("theta")
        x = ca.SX.sym("x", len(sym.STATE_NAMES))
        a = ca.SX.sym("a", len(model.activations))
        names = parameter_names_of(model)
        p = ca.SX.sym("p", len(names))
        u = ca.SX.sym("u", len(sym.INPUT_NAMES))
        values = {sym.theta: theta, sym.Pa: u[0], sym.Pb: u[1]}
        values.update({s: x[i] for i, s in enumerate(sym.qs + sym.us)})
        values.update({sym.P[n]: p[i] for i, n in enumerate(names)})
        values.update({s: a[i] for i, s in enumerate(model.activations.values())})
        return cls(theta, x, a, p, u, Lowering(values))

    def vector(self, exprs) -> ca.SX:
        exprs = list(exprs)
        return ca.vertcat(*[self.lower(e) for e in exprs]) if exprs else ca.SX(0, 1)


@dataclass
class ModelFunctions:
    """The CasADi Functions of one model and the names of their inputs' and outputs' entries.

    The same class holds the SX Functions (``load_functions(...).sx``) and their
    compiled counterparts (``.c``, see :meth:`with_functions`).
    """

    rhs: ca.Function
    rhs_jac: ca.Function
    rhs_switched: ca.Function
    rhs_switched_jac: ca.Function
    guards: ca.Function
    velocity_guards: ca.Function
    outputs: ca.Function
    #: mode label -> Function ``mode_<label>(theta, x, p, u) -> xdot``, in the order of ``mode_list``
    modes: dict[str, ca.Function]
    #: mode label -> its Jacobian ``jac_mode_<label>``
    mode_jacs: dict[str, ca.Function]
    mode_list: tuple[Mode, ...]
    state_names: tuple[str, ...] = sym.STATE_NAMES
    parameter_names: tuple[str, ...] = sym.PARAMETER_NAMES
    input_names: tuple[str, ...] = sym.INPUT_NAMES
    guard_names: tuple[str, ...] = ()
    activation_names: tuple[str, ...] = ()
    velocity_guard_names: tuple[str, ...] = ()
    output_names: tuple[str, ...] = ()
    #: Function name -> number of SX instructions (of the SX Function, also for compiled sets)
    n_instructions: dict[str, int] = field(default_factory=dict)

    @property
    def mode_labels(self) -> tuple[str, ...]:
        return tuple(m.label for m in self.mode_list)

    def functions(self) -> dict[str, ca.Function]:
        """Every Function by its CasADi name, in a fixed order (the order of the generated C)."""
        out = {f.name(): f for f in (self.rhs, self.rhs_jac, self.rhs_switched, self.rhs_switched_jac,
                                      self.guards, self.velocity_guards, self.outputs)}
        for label in self.mode_labels:
            out[self.modes[label].name()] = self.modes[label]
            out[self.mode_jacs[label].name()] = self.mode_jacs[label]
        return out

    def mode_of(self, closed) -> str:
        """The label of the mode with these contacts closed (in ``guard_names`` order)."""
        return Mode(tuple(bool(c) for c in closed), self.guard_names).label

    def with_functions(self, replacement: Mapping[str, ca.Function]) -> ModelFunctions:
        """A copy whose Functions are replaced by name (e.g. by compiled externals)."""

        def pick(f: ca.Function) -> ca.Function:
            return replacement.get(f.name(), f)

        return replace(
            self, rhs=pick(self.rhs), rhs_jac=pick(self.rhs_jac), rhs_switched=pick(self.rhs_switched),
            rhs_switched_jac=pick(self.rhs_switched_jac), guards=pick(self.guards),
            velocity_guards=pick(self.velocity_guards), outputs=pick(self.outputs),
            modes={k: pick(f) for k, f in self.modes.items()}, mode_jacs={k: pick(f) for k, f in self.mode_jacs.items()},
        )


def _accelerations(args: Arguments, mass_matrix: sp.Matrix, forcing: sp.Matrix) -> ca.SX:
    """solve(M, f): elementwise division when M is diagonal (the seal's case), a symbolic solve otherwise."""
    f = args.vector(forcing)
    if mass_matrix.is_diagonal():
        return ca.vertcat(*[f[i] / args.lower(mass_matrix[i, i]) for i in range(mass_matrix.rows)])
    M = ca.vertcat(*[ca.horzcat(*[args.lower(mass_matrix[i, j]) for j in range(mass_matrix.cols)])
                     for i in range(mass_matrix.rows)])
    return ca.solve(M, f)


def parameter_names_of(model) -> tuple[str, ...]:
    """The parameter vector a derived model was derived with (the registry's order at the time)."""
    return tuple(model.parameter_names) or sym.PARAMETER_NAMES


#: CasADi's operations for Algorithm 4 (:func:`~apexseal.derive.modes.gap_width`)
CASADI_OPS = Ops(ca.logic_and, ca.fmin, ca.if_else)


def with_sympy_cse(model, args: Arguments):
    """The model with every expression reduced by one ``sympy.cse`` over all of them (mass matrix, forcing, guards,
    velocity guards, outputs); each temporary is lowered once, in dependency order, into ``args``.

    sympy's cse finds sums and products shared across the expressions that the memoised tree walk of
    generated/lower.py and ``casadi.cse`` do not (the same kinematics reached through differently grouped sums):
    the default model's ``rhs`` has 481 SX instructions instead of 528. Off by default (docs/bench/levers.md): it
    gains 0-10 % per evaluation inside erk, and its different round-off turns the IPOPT preload study of the
    default scene infeasible (tests/runtime/test_preload.py)."""
    M = model.mass_matrix
    parts = {"mass": [M[i, j] for i in range(M.rows) for j in range(M.cols)], "forcing": list(model.forcing),
             "guards": list(model.guards.values()), "vguards": list(model.velocity_guards.values()),
             "outputs": list(model.outputs.values())}
    replacements, reduced = sp.cse([e for v in parts.values() for e in v], symbols=sp.numbered_symbols("_cse"),
                                   optimizations=None)
    for s, e in replacements:
        args.lower.values[s] = args.lower(e)
    it = iter(reduced)
    new = {k: [next(it) for _ in v] for k, v in parts.items()}
    return replace(model, mass_matrix=sp.Matrix(M.rows, M.cols, new["mass"]), forcing=sp.Matrix(new["forcing"]),
                   guards=dict(zip(model.guards, new["guards"], strict=True)),
                   velocity_guards=dict(zip(model.velocity_guards, new["vguards"], strict=True)),
                   outputs=dict(zip(model.outputs, new["outputs"], strict=True)))


def build_functions(model, *, sympy_cse: bool = False) -> ModelFunctions:
    """Lower a derived model to SX Functions (named inputs and outputs, common subexpressions merged by the memoised
    tree walk and ``casadi.cse``; with ``sympy_cse``, by one ``sympy.cse`` over every expression first)."""
    args = Arguments.for_model(model)
    if sympy_cse:
        model = with_sympy_cse(model, args)
    th, x, a, p, u = args.theta, args.x, args.a, args.p, args.u
    n_q = len(sym.qs)
    xdot = ca.cse(ca.vertcat(x[n_q:], _accelerations(args, model.mass_matrix, model.forcing)))
    g = ca.cse(args.vector(model.guards.values()))
    vg = ca.cse(args.vector(model.velocity_guards.values()))

    output_names = list(model.outputs)
    y = [args.lower(e) for e in model.outputs.values()]
    if all(n in model.guards for n in GAP_GUARDS):
        y.append(gap_width([g[list(model.guards).index(n)] for n in GAP_GUARDS], CASADI_OPS))
        output_names.append("b_gap")
    y = ca.cse(ca.vertcat(*y)) if y else ca.SX(0, 1)

    in4, names4 = [th, x, p, u], ["theta", "x", "p", "u"]
    in5, names5 = [th, x, a, p, u], ["theta", "x", "a", "p", "u"]
    rhs = ca.Function("rhs", in5, [xdot], names5, ["xdot"])
    act = ca.vertcat(*[ca.if_else(g[i] < 0, 1, 0) for i in range(g.numel())]) if g.numel() else ca.SX(0, 1)
    switched = ca.cse(ca.substitute(xdot, a, act))
    rhs_switched = ca.Function("rhs_switched", in4, [switched], names4, ["xdot"])
    guards = ca.Function("guards", in4, [g], names4, ["g"])
    velocity_guards = ca.Function("velocity_guards", in4, [vg], names4, ["vg"])
    outputs = ca.Function("outputs", in5, [y], names5, ["y"])

    mode_list = tuple(modes(model.guard_names))
    mode_fns, mode_jacs = {}, {}
    for mode in mode_list:
        closed = ca.DM([1.0 if c else 0.0 for c in mode.closed]) if mode.closed else ca.DM(0, 1)
        f = ca.Function(f"mode_{mode.label}", in4, [ca.cse(ca.substitute(xdot, a, closed))], names4, ["xdot"])
        mode_fns[mode.label], mode_jacs[mode.label] = f, f.jacobian()

    out = ModelFunctions(
        parameter_names=parameter_names_of(model),
        rhs=rhs, rhs_jac=rhs.jacobian(), rhs_switched=rhs_switched, rhs_switched_jac=rhs_switched.jacobian(),
        guards=guards, velocity_guards=velocity_guards, outputs=outputs, modes=mode_fns, mode_jacs=mode_jacs,
        mode_list=mode_list, guard_names=tuple(model.guards),
        activation_names=tuple(str(s) for s in model.activations.values()),
        velocity_guard_names=tuple(model.velocity_guards), output_names=tuple(output_names),
    )
    out.n_instructions = {name: f.n_instructions() for name, f in out.functions().items()}
    return out
