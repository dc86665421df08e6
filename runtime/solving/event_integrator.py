"""One revolution at a time with CasADi's event-locating integrators (erk, rosenbrock).

The hybrid DAE (generated/hybrid.py) is integrated over one revolution in a single
call, with the output grid of the scene; events (contact switches) are located on
the integrator's dense output inside CasADi, so no Python runs between steps. The
integrator itself is generated to C at the generation station and compiled (with its
event logic). For erk with a compiled model library (a run's usual case) its DAE calls
the library's ``hybrid_ode`` and ``hybrid_zero``: the integrator's C declares them
extern and is linked against the library, so it holds the integrator and nothing of
the model. Otherwise (rosenbrock, interpreted model, no compiler, or Functions built
directly from a derivation) it embeds the SX Functions. Its record names the model manifest
and the library it was built from (generated/compile.py).
"""

from __future__ import annotations

import contextlib
import io
import sys
import warnings

import casadi as ca
import numpy as np

from ...generated.hybrid import build_hybrid_dae, controls, parameter_controls
from .methods import METHODS, Engine, RevolutionResult, run_params

#: what CasADi 3.8 prints whenever an integrator with events is built; apexseal's tests cover crossings in
#: both directions for every event method (tests/runtime/test_simulate.py), so the run does not repeat it
EXPERIMENTAL_EVENTS = 'WARNING("Event support is experimental")'


@contextlib.contextmanager
def events_tested():
    """Build an event integrator without CasADi's experimental-events warning; anything else it prints passes."""
    buf = io.StringIO()
    try:
        with contextlib.redirect_stderr(buf), contextlib.redirect_stdout(buf):
            yield
    finally:
        rest = "".join(line for line in buf.getvalue().splitlines(keepends=True) if EXPERIMENTAL_EVENTS not in line)
        if rest:
            sys.stderr.write(rest)


class EventIntegrator(Engine):
    """Integrates the hybrid model over `span` of crank angle with `n_samples` outputs."""

    pressure_profiles = ("steps", "linear")
    parameter_profiles = ("constant", "linear")

    @classmethod
    def build(cls, functions, settings, *, method, n_samples, span, compile_c):
        names = tuple(functions.parameter_names)
        # for the fixed-step variant the rtol slot carries the step in crank angle
        rtol = settings.rtol if method != "erk-rk4" else 2 * np.pi / settings.steps_per_revolution
        sx = functions.sx()
        return cls(sx.rhs, sx.guards, len(names), names.index("omega"), method=method, rtol=rtol,
                   atol=settings.atol, n_samples=n_samples, span=span, max_events=settings.max_events_per_revolution,
                   max_steps=settings.max_steps_per_interval, event_tol=settings.event_tol, compile_c=compile_c,
                   flags=settings.flags, model_hash=sx.model_hash, state_names=functions.state_names,
                   pressure=settings.pressure, library=functions if compile_c else None,
                   parameters=settings.parameters)

    def __init__(self, rhs: ca.Function, guards: ca.Function, n_par: int, omega_index: int, *, method: str,
                 rtol: float, atol: float | None, n_samples: int, span: float = 2 * np.pi,
                 max_events: int = 10000, max_steps: int = 200000, event_tol: float = 1e-10, compile_c: bool = True,
                 flags: str = "optimised", model_hash: str | None = None, state_names=None, pressure: str = "steps",
                 library=None, parameters: str = "constant"):
        """``library``: model Functions (:class:`~apexseal.generated.functions.ModelFunctions`); when they are the
        compiled model library's, the DAE calls its hybrid Functions and the compiled integrator links against it
        (``self.link``; either pressure profile: the library takes the controls of both, :func:`.hybrid.controls`);
        otherwise (or None) the DAE embeds the SX Functions built from ``rhs`` and ``guards``. ``parameters``:
        "linear" to take the parameters' values at the interval edges (a scene's schedule; generated/hybrid.py)."""
        plugin = METHODS[method].plugin
        # rosenbrock would need the hybrid Functions' Jacobians in the library too (without them it built its
        # Jacobian column by column: 3.2x slower), which would add 40 % to the library's instructions; it embeds
        linked = (plugin == "erk" and library is not None and library.hybrid_ode is not None
                  and library.hybrid_ode.is_a("External"))
        #: the compiled model library the integrator's DAE calls (None: the DAE embeds the model's SX)
        self.link = library.library if linked else None
        #: the model whose Functions the integrator embeds or calls, as its compiled C's record names it
        self.model_hash = model_hash
        externals = (library.hybrid_ode, library.hybrid_zero) if self.link is not None else None
        self.hybrid = build_hybrid_dae(rhs, guards, n_par, omega_index, event_tol=event_tol, state_names=state_names,
                                       pressure=pressure, library=externals, parameters=parameters)
        self.pressure, self.parameters = pressure, parameters
        self.n_samples = n_samples
        self.grid = np.linspace(0.0, span, n_samples + 1)[1:]
        opts = {"transition": self.hybrid.transition, "reltol": rtol, "abstol": atol if atol is not None else rtol,
                "max_events": int(max_events), "max_num_steps": int(max_steps), "event_tol": float(event_tol),
                "show_eval_warnings": False}  # a NaN tried inside a failing step is reported once, by the run
        if method == "erk-rk4":
            opts["method"] = "rk4"
            opts["step_size"] = float(rtol)  # for the fixed-step variant rtol is read as the step in crank angle
            opts.pop("reltol")
            opts.pop("abstol")
        with warnings.catch_warnings(), events_tested():
            warnings.simplefilter("ignore")
            self.vm = ca.integrator("apexseal_" + method.replace("-", "_"), plugin, self.hybrid.dae, 0.0,
                                    self.grid, opts)
        self.function = self.vm
        self.compiled = False
        if compile_c:
            from ...generated.compile import compile_function

            self.function = compile_function(self.vm, flags=flags, model_hash=model_hash, link=self.link)
            self.compiled = self.function is not self.vm

    def run(self, z0: np.ndarray, params: np.ndarray, theta0: float, pressures: np.ndarray) -> RevolutionResult:
        """Integrate from z0 at crank angle theta0; pressures is (2, n_samples), one column per output interval
        (``pressure = "steps"``), or (2, n_samples + 1), the values at the intervals' ends ("linear"); params is
        the parameter vector, or, built with ``parameters = "linear"``, its values at the intervals' ends too."""
        rows = self.hybrid.dae["u"].size1()
        params = run_params(params, self.parameters)
        if self.parameters == "linear":
            params, u_par = parameter_controls(params, self.grid)
            u = np.vstack([controls(pressures, self.grid, self.pressure, rows - u_par.shape[0]), u_par])
        else:
            u = controls(pressures, self.grid, self.pressure, rows)
        out = self.function(x0=z0, p=np.r_[params, theta0], u=u)
        stats = {}
        try:
            stats = dict(self.function.stats())
        except Exception:  # noqa: BLE001 - externals may not report stats
            pass
        return RevolutionResult(np.array(out["xf"]), stats)
