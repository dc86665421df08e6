"""The preload study's compiled CasADi Functions as a public entry point, with every input and output slot named.

``preload_functions(scene)`` builds what :func:`.study.optimise_preload` builds (a :class:`.problem.PreloadSetup` and
the interval integrator of :func:`.shooting.study_functions`) and returns them with the names of the entries of
CasADi's generic slots ``x0``, ``p``, ``u`` and ``qf`` (docs/preload.md, "The study's Functions from Python"):

* ``x0`` (and each column of ``xf``): the hybrid state ``z`` (generated/layout.py): the scaled continuous states
  (physical = :func:`~apexseal.generated.scaling.to_physical`; :meth:`PreloadFunctions.hybrid_state` and
  :meth:`PreloadFunctions.physical` convert), then ``closed_<guard>`` (1 while that contact is closed), then
  ``events_<guard>`` (switches of that contact counted from the call's start);
* ``p``: the physical parameter vector at the call's start (the scene's model's names), ``theta0`` (the call's
  absolute crank angle, rad), ``slope`` (d delta_s / d theta along the call, m/rad), ``f_min`` (N), ``f_max`` (N, read
  only with the groove-force quadrature), then the excluded windows' ``window<i>_start`` / ``window<i>_end`` (rad);
* ``u`` (4 x m, a column per output interval): ``Pa0``, ``Pb0``, the chamber pressures (Pa) at the call's start along
  the interval's line, and ``Pa_slope``, ``Pb_slope`` (Pa/rad; zero for ``solver.pressure = "steps"``);
* ``qf`` (n_quad x m): each quadrature integrated from the call's start to each output sample over crank angle:
  ``friction_energy`` (the integral of ``Pf_total`` over crank angle, W rad: divided by the call's span it is the
  mean friction power between samples too), ``force_deficit`` (N^2 rad) and, with a groove-force bound,
  ``groove_excess`` (N^2 rad) (runtime/studies/preload/shooting.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ....generated.scaling import to_physical, to_scaled
from .problem import MAX_WINDOWS, PreloadSetup
from .shooting import StudyFunctions, q_layout, study_functions, window_vector

#: the rows of ``u``: the chamber pressures at the call's start along the interval's line, then their slopes
CONTROL_NAMES = ("Pa0", "Pb0", "Pa_slope", "Pb_slope")
#: the rows of ``qf`` (the third only with a groove-force bound)
QUADRATURE_NAMES = ("friction_energy", "force_deficit", "groove_excess")


@dataclass(eq=False, repr=False)
class PreloadFunctions:
    """The setup and the compiled Functions of the preload study, with the names of their slots (module docstring).

    ``interval(x0=..., p=..., u=...)`` integrates ``m`` output samples (``m * setup.dth`` rad of crank angle) and
    returns ``xf`` (the hybrid state at each sample) and ``qf`` (the quadratures from the call's start to each
    sample); ``forward`` is its forward derivative in ``CHUNK`` directions (first derivatives only, as the study
    uses them). :meth:`p` and :meth:`u` build the inputs as the study does.
    """

    setup: PreloadSetup
    study: StudyFunctions
    x0_names: tuple[str, ...]  # the entries of x0 and of each column of xf
    p_names: tuple[str, ...]  # the entries of p
    u_names: tuple[str, ...]  # the rows of u
    qf_names: tuple[str, ...]  # the rows of qf

    @property
    def interval(self):
        return self.study.interval

    @property
    def forward(self):
        return self.study.forward

    @property
    def m(self) -> int:
        """Output samples per call of :attr:`interval`."""
        return self.study.m

    def p(self, delta_s: float, theta0: float, *, slope: float = 0.0) -> np.ndarray:
        """``p`` for a call from absolute crank angle ``theta0`` (rad) at preload ``delta_s`` (m) there, the preload
        growing by ``slope`` m/rad along the call; the setup's min_force, groove-force bound and windows."""
        s = self.setup
        f_max = s.max_groove_force if s.max_groove_force is not None else 0.0
        return np.r_[s.pmap(delta_s), theta0, slope, s.min_force, f_max, window_vector(s.exclude)]

    def u(self, theta0: float) -> np.ndarray:
        """``u`` (4 x m) for a call from absolute crank angle ``theta0`` (rad): the scene's chamber pressures."""
        s = self.setup
        return s.controls(theta0 + s.dth * np.arange(self.m + 1), self.m)

    def hybrid_state(self, state, closed, events=None) -> np.ndarray:
        """``x0`` from a physical state (the model's state order, e.g. a :class:`SimulationResult`'s
        ``state[:, i]``), the contacts closed (``closed[:, i]``) and the event counts (default 0)."""
        s = self.setup
        return s.layout.pack(to_scaled(np.asarray(state, float), s.pmap.at("omega"), s.layout.state_names),
                             np.asarray(closed, float), events)

    def physical(self, xf) -> np.ndarray:
        """The physical continuous states (the model's state order, SI) of hybrid states ``xf`` (a column each)."""
        s = self.setup
        return to_physical(np.asarray(xf, float)[s.layout.x], s.pmap.at("omega"), s.layout.state_names)

    def describe(self) -> str:
        """Each slot of :attr:`interval` with its size and the names of its entries (rows), a line each."""
        f = self.interval

        def size(slot):
            rows, cols = f.size_in(slot) if slot in ("x0", "p", "u") else f.size_out(slot)
            return f"{rows}" if cols == 1 else f"{rows}x{cols}"

        return "\n".join(f"{slot} {size(slot)}: {', '.join(names)}"
                         for slot, names in (("x0", self.x0_names), ("p", self.p_names), ("u", self.u_names),
                                             ("xf", self.x0_names), ("qf", self.qf_names)))

    def __repr__(self) -> str:
        return (f"PreloadFunctions({self.setup.scene.name}, {self.setup.samples} samples per revolution, {self.m} "
                f"per call, quadratures {', '.join(self.qf_names)}{'' if self.study.compiled else ', not compiled'})")


def preload_functions(scene, *, min_force: float = 5.0, exclude=(), samples: int | None = None,
                      per_interval: int | None = None, rtol: float | None = None,
                      max_groove_force: float | None = None, compile_c: bool = True, functions=None,
                      flags: str = "quick") -> PreloadFunctions:
    """The preload study's setup and Functions for ``scene`` (a Scene or a scene file), with their slots named.

    ``per_interval``: output samples per call of the interval integrator (default: ``samples``, one revolution per
    call); it must divide ``samples`` (default the scene's ``solver.samples_per_revolution``). ``compile_c``: the
    study's two C units, compiled and cached as :func:`apexseal.optimise_preload` builds them (tens of seconds
    cold), or False for CasADi's own evaluation. The other options are :func:`apexseal.optimise_preload`'s, with its
    ranges (a :class:`PreloadStudyError` names a bad one).
    """
    from ...api import model_functions, scene_of
    from .problem import PreloadStudyError, is_integer, study_quantities, windows

    scene = scene_of(scene)
    min_force, max_groove_force, _ = study_quantities(min_force, max_groove_force)
    setup = PreloadSetup(scene, functions or model_functions(scene), min_force, windows(exclude), samples, rtol,
                         flags=flags, max_groove_force=max_groove_force)
    m = setup.samples if per_interval is None else per_interval
    if not (is_integer(m) and 1 <= m <= setup.samples and setup.samples % m == 0):
        raise PreloadStudyError(f"per_interval = {m!r}: must be an integer in 1..{setup.samples} dividing the "
                                f"{setup.samples} samples per revolution")
    study = study_functions(setup, int(m), compile_c=compile_c)
    lay, names = setup.layout, setup.pmap.names
    L = q_layout(len(names))
    p_names = [""] * L["size"]
    p_names[L["p"]] = names
    for key in ("theta0", "slope", "f_min", "f_max"):
        p_names[L[key]] = key
    p_names[L["windows"]] = [f"window{i}_{end}" for i in range(1, MAX_WINDOWS + 1) for end in ("start", "end")]
    return PreloadFunctions(setup, study,
                            (*lay.state_names, *(f"closed_{g}" for g in lay.guard_names),
                             *(f"events_{g}" for g in lay.guard_names)),
                            tuple(p_names), CONTROL_NAMES, QUADRATURE_NAMES[:study.n_quad])


__all__ = ["CONTROL_NAMES", "QUADRATURE_NAMES", "PreloadFunctions", "preload_functions"]
