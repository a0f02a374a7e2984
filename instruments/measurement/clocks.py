"""Two clocks on one time line: the laser's samples placed on the audio's sample grid.

The sound card and the laser each count their own samples. Both streams
arrive at the host in blocks, and the host notes when each block arrived
(time.monotonic). A block can only arrive after its last sample was taken,
never before; it arrives later by a latency that varies (thread wake-ups,
USB, the pty). So the earliest arrivals trace the sampling itself:

    arrival(block) >= intercept + slope * index(last sample of the block)

``lower_envelope`` finds that line under the points: of the lines no arrival
lies below, the one closest to them all (an edge of their lower convex hull).
Its ``jitter_s`` is the median height of the arrivals above the line.

Audio: index = the block's stop (the sample after its last), because a block
is complete, and handed over, once its last sample is in (the virtual rig
hands over frames n .. n+P-1 at the start of the cycle in which frame n+P
would be taken: instruments/rig/laser_feed.py). Laser: index = the counter of
the block's last measurement (it is sent once taken).

Put together (``clock_from_host_times``): laser sample k sits at audio index

    m(k) = offset + ratio * k,     ratio = audio samples per laser sample

``ratio`` from the two slopes is good to about a ppm over a few seconds.
The excitation then refines it (``refine_ratio``): the displacement repeats
exactly with the excitation period, so with the right ratio every line of
the resampled displacement keeps its phase from period to period; a ratio
off by a fraction e warps time by e * (m - pivot), and line b's phase drifts
by 2 pi b e / P per sample of elapsed time. The drift of the strongest lines
below the laser's Nyquist frequency, weighted by their signal-to-noise
ratio, measures e to well below a ppm. The pivot, where the time line is
best known from the host times, stays put.

The offset cannot be refined the same way: a constant delay of the
displacement is indistinguishable, in a periodic steady state, from the
driver's own phase (Hx * exp(-s tau) is as periodic as Hx). It comes from the
host times alone, good to the difference of the two streams' smallest
latencies (~0.1 ms on the virtual rig); ``latency_s`` subtracts a known
sensor/link latency (a calibration). What is left shows up in Hx as a pure
delay, a phase lag w*tau growing with frequency while |Hx| is unchanged: the
`delay-x` effect of the analysis fits it.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MIN_POINTS = 4


@dataclass(frozen=True, slots=True)
class TimeLine:
    """host time (s) = intercept + slope * index, from the lower envelope of arrivals."""

    intercept: float
    slope: float
    jitter_s: float      # median arrival above the line
    points: int

    def time_of(self, index) -> np.ndarray | float:
        return self.intercept + self.slope * np.asarray(index, dtype=np.float64)


@dataclass(frozen=True, slots=True)
class LaserClock:
    """Laser sample k sits at audio sample index offset + ratio * k."""

    offset: float
    ratio: float

    def audio_index(self, k) -> np.ndarray | float:
        return self.offset + self.ratio * np.asarray(k, dtype=np.float64)

    def laser_index(self, m) -> np.ndarray | float:
        return (np.asarray(m, dtype=np.float64) - self.offset) / self.ratio

    def laser_rate(self, audio_rate: float) -> float:
        """The laser's rate in samples per second of the audio clock."""
        return audio_rate / self.ratio

    def ppm(self, audio_rate: float, nominal_rate: float) -> float:
        """How fast the laser's clock runs against the audio's, in ppm of its nominal rate."""
        return (self.laser_rate(audio_rate) / nominal_rate - 1.0) * 1e6

    def pivoted(self, ratio: float, pivot_k: float) -> LaserClock:
        """The same audio index at laser sample ``pivot_k``, another ratio."""
        m = float(self.audio_index(pivot_k))
        return LaserClock(m - ratio * pivot_k, ratio)


def lower_envelope(index: np.ndarray, host_time: np.ndarray) -> TimeLine:
    """The line under the arrivals (module doc). ValueError with fewer than MIN_POINTS blocks.

    Of all lines that no arrival lies below, the one with the least total
    height of the arrivals above it (Moon, Skelly, Towsley, "Estimation and
    removal of clock skew from network delay measurements", INFOCOM 1999):
    the edge of the lower convex hull over the points' mean index.
    """
    index = np.asarray(index, dtype=np.float64)
    host_time = np.asarray(host_time, dtype=np.float64)
    if index.size < MIN_POINTS:
        raise ValueError(f"{index.size} blocks are too few to place a stream in time (need {MIN_POINTS})")
    order = np.argsort(index, kind="stable")
    i0, t0 = index[order[0]], host_time[order[0]]
    x, t = index[order] - i0, host_time[order] - t0      # small numbers: no cancellation
    if x[-1] <= 0:
        raise ValueError("the blocks' sample indices do not advance")
    hull = _lower_hull(x, t)
    centre = float(np.mean(x))
    edge = max(int(np.searchsorted(x[hull], centre, side="right")) - 1, 0)
    edge = min(edge, len(hull) - 2)
    a, b = hull[edge], hull[edge + 1]
    slope = (t[b] - t[a]) / (x[b] - x[a])
    intercept = t[a] - slope * x[a]
    above = t - (intercept + slope * x)
    return TimeLine(float(t0 + intercept - slope * i0), float(slope), float(np.median(above)), int(index.size))


def floor_line(index: np.ndarray, host_time: np.ndarray, slope: float) -> TimeLine:
    """The line of a known ``slope`` (s per sample: the stream's nominal rate) under every arrival: it rests on
    the single most timely block. The fallback when the envelope's own slope is implausible (alignment.py):
    arrivals late by a growing amount (a starved thread) tilt the envelope's edge, and its line at the centre
    is then as late as the arrivals there, while the most timely block, wherever it lies, still places the
    stream to its lateness plus the rate's error (tens of ppm) times its distance."""
    index = np.asarray(index, dtype=np.float64)
    host_time = np.asarray(host_time, dtype=np.float64)
    if index.size < MIN_POINTS:
        raise ValueError(f"{index.size} blocks are too few to place a stream in time (need {MIN_POINTS})")
    i0, t0 = float(index[0]), float(host_time[0])
    above = (host_time - t0) - slope * (index - i0)         # small numbers: no cancellation
    floor = float(np.min(above))
    return TimeLine(t0 + floor - slope * i0, float(slope), float(np.median(above - floor)), int(index.size))


def _lower_hull(x: np.ndarray, t: np.ndarray) -> list[int]:
    """Indices of the lower convex hull of points sorted by x (monotone chain), at least two."""
    hull: list[int] = []
    for i in range(x.size):
        if hull and x[i] == x[hull[-1]]:
            if t[i] >= t[hull[-1]]:
                continue
            hull.pop()
        while len(hull) >= 2:
            o, a = hull[-2], hull[-1]
            if (x[a] - x[o]) * (t[i] - t[o]) - (t[a] - t[o]) * (x[i] - x[o]) > 0:
                break
            hull.pop()
        hull.append(i)
    if len(hull) < 2:
        raise ValueError("the blocks' sample indices do not advance")
    return hull


def clock_from_host_times(laser: TimeLine, audio: TimeLine, latency_s: float = 0.0) -> LaserClock:
    """Laser sample k -> audio index, from the two time lines; ``latency_s``: the sensor's known latency
    (the time from a measurement to its arrival that the envelope cannot see), subtracted."""
    return LaserClock((laser.intercept - latency_s - audio.intercept) / audio.slope, laser.slope / audio.slope)


@dataclass(frozen=True, slots=True)
class RatioRefinement:
    clock: LaserClock
    drift: float            # the fraction e found in the last pass (module doc)
    passes: int
    lines: int              # lines that weighed in


def period_phase_drift(periods: np.ndarray, bins: np.ndarray, period_samples: int) -> tuple[float, int]:
    """The time warp e (module doc) from per-period spectra of a periodic signal (periods x samples).

    The rows may hold every D-th sample of a period of ``period_samples``
    (bins below half their length). Weighted least squares of each line's
    phase against the period's centre, weights |line|^2 / its scatter.
    (0, 0) when fewer than 2 periods or no line stands out.
    """
    n = periods.shape[0]
    bins = bins[bins < periods.shape[1] // 2]
    if n < 2 or bins.size == 0:
        return 0.0, 0
    spectra = np.fft.rfft(periods, axis=1)[:, bins]
    mean = spectra.mean(axis=0)
    scatter = np.sum(np.abs(spectra - mean) ** 2, axis=0) / (n - 1)
    strong = np.abs(mean) ** 2 > 100.0 * np.maximum(scatter, 1e-300)
    if not np.any(strong):
        return 0.0, 0
    bins, spectra, mean = bins[strong], spectra[:, strong], mean[strong]
    weight = np.abs(mean) ** 2 / np.maximum(scatter[strong], np.abs(mean) ** 2 * 1e-24)
    theta = np.angle(spectra * np.conj(mean))                       # periods x lines
    tau = (np.arange(n) - (n - 1) / 2.0) * period_samples            # period centres about their mean
    c = 2.0 * np.pi * bins / period_samples
    num = np.sum(weight[None, :] * c[None, :] * tau[:, None] * theta)
    den = np.sum(weight[None, :] * (c[None, :] * tau[:, None]) ** 2)
    return float(num / den), int(bins.size)
