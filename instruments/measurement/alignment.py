"""The serial laser's displacement, aligned to the excitation and resampled onto the audio grid.

What is estimated from what (see clocks.py for the reasoning):

1. Laser sample numbers from its measurement counter (lost measurements are
   gaps in the counter); without a counter, measurements are numbered in
   arrival order.
2. The laser's time line and the audio's time line from the host arrival
   times of their blocks (lower envelopes): the ratio (audio samples per
   laser sample) and the offset (the audio index of laser sample 0), and so
   the laser's clock error in ppm and its start latency. An envelope whose
   rate is implausibly far from its stream's nominal rate (PLAUSIBLE_PPM) was
   tilted by the host's scheduling: that line runs at the nominal rate under
   the stream's most timely block instead (clocks.floor_line).
3. The ratio refined by the excitation: the resampled displacement must
   repeat exactly with the excitation period (``refine_ratio``).
4. The offset stays as the host times put it (less a known sensor latency):
   a periodic steady state cannot tell a delay from the driver's own phase.

Error codes and lost measurements are not distances: they are missing data
(laser_gaps.py). They are first bridged by straight lines between the valid
neighbours on the laser's grid, then, period after period, set to the mean
of the periods that measured that point of the excitation, so that what is
averaged and fitted rests on measured samples only; the sidecar says how
many were missing, in how many periods, and how much that widens the
displacement's noise (capture.laser_gaps). Out-of-range distances (the
sensor's reserves) are kept, and counted. Outliers are missing data too:
measured distances no smooth motion through their neighbours could give. The
line has no checksum, and now and then line noise forges a whole measurement
that the parser cannot tell from a real one (instruments/laser/ild1420/frames.py).
The cone's motion is smooth on the laser's grid (its content lies well below
the laser's Nyquist frequency), so a measurement further from the cubic
through its two neighbours on either side than OUTLIER_SIGMAS times the
typical distance is one.

The ratio's refinement sees the missing samples at the periodic mean of the
current clock: they carry no phase of their own, so they neither pull nor
push the drift it measures (a bridge across a flood did: it made the
refinement miss by hundreds of ppm).

Lines above PASSBAND x the laser rate (``max_hz``) carry nothing of the
displacement after resampling: they are not measured and must not enter Hx.
What the interpolator's stopband lets through up there (~-100 dB) is set to
zero, period by period, so it cannot pass for distortion.
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import Mapping, Sequence

import numpy as np

from instruments.laser.sensor import NO_COUNTER, LaserBlock
from instruments.measurement.clocks import (
    LaserClock, TimeLine, clock_from_host_times, floor_line, lower_envelope, period_phase_drift)
from instruments.measurement.laser_gaps import LaserGaps, gap_accounting, refill
from instruments.measurement.resample import HALF_TAPS, PASSBAND, covered, interpolate

REFINE_PASSES = 3
# A laser's crystal runs within tens of ppm of its rate; host times that say more than this are the host's
# scheduling (a loaded machine, a USB adapter's bursts: -9,300 ppm seen on a JACK plan), and the refinement,
# which follows a drift of less than a line's half turn per period, would not start from them.
PLAUSIBLE_PPM = 1000.0
REFILL_ROUNDS = 2       # EM rounds per pass of the refinement (laser_gaps.py): the second changes ~1e-3 of the first
OUTLIER_SIGMAS = 12.0
_CONVERGED = 1e-10      # a drift below this changes nothing measurable


@dataclass(frozen=True, slots=True, eq=False)
class LaserStream:
    """Every measurement received, numbered on the laser's own grid 0 .. n-1 (NaN: no distance)."""

    distance_m: np.ndarray        # float64, NaN where an error code or a lost measurement is
    error_code: np.ndarray        # int32, 0 for a distance, -1 for a lost measurement
    in_range: np.ndarray          # bool
    block_last: np.ndarray        # laser index of each block's last measurement
    block_host_time: np.ndarray   # when each block arrived (time.monotonic)

    @property
    def n_samples(self) -> int:
        return self.distance_m.size


def stream_of_blocks(blocks: Sequence[LaserBlock]) -> LaserStream:
    """The blocks as one stream on the laser's grid; ValueError when none holds a measurement."""
    blocks = [b for b in blocks if len(b)]
    if not blocks:
        raise ValueError("the laser delivered no measurement")
    counter = np.concatenate([b.counter for b in blocks])
    if np.any(counter == NO_COUNTER):
        counter = np.arange(counter.size)       # no counter: arrival order is all there is
    k = counter - counter[0]
    keep = np.concatenate([[True], np.diff(k) > 0])     # a counter that goes back is not trusted
    k = k[keep]
    n = int(k[-1]) + 1
    distance = np.full(n, np.nan)
    code = np.full(n, -1, dtype=np.int32)
    in_range = np.zeros(n, dtype=bool)
    distance[k] = np.concatenate([b.distance_m for b in blocks])[keep]
    code[k] = np.concatenate([b.error_code for b in blocks])[keep]
    in_range[k] = np.concatenate([b.in_range for b in blocks])[keep]
    ends = np.cumsum([len(b) for b in blocks]) - 1
    last = (counter - counter[0])[ends]
    return LaserStream(distance, code, in_range, last, np.array([b.host_time for b in blocks]))


@dataclass(frozen=True, slots=True)
class LaserCounts:
    """What the laser sent over the stretch that feeds the recording."""

    samples: int
    lost: int
    errors_by_code: Mapping[int, int] = field(default_factory=dict)
    out_of_range: int = 0
    outliers: int = 0
    gaps: LaserGaps | None = None

    def capture_json(self) -> dict:
        """The laser's part of the sidecar's "capture" object (analysis.validity.capture). Lost and forged
        measurements are missing data like the error codes (laser_gaps), not dropouts of the sound card."""
        out = {"laser_samples": self.samples, "laser_error_counts": {str(c): n for c, n in
                                                                     sorted(self.errors_by_code.items())},
               "laser_out_of_range_share": self.out_of_range / self.samples if self.samples else 0.0}
        if self.gaps is not None:
            out["laser_gaps"] = {**self.gaps.capture_json(), "lost": self.lost, "outliers": self.outliers}
        return out


@dataclass(frozen=True, slots=True, eq=False)
class AlignedDisplacement:
    displacement: np.ndarray      # m, positive outward, the covered periods back to back
    periods: int                  # whole periods covered, from the first
    clock: LaserClock             # refined
    host_clock: LaserClock        # from the host times alone
    laser_line: TimeLine
    audio_line: TimeLine
    counts: LaserCounts
    max_hz: float                 # highest frequency the resampled displacement carries
    drift_lines: int
    passes: int

    def as_json(self, audio_rate: float, nominal_rate: float) -> dict:
        """The sidecar's "laser_alignment": what was estimated, so a report can show it."""
        return {"laser_rate_hz": self.clock.laser_rate(audio_rate), "nominal_rate_hz": nominal_rate,
                "clock_ppm": self.clock.ppm(audio_rate, nominal_rate),
                "clock_ppm_from_host_times": self.host_clock.ppm(audio_rate, nominal_rate),
                "offset_audio_samples": self.clock.offset, "ratio": self.clock.ratio,
                "laser_arrival_jitter_s": self.laser_line.jitter_s,
                "audio_arrival_jitter_s": self.audio_line.jitter_s,
                "refinement_lines": self.drift_lines, "refinement_passes": self.passes,
                "displacement_max_hz": self.max_hz}


def align_laser(stream: LaserStream, audio_stops: np.ndarray, audio_host_times: np.ndarray,
                period_starts: Sequence[int], period_samples: int, audio_rate: float, nominal_rate: float,
                excited_bins: np.ndarray, *, sign: float = -1.0, latency_s: float = 0.0,
                refine: bool = True, quick: bool = False) -> AlignedDisplacement:
    """The displacement at the audio samples of the given periods (contiguous, in order).

    ``sign``: -1 when the laser looks at the front of the cone (outward motion
    shortens the distance). Periods at the end that the laser's stream does not
    cover are left out (``periods`` says how many are in); ValueError if none is.
    ``quick`` (the live view): interpolated on every D-th audio sample only and
    brought to the full rate period by period through the FFT, D times less
    work, the same lines; the recording gets the full interpolation.
    """
    laser_line = lower_envelope(stream.block_last, stream.block_host_time)
    audio_line = lower_envelope(audio_stops, audio_host_times)
    host_clock = clock_from_host_times(laser_line, audio_line, latency_s)
    # A starved host's arrivals, later and later, tilt an envelope (a 4 V step measured 0.25 s off: a period
    # read after the drive stopped, its peak halved): such a line is replaced (_timely).
    placed = clock_from_host_times(_timely(laser_line, stream.block_last, stream.block_host_time, nominal_rate),
                                   _timely(audio_line, audio_stops, audio_host_times, audio_rate), latency_s)
    starts = np.asarray(period_starts, dtype=np.int64)
    n_periods = _covered_periods(placed, starts, period_samples, stream.n_samples)
    if n_periods == 0:
        raise ValueError("the laser's stream does not cover any of the captured periods")
    starts = starts[:n_periods]
    grid = (starts[:, None] + np.arange(period_samples)[None, :]).ravel()
    used = _used_laser_range(placed, grid, stream.n_samples)
    outliers = outlier_mask(stream.distance_m)
    missing = ~np.isfinite(stream.distance_m) | outliers
    filled = _bridged(np.where(outliers, np.nan, stream.distance_m))
    pivot = float(np.mean(stream.block_last))      # where the host times place the stream best
    start_clock = placed
    if refine and abs(placed.ppm(audio_rate, nominal_rate)) > PLAUSIBLE_PPM:
        start_clock = placed.pivoted(audio_rate / nominal_rate, pivot)     # the nominal rate: far closer
    laser_rate = audio_rate / start_clock.ratio
    max_hz = PASSBAND * min(laser_rate, nominal_rate)
    max_bin = int(np.floor(max_hz * period_samples / audio_rate))
    bins = np.asarray(excited_bins, dtype=np.int64)
    bins = bins[bins <= max_bin]
    clock, drift, lines, passes = start_clock, 0.0, 0, 0
    # The drift is measured on every D-th audio sample: still above twice max_hz, D times less work.
    step = _decimation(audio_rate, max_hz, period_samples)
    coarse = (starts[:, None] + np.arange(0, period_samples, step)[None, :]).ravel()
    # Only the missing samples the interpolation of the periods reaches are filled from the periods.
    near = np.zeros(missing.size, dtype=bool)
    near[max(used.start - HALF_TAPS, 0):used.stop + HALF_TAPS] = True
    gaps = missing & near if n_periods >= 2 else np.zeros_like(missing)

    def coarse_periods(stream_values: np.ndarray) -> np.ndarray:
        return interpolate(stream_values, clock.laser_index(coarse)).reshape(n_periods, -1)

    def refilled(stream_values: np.ndarray) -> np.ndarray:
        for _ in range(REFILL_ROUNDS if np.any(gaps) else 0):
            stream_values = refill(stream_values, gaps, coarse_periods(stream_values),
                                   clock.laser_index(coarse).reshape(n_periods, -1), clock, int(starts[0]),
                                   period_samples, max_bin)
        return stream_values

    while refine and passes < REFINE_PASSES and n_periods >= 2:
        filled = refilled(filled)
        drift, lines = period_phase_drift(coarse_periods(filled), bins, period_samples)
        if lines == 0:
            break
        passes += 1
        moved = clock.pivoted(clock.ratio * (1.0 + drift), pivot)
        if not np.all(covered(moved.laser_index(grid[[0, -1]]), filled.size)):
            break                     # a drift that large is not to be trusted: keep the last clock
        clock = moved
        if abs(drift) < _CONVERGED:
            break
    filled = refilled(filled)
    gap_cost = gap_accounting(missing, used, clock.laser_index(coarse).reshape(n_periods, -1), n_periods, step,
                              audio_rate)
    counts = _counts(stream, used, int(np.count_nonzero(outliers[used])), gap_cost)
    if quick:
        coarse_x = interpolate(filled, clock.laser_index(coarse)).reshape(n_periods, -1)
        spectra = np.fft.rfft(coarse_x, axis=1) * step          # the same lines at the full rate
        x = np.fft.irfft(spectra, period_samples, axis=1).ravel()
    else:
        x = interpolate(filled, clock.laser_index(grid))
    x = _band_limited(sign * (x - np.mean(x)), n_periods, period_samples, max_hz / audio_rate)
    return AlignedDisplacement(x, n_periods, clock, host_clock, laser_line, audio_line, counts, float(max_hz),
                               lines, passes)


def _timely(line: TimeLine, index: np.ndarray, host_time: np.ndarray, rate: float) -> TimeLine:
    """The envelope, or, when its rate is implausibly far from the stream's nominal ``rate`` (the host's
    scheduling tilted it, and its line at the centre is as late as the arrivals there), the line at the
    nominal rate under the stream's most timely block (clocks.floor_line)."""
    if abs(line.slope * rate - 1.0) * 1e6 <= PLAUSIBLE_PPM:
        return line
    return floor_line(index, host_time, 1.0 / rate)


def _decimation(audio_rate: float, max_hz: float, period: int) -> int:
    """The largest power of two D dividing the period with audio_rate / D >= 2.5 max_hz."""
    step = 1
    while period % (2 * step) == 0 and audio_rate / (2 * step) >= 2.5 * max_hz:
        step *= 2
    return step


def _band_limited(x: np.ndarray, n_periods: int, period: int, max_cycles_per_sample: float) -> np.ndarray:
    """Every bin above the laser's band set to zero, period by period: what leaks through the
    interpolator's stopband is not the displacement, and would read as distortion there."""
    spectra = np.fft.rfft(x.reshape(n_periods, period), axis=1)
    spectra[:, int(np.floor(max_cycles_per_sample * period)) + 1:] = 0.0
    return np.fft.irfft(spectra, period, axis=1).ravel()


def _covered_periods(clock: LaserClock, starts: np.ndarray, period: int, n_samples: int) -> int:
    margin = 1e-6 * period * len(starts) + 2.0      # room for the refinement to move the ends
    n = 0
    for start in starts:
        ends = clock.laser_index(np.array([start - margin, start + period - 1 + margin]))
        if not np.all(covered(ends, n_samples)):
            break
        n += 1
    return n


def _used_laser_range(clock: LaserClock, grid: np.ndarray, n_samples: int) -> slice:
    k = clock.laser_index(np.array([grid[0], grid[-1]]))
    return slice(max(int(np.floor(k[0])), 0), min(int(np.ceil(k[1])) + 1, n_samples))


def _counts(stream: LaserStream, used: slice, outliers: int, gaps: LaserGaps | None) -> LaserCounts:
    code = stream.error_code[used]
    errors = Counter(int(c) for c in code[code > 0])
    out_of_range = int(np.count_nonzero((code == 0) & ~stream.in_range[used]))
    return LaserCounts(int(code.size), int(np.count_nonzero(code < 0)), dict(errors), out_of_range, outliers,
                       gaps)


def outlier_mask(distance: np.ndarray, passes: int = 3) -> np.ndarray:
    """Measurements too far from the cubic through their neighbours (module doc); NaNs are not outliers.

    Only the worst of any five neighbours is taken per pass (a spike also
    pulls its neighbours' predictions), then the check runs again without it.
    The typical distance is 1.4826 x the median absolute residual, at least
    the sensor's quantum (the smallest step in the data).
    """
    distance = np.asarray(distance, dtype=np.float64)
    outliers = np.zeros(distance.size, dtype=bool)
    if np.count_nonzero(np.isfinite(distance)) < 16:
        return outliers
    steps = np.abs(np.diff(distance[np.isfinite(distance)]))
    quantum = float(np.min(steps[steps > 0])) if np.any(steps > 0) else 0.0
    for _ in range(passes):
        x = _bridged(np.where(outliers, np.nan, distance))
        r = np.zeros(x.size)
        r[2:-2] = x[2:-2] - (-x[:-4] + 4 * x[1:-3] + 4 * x[3:-1] - x[4:]) / 6.0
        # A missing neighbour in the stencil is a bridge, not the motion: such a sample cannot be judged.
        r[np.convolve(~np.isfinite(distance) | outliers, np.ones(5), mode="same") > 0] = 0.0
        sigma = max(1.4826 * float(np.median(np.abs(r[2:-2]))), quantum)
        big = np.abs(r) > OUTLIER_SIGMAS * sigma
        if not np.any(big):
            break
        local = np.abs(r) >= np.max(np.lib.stride_tricks.sliding_window_view(np.pad(np.abs(r), 2), 5), axis=1)
        new = big & local
        if not np.any(new):
            break
        outliers |= new
    return outliers


def _bridged(distance: np.ndarray) -> np.ndarray:
    """NaNs replaced by straight lines between their valid neighbours (ends: the nearest valid value)."""
    valid = np.isfinite(distance)
    if not np.any(valid):
        raise ValueError("the laser sent no valid distance")
    if np.all(valid):
        return distance
    k = np.arange(distance.size)
    return np.interp(k, k[valid], distance[valid])
