"""The numbers of docs/paper-findings.md: the paper's features on the default scene, with and without the chamber
pressure, by erk and by explicit (forward) Euler at several steps (apexseal's reading of the paper's "Euler
method", Section 1).

    python -m apexseal.runtime.studies.calibration.findings                 # about 10 s on one core
    python -m apexseal.runtime.studies.calibration.findings --samples 36000 # the same at 36000 output samples

Each run is two revolutions from rest; the features are those of the last one (:mod:`.features`). Its extremes,
|Fs5| max and deepest penetrations are the largest at the output samples (the scene's
``solver.samples_per_revolution``, 3600 on the default scene, or ``--samples``): an impact of a few microseconds
falls between them, so a denser sampling finds higher peaks, by erk and by Euler alike, and the difference of two
runs' peaks is partly where their samples fall. An Euler run's steps are rounded to a whole number per output
interval (:func:`~apexseal.runtime.solving.methods.fixed_steps`), so its steps per revolution move a little with
the sampling; each line prints the steps taken.

Besides the features it prints the unsmoothed |Fs5| spectrum at its first bins, which over the one revolution
analysed are the rotor's harmonics (bins omega = 157 rad/s apart), and its largest amplitude above ``HIGH_BAND``,
where the paper's main peak lies.
"""

from __future__ import annotations

import math
import time
import warnings

import numpy as np

from .features import features as features_of
from .features import force_spectrum, last_revolution

#: (label, method, Euler steps per revolution)
RUNS = (("erk", "erk", None), ("euler 1e6", "euler", 1_000_000), ("euler 2e5", "euler", 200_000),
        ("euler 6e4", "euler", 60_000))
#: the rotor harmonics (multiples of omega, the first bins of a one-revolution spectrum) whose amplitude is printed
HARMONICS = (1, 2, 3, 4)
#: rad/s: the largest amplitude above this is printed (the paper's main peak, 6e4 rad/s, lies above it; its smaller
#: peaks at 1e2 and 5e2 rad/s below)
HIGH_BAND = 1.0e4


def spectrum_lines(w: np.ndarray, amp: np.ndarray, omega: float) -> dict:
    """What a spectrum ``w`` (rad/s), ``amp`` (N) says of the paper's Fig. 14: its bin width, the amplitude at the
    bin nearest each of ``HARMONICS`` times ``omega`` (as ``{frequency of the bin: amplitude}``), and the largest
    amplitude above ``HIGH_BAND`` with its frequency."""
    lines = {}
    for k in HARMONICS:
        i = int(np.argmin(np.abs(w - k * omega)))
        lines[float(w[i])] = float(amp[i])
    high = w > HIGH_BAND
    j = int(np.argmax(np.where(high, amp, -np.inf)))
    return {"bin_rad_s": float(w[1] - w[0]), "harmonics_N": lines, "high_N": (float(amp[j]), float(w[j]))}


def run_all(scene=None, revolutions: int = 2, samples: int | None = None) -> list[dict]:
    """Every run of ``RUNS`` with and without the chamber pressure; ``samples``: output samples per revolution
    (default the scene's ``solver.samples_per_revolution``)."""
    import apexseal
    from apexseal.runtime.api import model_functions
    from apexseal.runtime.results.plausibility import penetration_check
    from apexseal.runtime.solving.methods import fixed_steps

    base = scene or apexseal.load_scene()
    rows = []
    for pressure in (True, False):
        sc = base if pressure else base.with_overrides(**{"effects.chamber_pressure": False})
        fns = model_functions(sc)
        for label, method, steps in RUNS:
            start = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                extra = {} if steps is None else {"steps_per_revolution": steps}
                if samples is not None:
                    extra["samples_per_revolution"] = samples
                r = apexseal.simulate(sc, revolutions=revolutions, method=method, functions=fns, **extra)
            n = int(r.info.get("samples_per_revolution") or samples or sc.solver.samples_per_revolution)
            row = {"pressure": pressure, "run": label, "status": r.status, "wall_s": time.perf_counter() - start,
                   "samples_per_revolution": n,
                   "steps_taken": None if steps is None else n * fixed_steps(steps, 2 * math.pi / n)}
            if not r.ok:
                row["stop"] = r.stop.describe()
                rows.append(row)
                continue
            f = features_of(r, sc.omega)
            w = last_revolution(r)
            x, y = r.state[0][w] * 1e6, r.state[1][w] * 1e6
            om, raw = force_spectrum(r, w, bins=1)
            row.update(f.to_dict())
            row.update({"x_um": (float(x.min()), float(x.max())), "y_um": (float(y.min()), float(y.max())),
                        "penetration_um": penetration_check(r)["penetration_um"],
                        "events": int(r.events[:, -1].sum() - r.events[:, int(w.start)].sum()),
                        "spectrum": spectrum_lines(om, raw, sc.omega),
                        "housing_mode_rad_s": math.sqrt(sc.parameters["kw"] / sc.parameters["ms"])})
            rows.append(row)
    return rows


def main(argv: list[str] | None = None) -> None:
    import argparse

    parser = argparse.ArgumentParser(prog="python -m apexseal.runtime.studies.calibration.findings",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--samples", type=int, default=None,
                        help="output samples per revolution (default: the scene's solver.samples_per_revolution); "
                             "the extremes, |Fs5| max and penetrations are the largest at these samples")
    args = parser.parse_args(argv)
    rows = run_all(samples=args.samples)
    if rows:
        print(f"at {rows[0]['samples_per_revolution']} output samples per revolution (extremes, |Fs5| max and "
              "deepest penetration: the largest at those samples)")
    for row in rows:
        steps = "" if row["steps_taken"] is None else f" ({row['steps_taken']:.4g} steps/rev)"
        head = (f"pressure {'on ' if row['pressure'] else 'off'} | {row['run']:9s}{steps} | {row['wall_s']:5.1f} s "
                "| ")
        if row["status"] != "completed":
            print(head + row["status"] + ": " + row["stop"][:160])
            continue
        pen = max(row["penetration_um"].values())
        sp = row["spectrum"]
        lines = ", ".join(f"{a:.3g} N at {p:.0f}" for p, a in sp["harmonics_N"].items())
        print(head + f"x {row['x_um'][0]:.3f}..{row['x_um'][1]:.3f} um (largest at {row['x_max_deg']:.1f} deg), "
              f"y {row['y_um'][0]:.2f}..{row['y_um'][1]:.2f} um | main peak {row['main_peak_rad_s']:.3g} rad/s "
              f"(sqrt(kw/ms) {row['housing_mode_rad_s']:.3g}), small-peak bands "
              + ", ".join(f"{v:.3g}" for v in row["small_peaks_rad_s"])
              + f" | |Fs5| mean {row['housing_force_mean_N']:.1f} N, max {row['housing_force_max_N']:.0f} N | "
              f"deepest penetration {pen:.2f} um | {row['events']} switches | spectrum (bins {sp['bin_rad_s']:.0f} "
              f"rad/s apart, not smoothed): {lines}; largest above {HIGH_BAND:.0e} rad/s {sp['high_N'][0]:.3g} N "
              f"at {sp['high_N'][1]:.3g}")


if __name__ == "__main__":
    main()
