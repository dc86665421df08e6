"""The numerical noise of a run's compared numbers: how far integration error alone moves each of them.

The contact impacts amplify integration and rounding error: on the default scene at rtol 1e-6 a spring stiffness
changed by 1e-12 of itself moves the contact switches by 1.9 % and re-running at rtol 1e-7 moves the friction
power at a groove contact by 1 % (docs/results.md, "Numerical noise", the commands and every number). A change
:func:`apexseal.compare` shows is an effect of what differs between the runs only where it exceeds that noise.

Two estimates, a number per quantity, in the quantity's unit:

* :func:`rule_noise` (no run): the relative spread that rtol 1e-6 alone gave each kind of quantity on the default
  scene (:data:`SPREAD_AT_1E6`), scaled in proportion to the run's rtol (measured: rtol 1e-7 gives a tenth);
* :func:`measured_noise` (a run): the change of the first run when re-run at a tenth of its rtol
  (:func:`rerun`): the re-run's own error is a tenth of it, so the change is the first run's integration error.

A change between two runs is within the noise (:func:`within`) when it is no larger than the two runs' noises
together: each run carries its own error.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

#: the rtol at which :data:`SPREAD_AT_1E6` was measured
MEASURED_RTOL = 1e-6
#: relative spread (of the value) per kind of quantity at rtol 1e-6 on the default scene (the largest measured,
#: rounded up; docs/results.md, "Numerical noise"): counts of switches and fractions of samples move most, then the
#: friction power of the groove's contacts (a few impacts each), then peaks, extremes and penetrations at the
#: samples, and the means least
SPREAD_AT_1E6 = {"count": 0.02, "groove friction": 0.01, "peak": 0.005, "mean": 0.001}


def _groove() -> tuple[str, ...]:
    """The groove's contacts (i1, c2, i2, c4), as its submodel declares them."""
    from ...derive.submodels.groove import GrooveContacts

    return GrooveContacts.contact_names


def kind(name: str) -> str | None:
    """The kind of a compared quantity (a key of :data:`SPREAD_AT_1E6`), None for one without noise (the
    revolutions computed, the seal's mass). The wear numbers' sliding work and power at a contact
    (runtime/results/wear.py) are of a friction power's kind: N |v| where friction dissipates mu N |v|."""
    head, _, tail = name.partition(".")
    if name in ("revolutions", "wear.seal_mass"):  # computed from the scene, not integrated
        return None
    if head == "events" or name in ("liftoff_fraction", "gap.open_fraction"):
        return "count"
    if head == "friction_power":
        return "groove friction" if tail in _groove() else "mean"
    if head == "wear" and tail.split(".")[-1] in ("work", "power"):  # Archard's sliding work, like friction power
        return "groove friction" if tail.split(".")[0] in _groove() else "mean"
    if name.endswith((".mean", ".speed_mean")) or head == "gas" and name != "gas.pressure.max":
        return "mean"
    return "peak"  # extremes, largest forces and gaps, penetrations, flank.least, the highest chamber pressure


def rtol_of(result) -> float | None:
    """The rtol a run's error was controlled to; None for a fixed-step method (it controls no error)."""
    from ..solving.methods import method_of

    method = result.info.get("method")
    try:
        if method is None or method_of(method).fixed_step:
            return None
    except Exception:  # a method this version does not know: its rtol is still what it was asked
        pass
    rtol = result.info.get("rtol")
    return None if rtol is None else float(rtol)


def rule_noise(values: dict[str, float], rtol: float | None) -> dict[str, float]:
    """Each quantity's noise by the rule: :data:`SPREAD_AT_1E6` scaled by ``rtol`` / 1e-6, of its value, but for
    the friction power at a groove contact of the groove contacts' sum (a few impacts share it out: at 360 samples
    per revolution one of 2e-5 W moved by 66 % between rtol 1e-6 and 1e-7, 0.008 % of the sum); NaN without an
    rtol."""
    out = {}
    for name, value in values.items():
        k = kind(name)
        if k is None:
            out[name] = 0.0
        elif rtol is None or not isinstance(value, int | float) or math.isnan(value):
            out[name] = math.nan
        else:
            scale = _groove_sum(values, name) if k == "groove friction" else abs(value)
            out[name] = SPREAD_AT_1E6[k] * rtol / MEASURED_RTOL * scale
    return out


def _groove_sum(values: dict[str, float], name: str) -> float:
    """The sum over the groove's contacts of the quantity ``name`` is one of (``friction_power.<c>`` or
    ``wear.<c>.<what>``): a few impacts share it out between them."""
    head, _, tail = name.partition(".")
    what = tail.partition(".")[2]
    names = [f"{head}.{c}" + (f".{what}" if what else "") for c in _groove()]
    return sum(abs(values[n]) for n in names if not math.isnan(values.get(n, math.nan)))


def measured_noise(values: dict[str, float], rerun: dict[str, float]) -> dict[str, float]:
    """Each quantity's noise measured: its change in the re-run at a tighter rtol."""
    return {name: abs(value - rerun.get(name, math.nan)) for name, value in values.items()}


def within(value: float, base: float, noise: float, base_noise: float) -> bool:
    """Whether ``value``'s change against ``base`` is no larger than the two runs' noises together."""
    if any(not isinstance(v, int | float) or math.isnan(v) for v in (value, base, noise, base_noise)):
        return False
    return abs(value - base) <= noise + base_noise


def rerun(result, *, out=None, progress: bool = False):
    """``result``'s scene re-run at a tenth of its rtol (and of its atol, when one is given), with every other
    setting as it ran; streamed into ``out`` (a folder) when given, so an interrupted re-run keeps its
    revolutions. Refused (ValueError naming the field) for a run that did not complete, one without its scene,
    a fixed-step method's and an rtol whose tenth is below the allowed 1e-12."""
    from ..api import simulate

    if result.status != "completed":
        raise ValueError(f"noise: the first result's status is {result.status!r}; re-running it at a tighter rtol "
                         "needs a completed run (allowed: status 'completed')")
    if result.scene is None:
        raise ValueError("noise: the first result has no scene.toml; its scene cannot be re-run")
    rtol = rtol_of(result)
    if rtol is None:
        raise ValueError(f"noise: the first result's method {result.info.get('method')!r} controls no error (a "
                         "fixed-step method): no rtol to tighten; compare it with an erk run instead")
    if rtol / 10 < 1e-12:
        raise ValueError(f"noise: solver.rtol = {rtol:g}: its tenth is below the allowed 1e-12 (allowed for "
                         "--noise: 1e-11 <= rtol)")
    atol = result.scene.solver.atol
    return simulate(result.scene, rtol=rtol / 10, **({} if atol is None else {"atol": atol / 10}),
                    out=out, progress=progress)


def same_run_but_rtol(keys: Sequence[dict[str, str]]) -> list[str]:
    """The scene keys (:func:`.compare.scene_keys` of two scenes) that differ other than the tolerances."""
    first, second = keys
    return sorted(k for k in {*first, *second} if k not in ("solver.rtol", "solver.atol")
                  and first.get(k) != second.get(k))
