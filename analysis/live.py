"""Live processing, one period at a time, for the measurement panels.

The measurement thread hands each analysed period of the three channels to a
LiveAccumulator; it returns a frozen LiveFrame that crosses to the GUI as is.
Per bin of the analysed band (first to last excited line), per channel, the
running mean and variance follow Welford's update (one pass, stable for any
number of periods):

    n += 1,   d = X - mean,   mean += d / n,   M2 += Re(conj(d) * (X - mean))
    var_mean = M2 / (n (n - 1))          (the variance of the mean, as analysis.spectra)

Spectra are one-sided peak amplitudes (analysis.spectra.period_spectra), so
after the last period `mean` and `var_mean` equal estimate_spectra's on the
same periods. A frame shows, in dB re 1 V, 1 A or 1 m (10 log10 of the power,
DB_FLOOR for zero): the signal lines (|mean| at the excited bins), and, in
DISPLAY_BUCKETS log-spaced buckets of the band (analysis.log_buckets, the power
mean of each bucket's bins), the noise floor (var_mean at every bin) and the
noise + distortion lines (|mean| at the unexcited bins): arrays ready to draw,
worked out here in the measurement thread rather than in the GUI's. Its traffic
lights are the validity rules that apply to one frame
(analysis.validity.spectral: no signal, SNR, distortion, displacement band);
drift and the capture's counts are judged on the whole recording. Before the
second period there is no noise estimate: noise is NaN and the lights are
"unknown".

Feed only analysed periods (after settling); `reset()` starts over.
"""
from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType
from typing import Mapping, Sequence

import numpy as np

from analysis.band_fft import BandFFT
from analysis.excursion import peak_of_period
from analysis.log_buckets import LogBuckets
from analysis.recording.format import UNITS
from analysis.spectra import ChannelSpectrum
from analysis.thresholds import DEFAULT_THRESHOLDS, ValidityThresholds
from analysis.validity.findings import Finding, worst
from analysis.validity.line_spectra import LineSpectra
from analysis.validity.spectral import SIGNALS, line_checks
from analysis.validity.unexcited import distortion_bands

UNKNOWN = "unknown"
DB_FLOOR = -400.0
DISPLAY_BUCKETS = 300           # a few hundred columns: what a panel ~1000 pixels wide can show


@dataclass(frozen=True, slots=True, eq=False)
class LiveChannel:
    signal: str
    unit: str
    line_db: np.ndarray             # |mean| at the excited lines, dB re 1 unit
    other_db: np.ndarray            # noise + distortion: |mean| at the unexcited lines, dB, per bucket (other_freqs)
    noise_db: np.ndarray            # noise floor at every bin, dB, per bucket (noise_freqs; NaN before 2 periods)
    status: str                     # "green" | "yellow" | "red" | "unknown"
    findings: tuple[Finding, ...]
    measures: Mapping[str, float]


@dataclass(frozen=True, slots=True, eq=False)
class LiveFrame:
    n_periods: int
    line_freqs: np.ndarray          # Hz, the excited lines (shared by the channels); the band is first to last
    other_freqs: np.ndarray         # Hz, the centres of the buckets of the band's unexcited lines
    noise_freqs: np.ndarray         # Hz, the centres of the buckets of the band's bins
    channels: Mapping[str, LiveChannel]
    status: str                     # the worst channel's
    peak_displacement_m: float | None


class LiveAccumulator:
    """Running per-bin mean and variance of the periods fed so far (see the module doc)."""

    def __init__(self, sample_rate: float, period_samples: int, excited_bins: Sequence[int],
                 signals: Sequence[str] = SIGNALS, thresholds: ValidityThresholds = DEFAULT_THRESHOLDS,
                 display_buckets: int = DISPLAY_BUCKETS):
        excited = np.unique(np.asarray(excited_bins, dtype=np.int64))
        if excited.size == 0 or excited[0] < 1 or excited[-1] > period_samples // 2 - 1:
            raise ValueError(f"excited_bins must be non-empty and within 1 .. {period_samples // 2 - 1}")
        unknown = [s for s in signals if s not in SIGNALS]
        if unknown or "voltage" not in signals:
            raise ValueError(f"signals must include 'voltage' and be among {SIGNALS}, got {tuple(signals)}")
        self.sample_rate = float(sample_rate)
        self.period_samples = int(period_samples)
        self.signals = tuple(signals)
        self.thresholds = thresholds
        self._lo, self._hi = int(excited[0]), int(excited[-1]) + 1       # analysed band: bins lo .. hi-1
        span = np.arange(self._lo, self._hi)
        self._excited = excited - self._lo
        self._unexcited = np.setdiff1d(span, excited, assume_unique=True) - self._lo
        bin_width = self.sample_rate / self.period_samples
        self._line_freqs = _frozen(excited * bin_width)
        other_freqs = (self._unexcited + self._lo) * bin_width
        self._other_freqs = _frozen(other_freqs)
        self._bands = distortion_bands(other_freqs, thresholds.distortion_band_octaves,
                                       thresholds.distortion_min_bins)
        self._other_buckets = LogBuckets(other_freqs, display_buckets) if other_freqs.size else None
        self._noise_buckets = LogBuckets(span * bin_width, display_buckets)
        self._x_row = self.signals.index("displacement") if "displacement" in self.signals else None
        self._mean = np.zeros((len(self.signals), span.size), dtype=np.complex128)
        self._m2 = np.zeros((len(self.signals), span.size))
        # Kept for Welford's update and the variance of the mean: no band-sized temporaries per period.
        self._step = np.empty((2, len(self.signals), span.size))
        self._var = np.empty((len(self.signals), span.size))
        # Peak amplitudes (2/N; the band holds no DC or Nyquist bin), scaled as the band is copied out.
        self._fft = BandFFT(len(self.signals), self.period_samples, self._lo, self._hi, 2.0 / self.period_samples)
        self._x_sum = np.zeros(self.period_samples)      # the displacement's periods summed, for its peak
        self._x_total = 0.0                               # and the sum of that sum's samples
        self._n = 0

    @property
    def n_periods(self) -> int:
        return self._n

    def reset(self) -> None:
        self._mean[:] = 0
        self._m2[:] = 0
        self._x_sum[:] = 0
        self._x_total = 0.0
        self._n = 0

    def channel_spectra(self) -> dict[str, ChannelSpectrum]:
        """The band's running mean and variance of the mean per channel (element 0 is the first excited bin)."""
        var = self._var_mean()
        return {name: ChannelSpectrum(name, UNITS[name], self._mean[row].copy(), var[row].copy())
                for row, name in enumerate(self.signals)}

    def add_period(self, period: Mapping[str, np.ndarray] | np.ndarray) -> LiveFrame:
        """One period of every signal (a mapping by name, or rows in `signals` order) -> the new frame."""
        rows = self._rows(period)
        n = self._n + 1
        if self._x_row is not None:
            self._x_sum += rows[self._x_row]
        delta = self._fft.transform(rows)               # X, peak amplitudes
        if self._x_row is not None:
            self._x_total += float(self._fft.row_sums()[self._x_row])
        self._n = n
        # In place, no temporaries of the band's size: X - mean_new = d (1 - 1/n), so M2 += |d|^2 (n-1)/n.
        delta -= self._mean
        power, imag_power = np.square(delta.real, out=self._step[0]), np.square(delta.imag, out=self._step[1])
        power += imag_power
        power *= (n - 1) / n
        self._m2 += power
        delta *= 1.0 / n
        self._mean += delta
        return self._frame()

    # --- internals ----------------------------------------------------------------------------

    def _rows(self, period) -> list[np.ndarray] | np.ndarray:
        """The period's rows in `signals` order, as float64, checked (not copied: BandFFT copies them into
        its kept buffers, where a fresh 1.5 MB array per period would cost its pages' faults each time)."""
        if isinstance(period, Mapping):
            missing = [s for s in self.signals if s not in period]
            if missing:
                raise ValueError(f"the period lacks {', '.join(missing)}")
            rows = [np.asarray(period[s], dtype=np.float64) for s in self.signals]
            shape = (len(rows), *rows[0].shape) if len({row.shape for row in rows}) == 1 else "ragged"
        else:
            rows = np.asarray(period, dtype=np.float64)
            shape = rows.shape
        if shape != (len(self.signals), self.period_samples):
            raise ValueError(f"expected {len(self.signals)} signals of {self.period_samples} samples, "
                             f"got shape {shape}")
        return rows

    def _var_mean(self) -> np.ndarray:
        """The variance of the mean, in the kept buffer (the next period overwrites it)."""
        if self._n < 2:
            self._var.fill(np.nan)
            return self._var
        return np.divide(self._m2, self._n * (self._n - 1), out=self._var)

    def _frame(self) -> LiveFrame:
        var = self._var_mean()
        # The excited and unexcited lines gathered once, for the panels' arrays and every check.
        lines = LineSpectra.of_band(self.signals, self._mean, var, self._excited, self._unexcited)
        line_db = _db_of_power(np.square(lines.lines.real) + np.square(lines.lines.imag))
        if self._other_buckets is not None:
            other_db = self._other_buckets.power_mean_db(lines.other_power)
        else:
            other_db = np.zeros((len(self.signals), 0))
        if self._n >= 2:
            noise_db = self._noise_buckets.power_mean_db(var)
        else:
            noise_db = np.full((len(self.signals), self._noise_buckets.starts.size), np.nan)
        checks = {}
        if self._n >= 2:
            checks = line_checks(lines, self._line_freqs, self._other_freqs, self.thresholds, self._bands)
        channels = {}
        for row, name in enumerate(self.signals):
            findings, measures = checks.get(name, ([], {}))
            status = str(worst(f.severity for f in findings)) if name in checks else UNKNOWN
            channels[name] = LiveChannel(name, UNITS[name], _frozen(line_db[row]), _frozen(other_db[row]),
                                         _frozen(noise_db[row]), status, tuple(findings),
                                         MappingProxyType(dict(measures)))
        statuses = [ch.status for ch in channels.values()]
        overall = UNKNOWN if UNKNOWN in statuses else str(worst(f.severity for ch in channels.values()
                                                                 for f in ch.findings))
        # The peak of the coherent mean period: of the sum, divided by the count (one pass a period, not three),
        # about the sum's mean from the FFT's DC bins.
        peak = None
        if self._x_row is not None:
            peak = peak_of_period(self._x_sum, self._x_total / self.period_samples) / self._n
        other_freqs = self._other_buckets.freqs if self._other_buckets is not None else _frozen(np.zeros(0))
        return LiveFrame(self._n, self._line_freqs, other_freqs, self._noise_buckets.freqs,
                         MappingProxyType(channels), overall, peak)


def _db_of_power(power: np.ndarray) -> np.ndarray:
    """20 log10(amplitude) = 10 log10(amplitude^2), no square root; DB_FLOOR for zero."""
    with np.errstate(divide="ignore"):
        db = np.log10(power)
    db *= 10.0
    return np.maximum(db, DB_FLOOR, out=db)


def _frozen(array: np.ndarray) -> np.ndarray:
    array = np.ascontiguousarray(array)
    array.flags.writeable = False
    return array
