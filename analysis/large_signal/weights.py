"""The weight of each line of the large-signal regressions: its noise, and the misfit the model leaves there.

The noise of a line is the variance of its equation error in the mean
period: the scatter of the same equation error between the periods,
divided by P (as analysis.spectra does for Z and Hx), pooled over
neighbouring lines until it rests on enough degrees of freedom, and
unbiased for the reciprocal (nu / (nu - 2)).
"""
from __future__ import annotations

import numpy as np

from analysis.spectra import pooling_window
from analysis.validity.pooling import pooled_mean

MISFIT_BANDS_PER_OCTAVE = 3.0
MISFIT_SIGMAS = 4.0


def noise_variance(residual_per_period: np.ndarray) -> np.ndarray:
    """Variance of the mean period's equation error per line, from P periods' errors (P, bins); pooled, unbiased."""
    p = residual_per_period.shape[0]
    dev = residual_per_period - residual_per_period.mean(axis=0)
    var = np.sum(dev.real**2 + dev.imag**2, axis=0) / (p * (p - 1))
    window = pooling_window(p)
    nu = 2 * (p - 1) * window
    pooled = pooled_mean(var, window) * (nu / (nu - 2.0))
    floor = np.max(pooled) * 1e-15 if np.max(pooled) > 0 else 1e-300
    return np.maximum(pooled, floor)


def misfit_variance(residual: np.ndarray, noise: np.ndarray, bins: np.ndarray,
                    bands_per_octave: float = MISFIT_BANDS_PER_OCTAVE) -> np.ndarray:
    """What the residual holds beyond the noise, per fractional-octave band: max(mean |r|^2 - mean noise, 0).

    A line where the model misses more than the noise (at high frequencies a
    coil's semi-inductance, a cone's break-up, a simulation's step) is worth
    less than its noise says: counting the misfit as noise lets the lines the
    model does explain carry the curves, and keeps the bands honest where it
    does not (a band that ignored the misfit would be as narrow as the noise
    and miss the truth).
    """
    band = np.floor(bands_per_octave * np.log2(bins / bins[0])).astype(int)
    count = np.maximum(np.bincount(band), 1)
    power = np.bincount(band, residual.real**2 + residual.imag**2) / count
    floor = np.bincount(band, noise) / count
    # Only an excess the band's own scatter cannot make (|r|^2 / noise is chi^2 with 2 dof per line).
    significant = power > floor * (1.0 + MISFIT_SIGMAS / np.sqrt(count))
    return np.where(significant, power - floor, 0.0)[band]
