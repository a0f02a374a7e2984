"""Laser samples that never came (error codes, lost measurements, forged ones) as missing data.

A straight line drawn across a gap is not a measurement: over a flood of 30
samples (7.5 ms at 4 kHz) it cuts the chord of the cone's motion, and
averaged and fitted as if measured it biased Bl by up to +1.3 %, by an
amount that depended on where in the excitation the flood fell.

The displacement is periodic with the excitation, x_p(m) = s(m) + noise in
period p at audio sample m of the period. With samples missing, the best
estimate of s(m) (maximum likelihood for white noise) is the mean over the
periods in which sample m was measured; the spectrum and the fit then rest
on the measured samples only. It is computed here without changing the
recording's shape (a plain time signal): each missing laser sample is
filled with the current estimate of s at its place in the period, and the
estimate is made again from the filled stream (``refill``). That is the EM
algorithm for this model; its fixed point is exactly the mean over the
measured periods, because a filled sample adds to its own mean only what
the other periods say. Taking each point's mean over the periods that
measured it cleanly makes the fill nearly independent of itself, so a round
or two per pass of the clock refinement converge (a plain mean over all
periods shrank a fill's error only by half a round where every other period
had lost the point).

What the missing samples cost (``gap_accounting``): at audio sample m of the
period, P_m of the P periods were measured. The mean of P_m noisy values has
the variance sigma^2 / P_m; the scatter the spectra see is that of the
measured values about their mean, sigma^2 (P_m - 1) summed over them, as the
filled values sit on the mean. So the variance of the averaged spectrum is
larger than the scatter between periods says, by

    noise_factor = [sum_m 1/P_m] P (P - 1) / [sum_m (P_m - 1)]      (1 without gaps),

which the recording carries (capture.laser_gaps) and the analysis applies to
the displacement's per-line noise (analysis/spectra.py). A stretch of the
period measured in no period at all (P_m = 0: the spot lost at the same
point of every period) keeps the bridge, a guess: ``unseen_s`` says how
long it is, and the validity turns red when it is longer than a couple of
samples, where the motion is no longer smooth enough on the laser's grid
for a bridge to hold.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from instruments.measurement.clocks import LaserClock

_CHUNK = 512          # missing samples evaluated at a time (chunk x lines complex exponentials)
CLEAN_SAMPLES = 8     # a point this many laser samples from a missing one is measured cleanly (the
                      # interpolator's kernel has fallen to a few percent there)


@dataclass(frozen=True, slots=True)
class LaserGaps:
    """The laser samples missing from the stretch that feeds the recording, and what they cost."""

    samples: int            # laser samples without a distance (error codes, lost, outliers)
    periods: int            # periods with at least one of them
    of_periods: int         # periods in the recording
    longest_run: int        # the longest run of them in a row, laser samples
    noise_factor: float     # the displacement's variance over what the scatter between periods shows
    unseen_s: float         # the longest stretch of the period measured in no period, s

    def capture_json(self) -> dict:
        """The sidecar's capture.laser_gaps (analysis.validity.capture.LaserGapInfo); a noise factor that
        cannot be known (no point of the period measured twice) is null."""
        factor = self.noise_factor if np.isfinite(self.noise_factor) else None
        return {"samples": self.samples, "periods": self.periods, "of_periods": self.of_periods,
                "longest_run": self.longest_run, "noise_factor": factor, "unseen_s": self.unseen_s}


NO_GAPS_FACTOR = 1.0


def refill(filled: np.ndarray, missing: np.ndarray, periods: np.ndarray, positions: np.ndarray, clock: LaserClock,
           first_start: int, period_samples: int, max_bin: int) -> np.ndarray:
    """The stream with its ``missing`` samples set to the periodic mean of ``periods`` (module doc).

    ``periods``: the displacement on every ``step``-th audio sample of each
    covered period (periods x samples), interpolated from ``filled`` with
    ``clock``, at the laser positions ``positions`` (same shape);
    ``first_start``: the audio index of the first period's start. Only lines
    up to ``max_bin`` (of a period) carry the displacement.

    The mean at each point is taken over the periods whose laser samples
    there, within CLEAN_SAMPLES, were all measured (else over those whose
    nearest sample was): the fill then hardly depends on the fill itself, and
    the EM rounds converge at once (the plain mean would shrink a fill's
    error only by the share of periods that measured the point, a half where
    every other period lost it).
    """
    index = np.flatnonzero(missing)
    if index.size == 0 or periods.shape[0] < 2:
        return filled
    nearest = np.clip(np.rint(positions).astype(np.int64), 0, missing.size - 1)
    mean = periods.mean(axis=0)        # where no period measured the point: the bridge, a guess
    for reach in (0, CLEAN_SAMPLES):   # the periods that measured the point; better, measured it cleanly
        near_gap = np.convolve(missing, np.ones(2 * reach + 1), mode="same") > 0 if reach else missing
        clean = ~near_gap[nearest]
        count = np.count_nonzero(clean, axis=0)
        mean = np.where(count > 0, np.sum(np.where(clean, periods, 0.0), axis=0) / np.maximum(count, 1), mean)
    lines = np.fft.rfft(mean)[: max_bin + 1] / mean.size
    lines[1:] *= 2.0
    bins = np.arange(lines.size)
    out = filled.copy()
    where = (np.asarray(clock.audio_index(index)) - first_start) / period_samples    # in periods
    for lo in range(0, index.size, _CHUNK):
        phase = np.exp(2j * np.pi * np.outer(where[lo:lo + _CHUNK], bins))
        out[index[lo:lo + _CHUNK]] = (phase @ lines).real
    return out


def gap_accounting(missing: np.ndarray, used: slice, coarse_positions: np.ndarray, n_periods: int,
                   step: int, audio_rate: float) -> LaserGaps:
    """The gaps over the laser samples ``used`` for the recording, and their cost (module doc).

    ``coarse_positions``: the laser index of every ``step``-th audio sample of
    each covered period (periods x samples); a sample counts as measured when
    its nearest laser sample is.
    """
    k = np.clip(np.rint(coarse_positions).astype(np.int64), 0, missing.size - 1)
    lost = missing[k]                                           # periods x samples
    measured = n_periods - np.count_nonzero(lost, axis=0)       # P_m
    seen = measured > 0
    spread = float(np.sum(measured[seen] - 1))
    if not np.any(lost):
        factor = NO_GAPS_FACTOR
    elif spread <= 0:
        factor = float("inf")
    else:
        factor = float(np.sum(1.0 / measured[seen]) * n_periods * (n_periods - 1) / spread)
    inside = missing[used]
    return LaserGaps(int(np.count_nonzero(inside)), int(np.count_nonzero(np.any(lost, axis=1))), n_periods,
                     _longest_run(inside), factor, _longest_run(~seen, circular=True) * step / audio_rate)


def _longest_run(flags: np.ndarray, circular: bool = False) -> int:
    """The longest run of True (around the end too when ``circular``)."""
    flags = np.asarray(flags, dtype=bool)
    if not np.any(flags):
        return 0
    if np.all(flags):
        return int(flags.size)
    if circular:                       # start just after a False: a run across the end is counted whole
        flags = np.roll(flags, -int(np.flatnonzero(~flags)[0]) - 1)
    edges = np.diff(np.concatenate([[0], flags.astype(np.int8), [0]]))
    return int(np.max(np.flatnonzero(edges == -1) - np.flatnonzero(edges == 1)))
