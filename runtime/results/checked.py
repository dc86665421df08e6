"""The checks of a whole run, computed once: :func:`apexseal.simulate` warns from them and its summary
(summary.json, :func:`.summary.summarise`) writes them.

Lift-off (:mod:`.liftoff`), the chamber gas's cycle (:mod:`.gas`), the penetrations and the groove mouth corners
(:mod:`.plausibility`) each read every sample of the run; a run of many revolutions computed them twice, once for
its warnings and once more for its summary. :func:`checked` keeps them with the result they were computed from: a
result cut from it (``dataclasses.replace``, the last revolution of a summary) is another object and gets its own.
"""

from __future__ import annotations

from dataclasses import dataclass

from .gas import gas_summary, has_gas
from .liftoff import liftoff
from .plausibility import flank_check, penetration_check

#: the attribute of a result that holds its checks
ATTRIBUTE = "_checked"


@dataclass(frozen=True)
class RunChecked:
    """``liftoff``: :func:`.liftoff.liftoff`; ``gas``: :func:`.gas.gas_summary` (None without the gas model or
    with fewer than three samples); ``plausibility``: :func:`.plausibility.penetration_check` against the side
    clearance the run recorded (None without one); ``flank``: :func:`.plausibility.flank_check`."""

    liftoff: dict | None
    gas: dict | None
    plausibility: dict | None
    flank: dict | None


def checked(result) -> RunChecked:
    """The checks of ``result``, computed at the first call and kept with it while its samples and its recorded side
    clearance are those they were computed from."""
    kept = getattr(result, ATTRIBUTE, None)
    clearance = result.info.get("side_clearance_m")
    if kept is not None and kept[0] is result.theta and kept[1] == clearance:  # the samples and clearance they had
        return kept[2]
    checks = RunChecked(liftoff=liftoff(result),
                        gas=gas_summary(result) if has_gas(result) and result.n > 2 else None,
                        plausibility=penetration_check(result) if clearance is not None else None,
                        flank=flank_check(result))
    setattr(result, ATTRIBUTE, (result.theta, clearance, checks))
    return checks
