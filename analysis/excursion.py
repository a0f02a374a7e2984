"""Peak excursion of a measurement (docs/physics.md section 6): reported for every one.

The peak is taken from the coherent mean period, the average of the analysed
periods sample by sample,

    x_mean[n] = (1/P) sum_p x_p[n],   peak = max_n |x_mean[n] - <x_mean>|

so noise (which averages down by sqrt(P)) does not inflate it, while the
distortion products, which are periodic, stay in. The period's own mean is
removed: a laser measures a distance with an arbitrary offset, so the rest
position is not known; a DC shift of the cone under drive (from an asymmetric
Bl(x) or Kms(x)) is removed with it.
"""
from __future__ import annotations

import numpy as np

from analysis.recording.format import Recording

# The small-signal excursion limit: the level check raises the level until the peak reaches it, and the
# plausibility check calls a peak far above it impossible (here, not in analysis.level_check, so that judging
# a result does not load the level check and its validity limits).
DEFAULT_X_LIMIT_M = 0.5e-3


def peak_of_period(mean_period: np.ndarray, centre: float | None = None) -> float:
    """Largest |x - mean(x)| of one (averaged) period, m. `centre`: mean(x), when already known (a live frame
    has it from the FFT's DC bin: one pass over the period fewer)."""
    x = np.asarray(mean_period, dtype=np.float64)
    if x.size == 0:
        return 0.0
    if centre is None:
        centre = x.mean()
    return float(max(x.max() - centre, centre - x.min()))


def peak_excursion(periods: np.ndarray) -> float:
    """Peak of the coherent mean of a (P, N) stack of periods, m."""
    return peak_of_period(np.asarray(periods, dtype=np.float64).mean(axis=0))


def peak_from_spectrum(mean_spectrum: np.ndarray, period_samples: int) -> float:
    """The same peak from the one-sided peak-amplitude mean spectrum (analysis.spectra convention)."""
    spectrum = np.array(mean_spectrum, dtype=np.complex128)
    spectrum[0] = 0.0                       # the period's mean, see the module docstring
    spectrum *= period_samples / 2.0        # undo the peak-amplitude scaling of period_spectra
    if period_samples % 2 == 0:
        spectrum[-1] *= 2.0
    return peak_of_period(np.fft.irfft(spectrum, period_samples))


def recording_peak_displacement(recording: Recording) -> float | None:
    """Peak excursion of a recording's analysed periods, m; None without a displacement channel."""
    if recording.signal("displacement") is None:
        return None
    return peak_excursion(recording.periods("displacement"))
