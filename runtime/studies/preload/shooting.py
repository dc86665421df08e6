"""The preload study's compiled pieces: the hybrid DAE with a scheduled preload and two quadratures.

The DAE is the simulator's (generated/hybrid.py: contact switches as events, the same model
Functions), with three additions, all inside the DAE so the adaptive steps and the located events
resolve them (nothing depends on the output grid but the pressure means, which the simulator shares):

* **Scheduled preload.** The integrator's parameters are ``q = [p, theta0, slope, f_min, windows]``:
  the physical parameter vector p at the interval's start, and along the interval delta_s grows
  by ``slope`` (m per rad of crank angle), so the model sees ``p + dp slope tau`` where ``dp`` is
  d p / d delta_s of the scene (delta_s, delta_w of Eq. 9 and Li of Eq. 12 move together,
  runtime/studies/preload/problem.py). A piecewise-linear delta_s(theta) is one interval per
  knot stretch; the constant design is slope 0.
* **Friction power** quadrature: the simulator's output ``Pf_total`` (W, the Coulomb friction of
  every contact: Algorithms 1-2, Eq. 73) integrated over crank angle; divided by 2 pi it is the cycle-mean friction
  power.
* **Force-deficit** quadrature: ``(max(0, f_min - F) / F_REF)^2`` integrated over crank angle, where F
  is the tip's contact measure (the contact force of Eq. 34 with Eq. 67's damping in contact,
  ``kw xs5 < 0`` in lift-off), outside the excluded crank-angle windows. It is zero exactly when the
  force stays >= f_min everywhere on the trajectory outside the windows, and it is smooth (C1) in
  the decision variables, so it is the study's grid-independent constraint.
* **Groove-force excess** quadrature (only when the study bounds the groove forces; otherwise it is not
  built and the compiled units are those without it): ``sum_c (max(0, |F_c| - f_max) / F_REF)^2``
  integrated over crank angle, F_c the force of each seal-groove contact (Eq. 63: normal force, damping and
  friction; the contacts the groove submodel declares), everywhere on the revolution. Zero exactly when no
  groove contact force exceeds f_max, between samples too.

Compiled at the generation station (generated/compile.py) as two small C libraries built in parallel and
cached by content: the interval integrator and its forward derivative in ``CHUNK`` directions (a Jacobian
takes ``ceil((n_x + K) / CHUNK)`` calls per segment, its directions the n_x scaled continuous states at the
shooting node and the K knot values of the schedule: runtime/studies/preload/nlp.py).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ....generated.hybrid import build_hybrid_dae
from ....generated.scaling import state_scale
from ...solving.event_integrator import events_tested
from .problem import MAX_WINDOWS, windows

#: the deficit quadrature is in units of F_REF (N)
F_REF = 1.0
#: regularises the size of a groove contact force at zero (N): |F| is overstated by at most F_EPS
F_EPS = 1e-3
#: directions per call of the compiled forward derivative. Each call integrates the nominal trajectory again, so
#: fewer calls cost less; the C grows with the directions. On the default scene's constant study (720 samples,
#: windows 0:10 and 180:190; docs/preload.md), cold build / IPOPT: 2 directions 16.3 / 13.9 s, 4: 15.8 / 10.7 s
#: (the two units build in parallel, the interval integrator sets the time), 8: 29.4 / 8.9 s
CHUNK = 4
TWO_PI = 2 * np.pi


@dataclass
class StudyFunctions:
    """The compiled interval integrator, its forward derivative and the one-revolution integrator."""

    interval: ca.Function  # (x0, p=q, u) -> xf (n_z x m), qf (n_quad x m): [friction energy, deficit(, groove)]
    forward: ca.Function  # interval.forward(CHUNK): called once per CHUNK directions for a Jacobian
    n_par: int
    m: int  # samples per shooting interval
    compile_s: float
    compiled: bool
    groove: bool = False  # the groove-force excess is the third quadrature

    @property
    def n_quad(self) -> int:
        return 3 if self.groove else 2


def q_layout(n_par: int) -> dict[str, int | slice]:
    """Where each part lives in the integrator parameter vector q."""
    return {"p": slice(0, n_par), "theta0": n_par, "slope": n_par + 1, "f_min": n_par + 2, "f_max": n_par + 3,
            "windows": slice(n_par + 4, n_par + 4 + 2 * MAX_WINDOWS), "size": n_par + 4 + 2 * MAX_WINDOWS}


def groove_forces(functions) -> tuple[tuple[int, int], ...]:
    """Indices of (F_c_X, F_c_Y) in the model's outputs for each seal-groove contact c (the contacts the groove
    submodel declares, Eq. 63); empty when the groove contacts are off."""
    from ....derive.submodels.registry import contact_names

    names = tuple(functions.output_names)
    return tuple((names.index(f"F_{c}_X"), names.index(f"F_{c}_Y")) for c in contact_names("groove")
                 if f"F_{c}_X" in names)


def window_vector(exclude) -> np.ndarray:
    """The excluded windows (deg) as the parameters of the compiled functions: [start, end] rad pairs."""
    exclude = windows(exclude)
    w = np.zeros(2 * MAX_WINDOWS)
    for i, (a, b) in enumerate(exclude):
        w[2 * i:2 * i + 2] = np.radians([a, b])
    return w


def _mod2pi(x):
    return ca.fmod(ca.fmod(x, TWO_PI) + TWO_PI, TWO_PI)


def study_dae(functions, dp: np.ndarray, measure_fn: ca.Function, settings, *, groove: bool = False):
    """The DAE dict and transition of the study (see the module docstring); ``groove``: with the groove-force
    excess quadrature."""
    names = tuple(functions.parameter_names)
    n_par, omega_i = len(names), names.index("omega")
    hy = build_hybrid_dae(functions.rhs, functions.guards, n_par, omega_i, event_tol=settings.event_tol,
                          state_names=functions.state_names, pressure="linear")  # both profiles: zero slopes for steps
    dae, lay = hy.dae, hy.layout
    z, tau, p, u = dae["x"], dae["t"], dae["p"], dae["u"]
    n_u = u.size1() // 2
    pressure = u[:n_u] + u[n_u:] * tau  # the chamber pressures along the interval's line (PreloadSetup.controls)
    L = q_layout(n_par)
    q = ca.SX.sym("q", L["size"])
    par = q[L["p"]] + ca.DM(dp) * q[L["slope"]] * tau
    p_sub = ca.vertcat(par, q[L["theta0"]])
    ode, zero = ca.substitute([dae["ode"], dae["zero"]], [p], [p_sub])
    theta = q[L["theta0"]] + tau
    X = z[lay.x] * state_scale(par[omega_i], functions.state_names)
    a = z[lay.active]
    out_names = tuple(functions.output_names)
    power = functions.outputs(theta, X, a, par, pressure)[out_names.index("Pf_total")]
    deficit = ca.fmax(0.0, q[L["f_min"]] - measure_fn(theta, X, a, par, pressure)) / F_REF
    w = q[L["windows"]]
    outside = 1
    for i in range(MAX_WINDOWS):
        start, end = w[2 * i], w[2 * i + 1]
        outside = outside * ca.if_else(_mod2pi(theta - start) <= _mod2pi(end - start), 0, 1)
    quad = [power, outside * deficit**2]
    if groove:
        Y = functions.outputs(theta, X, a, par, pressure)
        # |F| as sqrt(Fx^2 + Fy^2 + F_EPS^2): the events' forward derivatives of the DAE pass through open contacts
        # (F = 0), where hypot's derivative is NaN and CasADi's erk stops ("Evaluation failed", measured)
        size = [ca.sqrt(Y[ix] ** 2 + Y[iy] ** 2 + F_EPS**2) for ix, iy in groove_forces(functions)]
        quad.append(sum(ca.fmax(0.0, f - q[L["f_max"]]) ** 2 for f in size) / F_REF**2)
    new = {"x": z, "t": tau, "p": q, "u": u, "ode": ode, "zero": zero, "quad": ca.vertcat(*quad)}
    idx, t_ev = ca.SX.sym("index"), ca.SX.sym("t")
    par_ev = q[L["p"]] + ca.DM(dp) * q[L["slope"]] * t_ev
    post = hy.transition(index=idx, t=t_ev, x=z, p=ca.vertcat(par_ev, q[L["theta0"]]), u=u)["post_x"]
    transition = ca.Function("transition", {"index": idx, "t": t_ev, "x": z, "p": q, "u": u, "post_x": post},
                             ca.event_in(), ca.event_out())
    return new, transition


def _integrator(name, dae, transition, settings, rtol, n_out, span):
    grid = np.linspace(0.0, span, n_out + 1)[1:]
    opts = {"transition": transition, "reltol": rtol, "abstol": settings.atol if settings.atol is not None else rtol,
            "max_events": int(settings.max_events_per_revolution), "max_num_steps": int(settings.max_steps_per_interval),
            "event_tol": float(settings.event_tol), "show_eval_warnings": False}
    with warnings.catch_warnings(), events_tested():
        warnings.simplefilter("ignore")
        return ca.integrator(name, "erk", dae, 0.0, grid, opts)


def study_functions(setup, m: int, *, compile_c: bool = True) -> StudyFunctions:
    """The study's interval integrator for shooting intervals of ``m`` samples and its forward derivative,
    each compiled into its own cached library (in parallel: both cores); with the groove-force excess
    quadrature when the setup bounds the groove forces (``setup.max_groove_force``)."""
    import time

    from ....generated.compile import build_function_libraries, fallback, function_source
    from ....generated.compiler import CompilerUnavailable
    from ....progress import stage

    st = setup.settings()
    t = time.perf_counter()
    groove = setup.max_groove_force is not None
    if groove and not groove_forces(setup.functions):
        from .problem import PreloadStudyError

        raise PreloadStudyError("max_groove_force: the scene has no groove contacts (effects.groove_contact is off)")
    dae, tr = study_dae(setup.functions, setup.pmap.dp, setup.measure_fn, st, groove=groove)
    interval = _integrator("apexseal_preload_interval", dae, tr, st, setup.rtol, m, m * setup.dth)
    with warnings.catch_warnings(), events_tested():  # the derivative is an integrator with events too
        warnings.simplefilter("ignore")
        fwd = interval.forward(CHUNK)
    n_par = setup.pmap.p0.size
    if not compile_c:
        return StudyFunctions(interval, fwd, n_par, m, time.perf_counter() - t, False, groove)
    with stage(f"generating the preload study's C (interval integrator, its forward derivative in {CHUNK} directions)"):
        sources = [function_source(f, model_hash=setup.functions.model_hash) for f in (interval, fwd)]
    try:
        libs = build_function_libraries(sources, flags=setup.flags)  # both at once; a signal abandons both
    except CompilerUnavailable as exc:
        fallback(exc)
        return StudyFunctions(interval, fwd, n_par, m, time.perf_counter() - t, False, groove)
    E, Ef = (ca.external(f.name(), str(so)) for f, so in zip((interval, fwd), libs, strict=True))
    return StudyFunctions(E, Ef, n_par, m, time.perf_counter() - t, True, groove)
