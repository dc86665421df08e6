"""Do the default scene's output samples resolve the work of its loads? The seal's energy balance
(:mod:`apexseal.runtime.results.energy`) over its second, settled revolution at several output samplings, and each
contact's work, friction dissipation (the integral of ``Pf_<contact>``) and Archard's sliding work (summary.json's
``wear``) beside the densest sampling's.

    python -m apexseal.runtime.studies.calibration.energy   # three runs of two revolutions, a few seconds

The balance's change of kinetic energy is exact (the states at the revolution's ends); the work is summed from the
samples. Its residual is what the samples miss; a contact whose work moves with the sampling is where.
"""

from __future__ import annotations

import warnings

import numpy as np

from ...results.energy import energy_balance
from ...results.summary import last_revolution_part
from ...results.wear import wear

SAMPLES = (360, 3600, 36000)


def settled(samples=SAMPLES) -> dict:
    """The default scene's second revolution (of two from rest, by its method) at each output sampling of
    ``samples`` (per revolution): ``{n: result}``."""
    import apexseal

    sc = apexseal.load_scene()
    out = {}
    for n in samples:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out[n] = last_revolution_part(apexseal.simulate(sc, revolutions=2, samples_per_revolution=n,
                                                            progress=False))
    return out


def friction_work(result) -> dict[str, float]:
    """Each contact's friction dissipation over ``result`` (J): the trapezoidal integral of ``Pf_<contact>``."""
    return {k[3:]: float(np.trapezoid(v, result.time)) for k, v in result.outputs.items() if k.startswith("Pf_")}


def _pct(value, reference) -> str:
    return f"{100 * (value / reference - 1):+.1f} %" if reference else "-"


def main() -> None:
    runs = settled()
    dense = max(SAMPLES)
    tables = {n: (energy_balance(r), friction_work(r), wear(r)) for n, r in runs.items()}
    for n, (bal, _, _) in tables.items():
        print(f"{n:6d} samples/rev: kinetic energy change {bal['kinetic_change_J_per_rev']:.3g} J, inertia forces' "
              f"work {bal['inertial_J_per_rev']:.4g} J, residual {bal['residual_J_per_rev']:.4g} J "
              f"({100 * bal['residual_fraction']:.1f} % of the terms; closes: {bal['closes']})")
    ref_bal, ref_fric, ref_wear = tables[dense]
    print(f"per contact, J per revolution (in brackets: against {dense} samples/rev)")
    for c in ref_bal["work_J_per_rev"]:
        line = [f"{c:9s}"]
        for n, (bal, fric, wr) in tables.items():
            w = bal["work_J_per_rev"][c]
            part = f"{n}: work {w:+.3g}"
            if c in fric:
                part += f", friction {fric[c]:.3g} [{_pct(fric[c], ref_fric[c])}]"
            if wr is not None and c in wr["contacts"]:
                s, s0 = (x["contacts"][c]["sliding_work_J_per_rev"] for x in (wr, ref_wear))
                part += f", N|v| {s:.3g} [{_pct(s, s0)}]"
            line.append(part)
        print(" | ".join(line))
    for n, (bal, fric, _) in list(tables.items())[:-1]:
        missed = {c: bal["work_J_per_rev"][c] - ref_bal["work_J_per_rev"][c] for c in bal["work_J_per_rev"]}
        top = sorted(missed, key=lambda c: -abs(missed[c]))[:3]
        total = fric.get("total", np.nan)
        print(f"{n:6d}: work against {dense}: " + ", ".join(f"{c} {missed[c]:+.3g} J" for c in top)
              + f"; friction in total {total:.4g} J [{_pct(total, ref_fric.get('total'))}]")


if __name__ == "__main__":
    main()
