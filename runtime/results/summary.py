"""The numbers a designer reads first: summary.json of a run."""

from __future__ import annotations

import math
import platform
from collections import Counter
from dataclasses import replace

import numpy as np

from ...derive.names import STATE_NAMES
from .checked import checked
from .energy import energy_balance
from .gas import last_revolution
from .result import SimulationResult, run_mean
from .spectra import housing_force, spectral_peaks, spectrum
from .wear import wear

#: the state coordinates whose extremes a summary reports, the seal's positions (x, y, phi) -> (unit shown, factor
#: from SI)
EXTREMES = dict(zip(STATE_NAMES[:3], (("um", 1e6), ("um", 1e6), ("mrad", 1e3)), strict=True))


def gap_series(result: SimulationResult) -> np.ndarray:
    """Algorithm 4 at every sample: b_gap (m), the model's output (zero without the groove's contacts)."""
    gap = result.outputs.get("b_gap")
    return np.zeros(result.n) if gap is None else np.asarray(gap, float)


def summarise(result: SimulationResult, scene_info: dict | None = None) -> dict:
    """Extremes with their crank angles, time in each mode, events, friction power, gaps, force spectrum.

    Every extreme, peak and deepest penetration here (``extremes``, ``housing_force_N.max``, ``leakage_gap.max_um``,
    ``plausibility``'s ``penetration_um`` and ``peak_force_N``) is the largest over the output samples, whose number
    per revolution is ``samples_per_revolution`` (null for a result that does not record it): an impact of a few
    microseconds between two samples is not seen, so these peaks grow with ``solver.samples_per_revolution``.
    ``sampling`` says whether those samples resolve the contacts' fastest ringing (2.4 samples per period of it)
    and which sampling would (runtime/solving/ringing.py); null for a run without contacts, one that failed at its
    start, or a result that does not record it. ``accuracy`` says whether the method controls its error
    (``error_control``; false for a fixed-step method) and, in ``note``, what a fixed step or a loose tolerance
    costs and how to check it (runtime/solving/accuracy.py); null for a result that does not record it. ``liftoff``
    is the part of the run with the seal tip off the housing (:func:`.liftoff.liftoff`: ``fraction`` of the samples,
    the ``longest_deg`` stretch and its start ``longest_from_deg``, ``ok`` false when it is most of the run); null
    for a model without the housing contact. ``wear`` is where and how fast the seal slides on its walls and
    Archard's sliding work there, with the seal's mass and length (:func:`.wear.wear`). ``energy_balance`` is the
    seal's energy balance over the samples (:func:`.energy.energy_balance`): its ``residual_J_per_rev`` is the work
    the samples miss, and ``closes`` false says that the contacts' works, friction powers and sliding works as
    small as it are sums over samples that do not resolve them. ``last_revolution`` (runs
    of two revolutions or more) holds the same numbers (:func:`run_quantities`) over the last revolution alone
    (``from_deg``..``to_deg`` of crank angle from the run's start): without the start-up from rest, the periodic
    regime of a run that went until periodic; the spectrum, the chamber gas (already its last revolution) and the
    run's record are the whole run's."""
    per_revolution = result.info.get("samples_per_revolution")
    out: dict = {"status": result.status, "stop": None if result.stop is None else result.stop.describe(),
                 "samples": int(result.n),
                 "samples_per_revolution": None if per_revolution is None else int(per_revolution),
                 # whether those samples resolve the contacts' ringing (runtime/solving/ringing.py; null: not known)
                 "sampling": result.info.get("sampling"),
                 # error control of its method and what its tolerances cost (runtime/solving/accuracy.py; null: not known)
                 "accuracy": result.info.get("accuracy"),
                 "revolutions": result.revolutions}
    out.update(run_quantities(result))
    if "F_housing_X" in result.outputs and result.n > 8:
        w, amp = spectrum(housing_force(result)[1:], float(np.mean(np.diff(result.time))))
        out["housing_force_spectrum_peaks"] = spectral_peaks(w, amp)
    last = last_revolution_part(result)
    if last is not None:  # the same numbers over the last revolution alone, without the start-up from rest
        out["last_revolution"] = {"from_deg": float(np.degrees(last.theta[0])),
                                  "to_deg": float(np.degrees(last.theta[-1])), **run_quantities(last)}
    gas = checked(result).gas  # computed once: the run's warnings read it too (runtime/results/checked.py)
    if gas is not None:
        out["gas"] = gas
    out["run"] = dict(result.info)
    out["versions"] = run_versions(result)
    if scene_info:
        out["scene"] = scene_info
    return out


def run_quantities(result: SimulationResult) -> dict:
    """The designer's numbers over the samples of ``result``: ``extremes`` of x, y, phi with their crank angles,
    ``mode_fraction``, ``liftoff``, ``wear``, ``events`` (the switches up to its last sample), mean friction
    powers, the leakage gap, the housing force (Eq. 68), and the checks ``plausibility`` (with a recorded side
    clearance) and ``flank`` (Eqs. 20-23). :func:`summarise` gives them over the whole run and, in
    ``last_revolution``, over the part :func:`last_revolution_part` cuts out."""
    deg = np.degrees(result.theta)
    out: dict = {}
    extremes = {}
    for name, (unit, scale) in EXTREMES.items():
        v = result.state[result.state_names.index(name)] * scale
        extremes[name] = {"unit": unit, "min": float(v.min()), "min_at_deg": float(deg[v.argmin()] % 360),
                          "max": float(v.max()), "max_at_deg": float(deg[v.argmax()] % 360)}
    out["extremes"] = extremes
    counts = Counter(result.modes[1:] or result.modes)
    total = sum(counts.values())
    out["mode_fraction"] = {m: counts[m] / total for m in sorted(counts, key=lambda m: -counts[m])}
    # the tip off the housing: fraction, longest stretch, whether it is most of the run (null: no housing contact)
    checks = checked(result)  # computed once: the run's warnings read them too (runtime/results/checked.py)
    out["liftoff"] = checks.liftoff
    # sliding speeds and Archard's sliding work at each contact, the seal's mass and length (null: no sliding output)
    out["wear"] = wear(result)
    # whether the samples resolve the loads' work: the seal's energy balance over them (null: no scene, no load)
    out["energy_balance"] = energy_balance(result)
    out["events"] = {g: int(result.events[i, -1]) for i, g in enumerate(result.guard_names)}
    out["events_total"] = int(result.events[:, -1].sum()) if result.events.size else 0
    means = {k[3:]: run_mean(v) for k, v in result.outputs.items() if k.startswith("Pf_")}
    powers = {k: None if math.isnan(v) else v for k, v in means.items()}  # null: no interval computed
    out["mean_friction_power_W"] = powers
    # a quantity of a contact the model does not have (its effect off) is null, as a friction power is
    if "b_gap" in result.outputs:
        gaps = gap_series(result)
        out["leakage_gap"] = {"open_fraction": float(np.mean(gaps > 0)), "mean_um": float(gaps.mean() * 1e6),
                              "max_um": float(gaps.max() * 1e6)}
    else:
        out["leakage_gap"] = dict.fromkeys(("open_fraction", "mean_um", "max_um"))
    if "F_housing_X" in result.outputs:
        F = housing_force(result)
        out["housing_force_N"] = {"mean": float(F.mean()), "max": float(F.max()),
                                  "max_at_deg": float(deg[F.argmax()] % 360)}
    else:
        out["housing_force_N"] = dict.fromkeys(("mean", "max", "max_at_deg"))
    if checks.plausibility is not None:
        out["plausibility"] = checks.plausibility
    if checks.flank is not None:
        out["flank"] = checks.flank
    return out


def last_revolution_part(result: SimulationResult) -> SimulationResult | None:
    """The last revolution of a run of two or more as a result of its own: the samples of :func:`.gas.last_revolution`
    (the last 360° of crank angle, from the sample where it begins), its switches counted from that sample. None for
    a run shorter than two revolutions (its last revolution is the start-up from rest)."""
    if result.revolutions < 2:
        return None
    k = last_revolution(result)
    events = result.events[:, k] - result.events[:, k.start:k.start + 1]  # its own, from where it begins
    return replace(result, theta=result.theta[k], time=result.time[k], state=result.state[:, k],
                   closed=result.closed[:, k], events=events, modes=list(result.modes[k]),
                   outputs={name: np.asarray(v)[k] for name, v in result.outputs.items()})


def run_versions(result: SimulationResult) -> dict:
    """The versions a result's summary names: the run's own record (its info's ``versions``), or, for a result
    without one, :func:`versions` of now for its scene's model, so that a package whose submodel was off in the run
    is not named (every installed package's only where the scene is not known)."""
    if result.info.get("versions"):
        return result.info["versions"]
    if result.scene is None:
        return versions()
    from ...derive.choices import options_of

    return versions(options_of(result.scene.effects, result.scene.assumptions))


def versions(opts=None) -> dict:
    """The versions a run's results depend on: apexseal's, its numerical libraries', Python's, the machine's kind,
    and each installed package's whose submodel entered the model (``opts``: the model's options; None: every
    installed package's). A submodel that is off enters neither the derivation nor the run, nor its record."""
    import casadi
    import numpy

    from ... import __version__
    from ...derive.submodels.registry import installed
    from ...versions import distribution_version

    # sympy's version from its distribution: reading it does not import sympy (1 s) into a run
    out = {"apexseal": __version__, "casadi": casadi.__version__, "sympy": distribution_version("sympy"),
           "numpy": numpy.__version__, "python": platform.python_version(), "machine": platform.machine()}
    # the packages whose submodels are in the registry (docs/extending.md), e.g. "submodel cushion": "seal-extras 0.2"
    out.update({f"submodel {name}": dist for name, dist in installed(opts).items()})
    return out
