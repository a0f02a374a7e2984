"""The noise of an imported curve, from its own local scatter (docs/physics.md section 9).

A curve exported by another tool has no periods to take the noise from.
Each line's noise is estimated instead from the scatter of the curve about
a smooth local fit, the idea of the local polynomial method (Pintelon and
Schoukens): over WINDOW_LINES neighbouring lines a polynomial of degree
DEGREE in f (on an evenly spaced grid, where the lowest lines span decades
of ln f) or in ln f (on any other grid) is fitted to the complex value (to the magnitude alone for a
magnitude-only curve); the residual sum of squares over its degrees of
freedom, WINDOW_LINES - (DEGREE + 1), estimates the variance at the centre
line. A window that straddles a sharp resonance is biased upwards (the
polynomial cannot follow the curve there), and one estimate rests on few
degrees of freedom, so the estimates are pooled as the recording path pools
periods, but robustly: the relative variance var/|H|^2 is taken as the
median over POOL_LINES neighbouring estimates, unbiased for the median of a
chi-square (Wilson-Hilferty), then scaled back by |H|^2.

What it cannot know: a tool that smoothed its export (1/24 octave, say)
leaves less scatter than its noise, and neighbouring lines whose errors are
correlated. tests/analysis/curves/test_noise.py checks the estimate on
simulated curves with known noise (unbiased to within 20 %).
"""
from __future__ import annotations

import dataclasses

import numpy as np
from scipy.ndimage import median_filter

from analysis.spectra import TransferFunction

WINDOW_LINES = 7
DEGREE = 2
POOL_LINES = 15


def _windows(n: int, m: int) -> np.ndarray:
    """Indices (n x m) of the m lines around each line, shifted inwards at the ends."""
    start = np.clip(np.arange(n) - m // 2, 0, n - m)
    return start[:, None] + np.arange(m)[None, :]


def evenly_spaced(freqs: np.ndarray) -> bool:
    steps = np.diff(freqs)
    return steps.size > 0 and float(np.ptp(steps)) <= 1e-3 * float(np.median(steps))


def local_variance(freqs: np.ndarray, values: np.ndarray, window: int = WINDOW_LINES,
                   degree: int = DEGREE) -> tuple[np.ndarray, int]:
    """Each line's variance about a local polynomial, and the degrees of freedom of each estimate.

    `values` complex: the variance is E|dH|^2 (both parts), on 2*(window - degree - 1)
    degrees of freedom; real: the variance of the value, on window - degree - 1.
    """
    n = len(freqs)
    idx = _windows(n, window)
    x = (freqs if evenly_spaced(freqs) else np.log(freqs))[idx]
    x = x - x.mean(axis=1, keepdims=True)
    span = np.maximum(np.ptp(x, axis=1, keepdims=True), 1e-300)
    design = (x / span)[:, :, None] ** np.arange(degree + 1)[None, None, :]     # n x m x (degree+1)
    q, _ = np.linalg.qr(design)
    y = values[idx]
    fitted = np.einsum("nmk,nk->nm", q, np.einsum("nmk,nm->nk", q, y))      # q is real: Q Q' y
    resid = y - fitted
    dof = window - degree - 1
    var = np.sum(np.abs(resid) ** 2, axis=1) / dof
    return var, (2 if np.iscomplexobj(values) else 1) * dof


def median_bias(dof: int) -> float:
    """median(chi^2_dof) / dof, by the Wilson-Hilferty approximation."""
    return (1.0 - 2.0 / (9.0 * dof)) ** 3


def estimated_std(tf: TransferFunction) -> np.ndarray:
    """The per-line standard uncertainty of a curve, as TransferFunction.std holds it (sqrt(E|dH|^2))."""
    n = len(tf.freqs)
    values = tf.value if tf.has_phase else tf.value.real
    window = min(WINDOW_LINES, n)
    if window <= DEGREE + 1:
        return np.full(n, np.nan)
    var, dof = local_variance(tf.freqs, values, window)
    with np.errstate(divide="ignore", invalid="ignore"):
        relative = var / np.abs(tf.value) ** 2
    pooled = median_filter(relative, size=min(POOL_LINES, n), mode="nearest") / median_bias(dof)
    var = pooled * np.abs(tf.value) ** 2
    # A magnitude-only line's variance is of one real number; std holds sqrt(2) times its sigma,
    # as the fit divides it by sqrt(2) per real component.
    return np.sqrt(var if tf.has_phase else 2.0 * var)


def with_estimated_noise(tf: TransferFunction) -> TransferFunction:
    """The curve with each line's noise estimated from its local scatter (unchanged when it has its own)."""
    if tf.noise_known:
        return tf
    return dataclasses.replace(tf, std=estimated_std(tf), noise_known=True)


def describe_noise(tf: TransferFunction) -> str:
    """'impedance: median 0.12 % of |Z| per line (local scatter)'."""
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = tf.std / np.abs(tf.value)
    rel = rel[np.isfinite(rel)]
    median = float(np.median(rel)) if rel.size else float("nan")
    return f"{tf.name}: median {100 * median:.2g} % of the value per line"
