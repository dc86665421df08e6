"""Is the seal tip on the housing? The part of a run with the tip lifted off, and a warning when it is most of it.

The housing contact (Eq. 33: xs5, the tip's penetration into the housing; Eq. 68: its force Fs5) is open while the
tip is off the housing: the mode labels of those samples carry the guard's open label (``h0``: modes ``*_h0_*``).
There the tip does not seal the two chambers from each other and its contact force is zero. :func:`liftoff` is
the one computation of that part of a run: ``summary.json`` carries it as ``liftoff``, the sweeps and
``apexseal compare`` read their ``liftoff_fraction`` from it (:mod:`.quantities`), and the console's summary
prints it.

The paper's tip contact (Eqs. 33-34, Algorithm 2) opens and closes: lift-off is part of the seal's dynamics, and
its case study lifts off briefly: the impacts at the chamber
switches throw the tip off the housing for a few samples (docs/paper-findings.md, finding 2: 1.36 µm at 183.6°; the
default scene: 1.22 % of a revolution, longest 1° from 184°, and 0.08-2.3 % over the preload map of
docs/sweeps.md). A preload too low for the seal's inertia lets it off for longer (the hard lift-off scene's 0.5 N:
23 % of a revolution, longest 62°), a design problem the preload study answers (docs/preload.md). A tip off the
housing for half a revolution or more (``WARN_FRACTION`` of the run, or one stretch of ``WARN_FRACTION`` × 360°)
leaves a chamber unsealed for a whole stroke (the chambers switch every half revolution): not a transient but a
seal that does not work, from pressures that push the seal off the housing (or hold it in its groove by friction)
or a preload far too low. :func:`apexseal.simulate` warns with :class:`LiftOffWarning` then.
"""

from __future__ import annotations

import numpy as np

from ..scenes.units import PlausibilityWarning

#: a tip off the housing for at least this fraction of the run, or for one stretch of this fraction of a
#: revolution, is warned of: half a revolution, a whole chamber stroke unsealed (see the module docstring)
WARN_FRACTION = 0.5


class LiftOffWarning(PlausibilityWarning):
    """A run whose seal tip is off the housing for most of it (a kind of the scene's
    :class:`~apexseal.runtime.scenes.units.PlausibilityWarning`: filtering that one filters this one too)."""


def tip_labels() -> tuple[str, str]:
    """The housing contact's part of a mode label, closed and open (``"h"``, ``"h0"``), as its submodel declares."""
    from ...derive.submodels.registry import guard

    tip = guard("xs5")
    return tip.closed_label, tip.open_label


def liftoff(result) -> dict | None:
    """The part of the run with the tip off the housing: ``fraction`` of the samples (the first, the start state,
    left out, as ``mode_fraction`` leaves it out), the ``longest_deg`` stretch of crank angle in one piece (each
    lifted sample counts from the sample before it) and where it begins (``longest_from_deg``, within its
    revolution), and ``ok`` (false when :func:`too_long`). None for a model without the housing contact, and for a
    run without a sample after its start."""
    if result.n < 2:
        return None
    closed, lifted = tip_labels()
    modes = result.modes[1:]
    parts = {m: set(m.split("_")) for m in dict.fromkeys(modes)}  # a run has a few labels over many samples
    if not any({closed, lifted} & p for p in parts.values()):
        return None  # no housing contact in this model
    off = np.fromiter((lifted in parts[m] for m in modes), dtype=bool, count=len(modes))
    # the stretches of lifted samples, each from the sample before its first (off[i] is sample i + 1) to its last
    edges = np.diff(np.concatenate(([0], off.astype(np.int8), [0])))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    deg = np.degrees(np.asarray(result.theta, float))
    lengths = deg[ends] - deg[starts]
    k = int(np.argmax(lengths)) if lengths.size else None
    longest = 0.0 if k is None else float(lengths[k])
    start = None if k is None else starts[k]
    out = {"fraction": float(off.mean()), "longest_deg": longest,
           "longest_from_deg": None if start is None else float(deg[start] % 360)}
    return out | {"ok": not too_long(out)}


def too_long(check: dict) -> bool:
    """Whether the tip is off the housing for most of the run: ``WARN_FRACTION`` of it, or one stretch of
    ``WARN_FRACTION`` of a revolution."""
    return check["fraction"] >= WARN_FRACTION or check["longest_deg"] >= WARN_FRACTION * 360


def fraction(check: dict | None) -> float:
    """The lift-off fraction of a summary's ``liftoff`` (NaN without the housing contact)."""
    return float("nan") if check is None else float(check["fraction"])


def describe_liftoff(check: dict, revolutions: float, guard_names=("spring",)) -> str:
    """One line for a :class:`LiftOffWarning`: how much of the run, the longest stretch, and what it means;
    ``guard_names``: the run's contacts (without ``spring``, the spring is off, and the message says so instead of
    pointing at its preload)."""
    spring = ("the spring preload (spring.delta_s, spring.ks)" if "spring" in guard_names else
              "the spring, which is off (effects.spring = false): nothing presses the seal onto the housing but "
              "the pressures")
    return (f"the seal tip is off the housing for {check['fraction']:.1%} of the samples of {revolutions:.3g} "
            f"revolution{'' if revolutions == 1 else 's'} (longest {check['longest_deg']:.4g}° in one stretch, "
            f"from {check['longest_from_deg']:.4g}°): "
            "there the tip does not seal the chambers from each other and its contact force Fs5 is zero (Fig. 14 "
            "has little or no spectrum); check the chamber pressures (their unit, and which side is high) and "
            + spring)
