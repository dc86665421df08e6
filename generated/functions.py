"""The model's CasADi Functions, built from a :class:`~apexseal.derive.model.DerivedModel`.

``build_functions(model)`` lowers the sympy expressions to SX once and returns a
:class:`ModelFunctions`: the right-hand side with the contact activations as an
input (``rhs``) and its Jacobian (``rhs_jac``, named ``jac_rhs`` so that
``casadi.external("rhs", so)`` finds it), the contact and velocity guards, the
named outputs, and ``rhs_switched``, which computes the activations from the
guards (for fixed-step methods). These are the Functions a run executes; a
mode of the hybrid model (Algorithm 3) is ``rhs`` with its activations fixed
(:meth:`ModelFunctions.mode_rhs`), so no per-mode Function is generated
(docs/codegen.md: per-case dispatch measured no faster, and no run used it).
Argument order everywhere: crank angle ``theta``, state ``x`` (the seal body's six, then the
active submodels' own states, ``state_names``), [activations ``a``], parameters ``p`` (named:
``parameter_names``, the submodels' declarations), chamber pressures ``u = [Pa, Pb]`` (unused when a
submodel computes Pa, Pb from its states: the chamber gas model).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

import casadi as ca

from ..derive.modes import GROOVE_GUARDS, Mode, Ops, gap_width, modes
from ..derive.names import INPUT_NAMES, STATE_NAMES


@dataclass
class Arguments:
    """The SX symbols of the Functions' inputs and the sympy -> SX lowering that uses them."""

    theta: ca.SX
    x: ca.SX
    a: ca.SX
    p: ca.SX
    u: ca.SX
    lower: object  # a .lower.Lowering

    @classmethod
    def for_model(cls, model) -> Arguments:
        from ..derive import symbols as sym  # the derivation's symbols (sympy): only when lowering
        from .lower import Lowering

        theta = ca.SX.sym("theta")
        states = state_names_of(model)
        x = ca.SX.sym("x", len(states))
        a = ca.SX.sym("a", len(model.activations))
        names = parameter_names_of(model)
        p = ca.SX.sym("p", len(names))
        u = ca.SX.sym("u", len(sym.INPUT_NAMES))
        values = {sym.theta: theta, sym.Pa: u[0], sym.Pb: u[1]}
        values.update({sym.state_symbol(n): x[i] for i, n in enumerate(states)})
        values.update({sym.P[n]: p[i] for i, n in enumerate(names)})
        values.update({s: a[i] for i, s in enumerate(model.activations.values())})
        lower = Lowering(values)
        pressures = getattr(model, "pressures", None) or {}
        if pressures:  # the chamber gas model: Pa, Pb from its states, not from u
            pa, pb = lower(pressures["Pa"]), lower(pressures["Pb"])
            lower = Lowering({**values, sym.Pa: pa, sym.Pb: pb})
        return cls(theta, x, a, p, u, lower)

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
    guards: ca.Function
    outputs: ca.Function
    mode_list: tuple[Mode, ...]
    state_names: tuple[str, ...] = STATE_NAMES
    parameter_names: tuple[str, ...] = ()
    input_names: tuple[str, ...] = INPUT_NAMES
    guard_names: tuple[str, ...] = ()
    activation_names: tuple[str, ...] = ()
    output_names: tuple[str, ...] = ()
    #: Function name -> number of SX instructions (of the SX Function, also for compiled sets)
    n_instructions: dict[str, int] = field(default_factory=dict)
    #: the SX Functions these were generated from (for compiled sets; None for an SX set, which is its own)
    symbolic: ModelFunctions | None = None
    #: the compiled model library the Functions come from (None: SX Functions)
    library: Path | None = None
    #: the input hash of the manifest of the generated model (None: built directly from a derivation)
    model_hash: str | None = None
    #: the hybrid DAE of the event integrators, ``(t, z, p, u) -> ode`` and ``-> zero``
    #: (generated/hybrid.py); in the model library with the derivatives the integrators call
    hybrid_ode: ca.Function | None = None
    hybrid_zero: ca.Function | None = None

    @property
    def mode_labels(self) -> tuple[str, ...]:
        return tuple(m.label for m in self.mode_list)

    def functions(self) -> dict[str, ca.Function]:
        """Every Function by its CasADi name, in a fixed order (the order of the generated C)."""
        fns = (self.rhs, self.rhs_jac, self.rhs_switched, self.guards, self.outputs, self.hybrid_ode, self.hybrid_zero)
        return {f.name(): f for f in fns if f is not None}

    def event_derivatives(self) -> list[ca.Function]:
        """The derivatives of the hybrid Functions that a compiled erk integrator calls, at events only (SX sets
        only; a compiled set finds them in the library by name): ``fwd1_*`` of both (the transition's look-ahead,
        the event's location) and ``fwd1_fwd1_hybrid_zero``.

        CasADi's erk asks for the second derivatives of its whole DAE to be built with one that calls a library.
        That of ``hybrid_ode`` (5 131 instructions, 40 % of the library) does not reach any result (a NaN in its
        place leaves the trajectory bit for bit the same; tests/generated/test_linked_integrator.py checks that
        CasADi still ignores it), so it is not generated: :data:`EXTERNAL_OPTIONS` lets CasADi build it by finite
        differences instead.
        """
        hybrid = [f for f in (self.hybrid_ode, self.hybrid_zero) if f is not None]
        return [f.forward(1) for f in hybrid] + [f.forward(1).forward(1) for f in hybrid[1:]]

    def sx(self) -> ModelFunctions:
        """The SX Functions (to embed in an integrator): this set, or the one it was compiled from."""
        return self if self.symbolic is None else self.symbolic

    def parameters_read(self) -> frozenset[str]:
        """The parameters some expression of the model reads (its right-hand side, guards or outputs). An effect
        that is off has no slot in the vector; a slot read by none is a parameter whose laws read it only in some
        settings (a modelling choice of [assumptions] that drops the term it is in)."""
        sx = self.sx()
        read = [any(flags) for flags in zip(*(f.which_depends("p", [f.name_out(0)], 1, False)
                                              for f in (sx.rhs, sx.guards, sx.outputs)), strict=True)]
        return frozenset(n for n, r in zip(self.parameter_names, read, strict=True) if r)

    def omega(self, params) -> float:
        """The rotor speed (rad/s) in a parameter vector of this model (its "omega" entry)."""
        return float(params[list(self.parameter_names).index("omega")])

    def mode_rhs(self, label: str):
        """``f(theta, x, p, u) -> xdot`` of one mode (Algorithm 3 label): ``rhs`` with that mode's activations."""
        mode = next(m for m in self.mode_list if m.label == label)
        closed = [1.0 if c else 0.0 for c in mode.closed]
        return lambda theta, x, p, u: self.rhs(theta, x, closed, p, u)

    def with_functions(self, replacement: Mapping[str, ca.Function]) -> ModelFunctions:
        """A copy whose Functions are replaced by name (e.g. by compiled externals)."""

        def pick(f: ca.Function | None) -> ca.Function | None:
            return None if f is None else replacement.get(f.name(), f)

        return replace(
            self, rhs=pick(self.rhs), rhs_jac=pick(self.rhs_jac), rhs_switched=pick(self.rhs_switched),
            guards=pick(self.guards), outputs=pick(self.outputs),
            hybrid_ode=pick(self.hybrid_ode), hybrid_zero=pick(self.hybrid_zero),
        )


def _accelerations(args: Arguments, mass_matrix, forcing) -> ca.SX:
    """solve(M, f): elementwise division when M is diagonal (the seal's case), a symbolic solve otherwise."""
    f = args.vector(forcing)
    if mass_matrix.is_diagonal():
        return ca.vertcat(*[f[i] / args.lower(mass_matrix[i, i]) for i in range(mass_matrix.rows)])
    M = ca.vertcat(*[ca.horzcat(*[args.lower(mass_matrix[i, j]) for j in range(mass_matrix.cols)])
                     for i in range(mass_matrix.rows)])
    return ca.solve(M, f)


def state_names_of(model) -> tuple[str, ...]:
    """The state vector a derived model was derived with (the seal body's six, then the submodels' own)."""
    return tuple(getattr(model, "state_names", ()) or STATE_NAMES)


def parameter_names_of(model) -> tuple[str, ...]:
    """The parameter vector a derived model was derived with (the registry's order at the time)."""
    from ..derive import symbols as sym

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
    import sympy as sp

    M = model.mass_matrix
    parts = {"mass": [M[i, j] for i in range(M.rows) for j in range(M.cols)], "forcing": list(model.forcing),
             "guards": list(model.guards.values()), "outputs": list(model.outputs.values())}
    replacements, reduced = sp.cse([e for v in parts.values() for e in v], symbols=sp.numbered_symbols("_cse"),
                                   optimizations=None)
    for s, e in replacements:
        args.lower.values[s] = args.lower(e)
    it = iter(reduced)
    new = {k: [next(it) for _ in v] for k, v in parts.items()}
    return replace(model, mass_matrix=sp.Matrix(M.rows, M.cols, new["mass"]), forcing=sp.Matrix(new["forcing"]),
                   guards=dict(zip(model.guards, new["guards"], strict=True)),
                   outputs=dict(zip(model.outputs, new["outputs"], strict=True)))


def build_functions(model, *, sympy_cse: bool = False) -> ModelFunctions:
    """Lower a derived model to SX Functions (named inputs and outputs, common subexpressions merged by the memoised
    tree walk and ``casadi.cse``; with ``sympy_cse``, by one ``sympy.cse`` over every expression first)."""
    from ..derive import symbols as sym  # the derivation (sympy): only when lowering

    args = Arguments.for_model(model)
    if sympy_cse:
        model = with_sympy_cse(model, args)
    th, x, a, p, u = args.theta, args.x, args.a, args.p, args.u
    n_q, n_u = len(sym.qs), len(sym.us)
    rates = getattr(model, "rates", None) or {}
    xdot = ca.cse(ca.vertcat(x[n_q:n_q + n_u], _accelerations(args, model.mass_matrix, model.forcing),
                             args.vector(rates[n] for n in state_names_of(model)[n_q + n_u:])))
    g = ca.cse(args.vector(model.guards.values()))

    output_names = list(model.outputs)
    y = [args.lower(e) for e in model.outputs.values()]
    if all(n in model.guards for n in GROOVE_GUARDS):
        y.append(gap_width([g[list(model.guards).index(n)] for n in GROOVE_GUARDS], CASADI_OPS))
        output_names.append("b_gap")
    y = ca.cse(ca.vertcat(*y)) if y else ca.SX(0, 1)

    in4, names4 = [th, x, p, u], ["theta", "x", "p", "u"]
    in5, names5 = [th, x, a, p, u], ["theta", "x", "a", "p", "u"]
    rhs = ca.Function("rhs", in5, [xdot], names5, ["xdot"])
    act = ca.vertcat(*[ca.if_else(g[i] < 0, 1, 0) for i in range(g.numel())]) if g.numel() else ca.SX(0, 1)
    switched = ca.cse(ca.substitute(xdot, a, act))
    rhs_switched = ca.Function("rhs_switched", in4, [switched], names4, ["xdot"])
    guards = ca.Function("guards", in4, [g], names4, ["g"])
    outputs = ca.Function("outputs", in5, [y], names5, ["y"])

    out = ModelFunctions(
        rhs=rhs, rhs_jac=rhs.jacobian(), rhs_switched=rhs_switched, guards=guards, outputs=outputs,
        mode_list=tuple(modes(model.guard_names)), guard_names=tuple(model.guards),
        parameter_names=parameter_names_of(model), state_names=state_names_of(model),
        activation_names=tuple(str(s) for s in model.activations.values()),
        output_names=tuple(output_names),
    )
    with_hybrid(out)
    out.n_instructions = {f.name(): f.n_instructions() for fs in library_groups(out).values() for f in fs}
    return out


def with_hybrid(fns: ModelFunctions) -> ModelFunctions:
    """Set ``fns.hybrid_ode`` and ``fns.hybrid_zero`` from its rhs and guards (SX; a few ms, no sympy), with the
    controls of either pressure profile (``LIBRARY_PROFILE``, generated/hybrid.py)."""
    from .hybrid import LIBRARY_PROFILE, hybrid_functions

    names = list(fns.parameter_names)
    fns.hybrid_ode, fns.hybrid_zero = hybrid_functions(fns.rhs, fns.guards, len(names), names.index("omega"),
                                                       state_names=fns.state_names, pressure=LIBRARY_PROFILE)
    return fns


def library_groups(fns: ModelFunctions) -> dict[str, list[ca.Function]]:
    """C file stem -> the Functions it holds: the model library, in two files that compile in parallel.

    ``casadi_model``: every Function a run or a Python-side evaluation calls; ``casadi_model_events``: the
    derivatives an erk integrator calls at events (:meth:`ModelFunctions.event_derivatives`).
    """
    return {"casadi_model": list(fns.functions().values()), "casadi_model_events": fns.event_derivatives()}


#: ``casadi.external`` options per Function of the model library (see :meth:`ModelFunctions.event_derivatives`)
EXTERNAL_OPTIONS = {"hybrid_ode": {"der_options": {"enable_fd": True}}}
