"""Does the |Fs5| spectrum's main peak (Fig. 14) depend on the output sampling? The main peak of the default scene
at several output samples per revolution, and the densest run's record thinned to the default sampling two ways:
every k-th sample (what a sparser run sees, aliasing included) and the mean of each block of k samples (a crude
anti-aliasing filter before the same thinning).

    python -m apexseal.runtime.studies.calibration.sampling   # three runs of two revolutions, a few seconds

Each run is two revolutions from rest by the scene's method, the last one analysed (:mod:`.features`).
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from ...results.spectra import housing_force
from ...solving.ringing import samples_resolving
from .features import (
    MIN_CONTACT_HARMONIC,
    features,
    force_spectrum,
    last_revolution,
    main_peak,
    smoothed_spectrum,
)

SAMPLES = (3600, 36000, 72000)


def main_peaks(samples=SAMPLES) -> dict:
    """The default scene's main |Fs5| peak (rad/s) at each output sampling of ``samples`` (per revolution), and the
    runs: ``({n: peak}, {n: result})``."""
    import apexseal

    sc = apexseal.load_scene()
    runs = {}
    for n in samples:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            runs[n] = apexseal.simulate(sc, revolutions=2, samples_per_revolution=n, progress=False)
    return {n: features(r, sc.omega).main_peak_rad_s for n, r in runs.items()}, runs


def main() -> None:
    import apexseal

    sc = apexseal.load_scene()
    omega = sc.omega
    peaks, runs = main_peaks()
    for n in SAMPLES:
        r = runs[n]
        w, amp = force_spectrum(r)
        band = w > MIN_CONTACT_HARMONIC * omega
        maxima = [i for i in range(1, w.size - 1) if band[i] and amp[i] >= amp[i - 1] and amp[i] > amp[i + 1]]
        top = sorted(maxima, key=lambda i: -amp[i])[:6]
        print(f"{n:6d} samples/rev: sampling rate {n * omega:.3g} rad/s, Nyquist {n * omega / 2:.3g} rad/s, main peak "
              f"{peaks[n]:.3g} rad/s; largest local maxima: "
              + ", ".join(f"{amp[i]:.2f} N at {w[i]:.3g}" for i in top))
    dense = max(SAMPLES)
    r = runs[dense]
    win = last_revolution(r)
    F, t = housing_force(r)[win], r.time[win]
    dt = float(np.mean(np.diff(t)))
    k = dense // SAMPLES[0]
    f, a = main_peak(*smoothed_spectrum(F[::k], dt * k), omega)
    print(f"{dense} thinned to every {k}th sample ({SAMPLES[0]}/rev): main peak {f:.3g} rad/s ({a:.2f} N)")
    blocks = F[: F.size // k * k].reshape(-1, k).mean(axis=1)
    f, a = main_peak(*smoothed_spectrum(blocks, dt * k), omega)
    print(f"{dense} as means of {k}-sample blocks ({SAMPLES[0]}/rev): main peak {f:.3g} rad/s ({a:.2f} N)")
    w, amp = force_spectrum(r)
    rate = SAMPLES[0] * omega
    ring = r.info["sampling"]["ringing_rad_s"]  # the seal's fastest ringing (runtime/solving/ringing.py)
    for label, freq in ((f"the contacts' fastest ringing ({ring / omega:.4g} per rad x omega)", ring),
                        (f"sampling rate at {SAMPLES[0]} minus its main peak", rate - peaks[SAMPLES[0]])):
        near = (w > freq - 1e4) & (w < freq + 1e4)
        print(f"{dense}-sample spectrum near {freq:.3g} rad/s, {label}: at most {amp[near].max():.2f} N")
    print(f"the ringing at {ring:.3g} rad/s (mode {r.info['sampling']['ringing_mode']}; sqrt(kw/ms) of the tip "
          f"alone {math.sqrt(sc.parameters['kw'] / sc.parameters['ms']):.3g} rad/s) folds to {abs(rate - ring):.3g} "
          f"rad/s at {SAMPLES[0]} samples; it lies below the Nyquist frequency from {2 * ring / omega:.0f} samples "
          f"per revolution (with a margin: {samples_resolving(ring, omega)})")

if __name__ == "__main__":
    main()
