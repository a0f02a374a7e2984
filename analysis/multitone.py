"""Periodic multitone excitation: which lines, what amplitudes, which phases.

One period of ``period_samples`` samples at ``sample_rate`` holds lines on the
FFT bins of that period only, so a steady-state measurement averaged over whole
periods has no leakage. The design has three parts:

Which bins (the detection grid)
    Only bins ``k`` with ``k % 6 in (1, 5)`` are ever excited: odd bins that are
    not multiples of 3. Consequences, each of which the spectrum analysis relies
    on:

    * no two excited bins are adjacent (neighbours are 2 or 4 bins apart), so
      there are unexcited bins between every pair of neighbouring lines, even
      at the lowest frequencies where every allowed bin is used;
    * every even-order product of excited lines (``k1 +- k2``, the 2nd
      harmonics, ...) lands on an even bin, never excited;
    * the 3rd harmonic ``3k`` of every line lands on an odd multiple of 3,
      never excited; of the other 3rd-order products ``k1 +- k2 +- k3`` the
      ones that land on ``3 (mod 6)`` are seen, the rest hide under excited
      lines (a deterministic pattern, unlike the random one of Schoukens'
      "random odd multisine", so the same bins are free at every level).

    One bin in three is thus excitable; the price is a coarser grid at the low
    end (3 bins per line on average).

Where on that grid (log spacing)
    Target frequencies are geometric from ``f_min`` to ``f_max``; each goes to
    the nearest allowed bin and duplicates are dropped. Where the log spacing
    is finer than the allowed grid (low frequencies) this takes every allowed
    bin; above, it gives ``lines_per_octave`` lines per octave.

Which phases (crest factor)
    Start from Schroeder's phases, generalised to an uneven grid (a sweep that
    spends on each line a time proportional to its power). Then lower the
    crest factor by minimising the L^p norm of the waveform for
    p = 4, 8, ... 128 by L-BFGS (Guillaume et al., 1991), keeping the best
    waveform seen. Only phases change, so the spectrum is exact by
    construction: the requested amplitudes at the excited bins and zero
    elsewhere, to float precision.

    NB: the clipping algorithm of Van der Ouderaa et al. (clip in time, keep
    the phases of the FFT) was tried first. On log-spaced lines it stalls:
    50 iterations take 5 Hz - 10 kHz / 113 lines from 3.8 only to 3.5, where
    the L^p descent reaches 2.4 for the same number of FFTs. Log-spaced lines
    are the hard case for crest factors (the dense-grid figure of ~1.5 is out
    of reach); expect 2.0 - 2.45, lower with more lines.

    The peak minimised is that of the waveform evaluated at >= 6 points per
    cycle of the top line (a grid other than the period's when that is
    coarser or needlessly fine): left to the period's own samples, the
    descent hides peaks between them (20 Hz - 20 kHz at 48 kHz: crest 2.21
    on the samples, 2.56 once reconstructed). The analogue peak is now
    within ~2 % of the sampled one.

Conventions: line ``i`` is ``amplitudes[i] * cos(2*pi*excited_bins[i]*n /
period_samples + phases[i])``, so ``rfft(waveform)[k] = period_samples / 2 *
amplitude * exp(1j * phase)``. ``peak`` and ``crest_factor`` are those of the
samples.
"""

from __future__ import annotations

import functools
import math
import operator
from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.fft

from analysis.crest_factor import reduce_crest_factor

MIN_PERIOD_SAMPLES = 16
# The excitable bins are k with k % 6 in _EXCITABLE_RESIDUES (see module doc).
_GRID_MODULUS = 6
_EXCITABLE_RESIDUES = (1, 5)
# Phase dither (rad, standard deviation) added to Schroeder's phases: it is the
# only use of `seed`; different seeds give different waveforms with about the
# same crest factor (independent realisations for a level series).
_SEED_DITHER_RAD = 0.1
_DEFAULT_RMS = 1.0


@dataclass(frozen=True, slots=True, eq=False)
class Multitone:
    """One period of a multitone and the spectrum it was built from.

    Immutable: arrays are copied and made read-only, so an instance can be
    handed to another thread. Compared by identity (arrays have no truth value).
    """

    sample_rate: int
    period_samples: int
    excited_bins: np.ndarray
    amplitudes: np.ndarray
    phases: np.ndarray
    waveform: np.ndarray

    def __post_init__(self) -> None:
        _frozen_array(self, "excited_bins", np.int64)
        for name in ("amplitudes", "phases", "waveform"):
            _frozen_array(self, name, np.float64)
        bins = self.excited_bins
        if bins.ndim != 1 or bins.size == 0:
            raise ValueError("excited_bins must be a non-empty 1-D array")
        if self.amplitudes.shape != bins.shape or self.phases.shape != bins.shape:
            raise ValueError("amplitudes and phases must have one value per excited bin")
        if self.waveform.shape != (self.period_samples,):
            raise ValueError(f"waveform must hold one period of {self.period_samples} samples")
        if np.any(np.diff(bins) <= 0):
            raise ValueError("excited_bins must be sorted and unique")
        if bins[0] < 1 or bins[-1] > self.period_samples // 2 - 1:
            raise ValueError("excited_bins must lie in 1 .. period_samples//2 - 1")

    @property
    def frequencies(self) -> np.ndarray:
        """Frequency of each excited line, Hz."""
        return self.excited_bins * self.sample_rate / self.period_samples

    @property
    def rms(self) -> float:
        """RMS of the waveform, V."""
        return float(np.sqrt(np.mean(self.waveform**2)))

    @property
    def peak(self) -> float:
        """Largest absolute sample of the waveform, V."""
        return float(np.max(np.abs(self.waveform)))

    @property
    def crest_factor(self) -> float:
        """Peak over RMS of the samples (sqrt(2) for a single sine)."""
        return self.peak / self.rms

    def scaled(self, *, rms: float | None = None, peak: float | None = None) -> Multitone:
        """The same multitone scaled to the given RMS or peak voltage (exactly one)."""
        target = _level_target(rms, peak)
        if target is None:
            raise ValueError("scaled() needs rms or peak")
        factor = target[1] / (self.rms if target[0] == "rms" else self.peak)
        return Multitone(self.sample_rate, self.period_samples, self.excited_bins,
                         self.amplitudes * factor, self.phases, self.waveform * factor)

    def tile(self, n_periods: int) -> np.ndarray:
        """``n_periods`` periods back to back, as a new writable array."""
        n = operator.index(n_periods)
        if n < 1:
            raise ValueError(f"n_periods must be at least 1, got {n}")
        return np.tile(self.waveform, n)


def design_multitone(
    sample_rate: int,
    period_samples: int,
    f_min: float,
    f_max: float,
    *,
    lines_per_octave: float = 12.0,
    n_lines: int | None = None,
    rms: float | None = None,
    peak: float | None = None,
    amplitude_shape: Callable[[np.ndarray], np.ndarray] | None = None,
    seed: int = 0,
    crest_iterations: int = 50,
) -> Multitone:
    """Design a low-crest-factor periodic multitone (see the module docstring).

    Args:
        sample_rate: samples per second.
        period_samples: length of one period (at least 16); the bin spacing is
            ``sample_rate / period_samples``.
        f_min, f_max: band, Hz; every excited line lies inside it. ``f_max``
            must be below Nyquist.
        lines_per_octave: density of the log spacing above the region where
            every allowed bin is taken.
        n_lines: exact number of lines instead; takes precedence over
            ``lines_per_octave`` (the density is then chosen to match).
        rms, peak: level of the result, V (at most one). Neither: 1 V RMS.
        amplitude_shape: relative peak amplitude of each line as a function of
            its frequency (Hz array in, positive array out); flat by default.
        seed: picks the small phase dither on Schroeder's start; the same seed
            gives the same waveform.
        crest_iterations: L-BFGS iterations of crest-factor reduction, spread
            over the L^p continuation; 0 keeps the (dithered) Schroeder phases.
    """
    sample_rate = operator.index(sample_rate)
    period_samples = operator.index(period_samples)
    level = _level_target(rms, peak) or ("rms", _DEFAULT_RMS)
    _check_design_inputs(sample_rate, period_samples, f_min, f_max, lines_per_octave, crest_iterations)

    if amplitude_shape is None:
        bins, shape, phases = _flat_design(sample_rate, period_samples, float(f_min), float(f_max),
                                           float(lines_per_octave), n_lines, seed, crest_iterations)
    else:
        bins, shape, phases = _design(sample_rate, period_samples, f_min, f_max, lines_per_octave, n_lines,
                                      amplitude_shape, seed, crest_iterations)
    unit = synthesize(period_samples, bins, shape, phases)
    measure = np.sqrt(np.mean(unit**2)) if level[0] == "rms" else np.max(np.abs(unit))
    amplitudes = shape * (level[1] / measure)
    return Multitone(sample_rate, period_samples, bins, amplitudes, phases,
                     synthesize(period_samples, bins, amplitudes, phases))


@functools.lru_cache(maxsize=16)
def _flat_design(sample_rate: int, period_samples: int, f_min: float, f_max: float, lines_per_octave: float,
                 n_lines: int | None, seed: int, crest_iterations: int) -> tuple[np.ndarray, ...]:
    """_design with flat lines, remembered: a measurement designs the same excitation as the level check
    before it, and the crest-factor descent is 0.5 s or more of work that holds the GIL in short slices,
    which the GUI thread feels as stalls. Read-only arrays, so the cached design cannot be altered."""
    design = _design(sample_rate, period_samples, f_min, f_max, lines_per_octave, n_lines, None, seed,
                     crest_iterations)
    for array in design:
        array.flags.writeable = False
    return design


def _design(sample_rate, period_samples, f_min, f_max, lines_per_octave, n_lines, amplitude_shape, seed,
            crest_iterations) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(excited bins, relative line amplitudes, phases) of design_multitone, before its level is set."""
    allowed = excitable_bins(sample_rate, period_samples, f_min, f_max)
    if allowed.size == 0:
        raise ValueError(
            f"no excitable bin between f_min={f_min} Hz and f_max={f_max} Hz (bin spacing "
            f"{sample_rate / period_samples:.4g} Hz, only odd non-multiple-of-3 bins): "
            "widen the band or lengthen the period")
    to_bins = period_samples / sample_rate
    if n_lines is None:
        n_targets = max(2, round(math.log2(f_max / f_min) * lines_per_octave) + 1)
        bins = _nearest_allowed(allowed, np.geomspace(f_min, f_max, n_targets) * to_bins)
    else:
        bins = _bins_for_count(allowed, f_min * to_bins, f_max * to_bins, n_lines)

    shape = _line_shape(amplitude_shape, bins * sample_rate / period_samples)
    rng = np.random.default_rng(seed)
    start = schroeder_phases(bins, shape) + rng.normal(0.0, _SEED_DITHER_RAD, bins.size)
    phases = reduce_crest_factor(bins, shape, start, crest_iterations)
    phases = np.mod(phases, 2 * np.pi)
    return bins, shape, phases


def unexcited_bins(mt: Multitone, f_min: float | None = None, f_max: float | None = None) -> np.ndarray:
    """Bins that carry only noise and distortion, sorted.

    By default the bins from the first to the last excited bin that are not
    excited. ``f_min`` / ``f_max`` (Hz) replace either end, e.g. to include the
    harmonics above the top line. DC and Nyquist are never included.
    """
    to_bins = mt.period_samples / mt.sample_rate
    lo = mt.excited_bins[0] if f_min is None else max(1, math.ceil(f_min * to_bins))
    hi = mt.excited_bins[-1] if f_max is None else min(mt.period_samples // 2 - 1,
                                                        math.floor(f_max * to_bins))
    candidates = np.arange(lo, hi + 1, dtype=np.int64)
    return candidates[~np.isin(candidates, mt.excited_bins)]


def excitable_bins(sample_rate: int, period_samples: int, f_min: float, f_max: float) -> np.ndarray:
    """Every bin that the detection grid allows in [f_min, f_max], sorted."""
    k = np.arange(1, period_samples // 2, dtype=np.int64)
    # Same float expression as Multitone.frequencies, so the band test agrees with it.
    freqs = k * sample_rate / period_samples
    on_grid = np.isin(k % _GRID_MODULUS, _EXCITABLE_RESIDUES)
    return k[on_grid & (freqs >= f_min) & (freqs <= f_max)]


def schroeder_phases(bins: np.ndarray, amplitudes: np.ndarray) -> np.ndarray:
    """Schroeder's low-crest phases, generalised to lines on any bin grid.

    The waveform is read as a sweep whose group delay at line i is the power
    fraction of the lines below it; integrating the group delay over frequency
    gives the phase. The sweep must fill the interval after which |x| repeats,
    not always the whole period: bins that are all multiples of d repeat after
    1/d period, and odd multiples of d change sign after half of that. On bins
    1..K this is Schroeder's -pi*i**2/K; on the odd grid the sweep fills half
    a period (a whole-period sweep would overlap itself: crest 4.2 instead of
    3.8 for 5 Hz - 10 kHz before the descent).
    """
    k = np.asarray(bins, dtype=np.int64)
    power = np.asarray(amplitudes, dtype=np.float64) ** 2
    step = int(np.gcd.reduce(k))
    repeat = 0.5 / step if np.all((k // step) % 2 == 1) else 1.0 / step  # of a period
    cumulative = np.cumsum(power) / power.sum()
    return -2 * np.pi * repeat * np.concatenate(([0.0], np.cumsum(np.diff(k) * cumulative[:-1])))


def synthesize(period_samples: int, bins: np.ndarray, amplitudes: np.ndarray,
               phases: np.ndarray) -> np.ndarray:
    """One period of sum(amplitudes * cos(2*pi*bins*n/period_samples + phases))."""
    spectrum = np.zeros(period_samples // 2 + 1, dtype=np.complex128)
    spectrum[bins] = amplitudes * (period_samples / 2) * np.exp(1j * np.asarray(phases))
    return scipy.fft.irfft(spectrum, period_samples)


def _nearest_allowed(allowed: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """The allowed bins nearest to the target bins (fractional), without repeats."""
    above = np.clip(np.searchsorted(allowed, targets), 0, allowed.size - 1)
    below = np.clip(above - 1, 0, allowed.size - 1)
    take_below = np.abs(allowed[below] - targets) <= np.abs(allowed[above] - targets)
    return np.unique(allowed[np.where(take_below, below, above)])


def _bins_for_count(allowed: np.ndarray, k_min: float, k_max: float, n_lines: int) -> np.ndarray:
    """Log-spaced bins, exactly ``n_lines`` of them when the grid allows.

    Merging of targets in the dense region makes the count smaller than the
    number of targets, so search the number of targets; each added target adds
    at most one line in practice, so the search lands on ``n_lines``.
    """
    n_lines = operator.index(n_lines)
    if n_lines < 1:
        raise ValueError(f"n_lines must be at least 1, got {n_lines}")
    if n_lines > allowed.size:
        raise ValueError(f"n_lines={n_lines} is more than the {allowed.size} excitable bins in the band")
    if n_lines == allowed.size:
        return allowed.copy()

    def lines(n_targets: int) -> np.ndarray:
        return _nearest_allowed(allowed, np.geomspace(k_min, k_max, n_targets))

    low, high = n_lines, n_lines  # lines(low) has fewer than n_lines unless equal
    while lines(high).size < n_lines:
        low, high = high, 2 * high
    while high - low > 1:
        middle = (low + high) // 2
        if lines(middle).size < n_lines:
            low = middle
        else:
            high = middle
    at_low = lines(low)
    return at_low if at_low.size == n_lines else lines(high)


def _line_shape(amplitude_shape: Callable[[np.ndarray], np.ndarray] | None,
                freqs: np.ndarray) -> np.ndarray:
    """Relative line amplitudes, checked: one finite positive value per line."""
    if amplitude_shape is None:
        return np.ones(freqs.size)
    shape = np.asarray(amplitude_shape(freqs.copy()), dtype=np.float64)
    if shape.shape != freqs.shape:
        raise ValueError(f"amplitude_shape returned shape {shape.shape}, expected {freqs.shape}")
    if not np.all(np.isfinite(shape)) or np.any(shape <= 0):
        raise ValueError("amplitude_shape must return finite, positive amplitudes")
    return shape


def _level_target(rms: float | None, peak: float | None) -> tuple[str, float] | None:
    """("rms" | "peak", value) from the two optional level arguments, checked."""
    if rms is not None and peak is not None:
        raise ValueError("give rms or peak, not both")
    name, value = ("rms", rms) if rms is not None else ("peak", peak)
    if value is None:
        return None
    if not math.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be a positive number of volts, got {value}")
    return name, float(value)


def _check_design_inputs(sample_rate: int, period_samples: int, f_min: float, f_max: float,
                         lines_per_octave: float, crest_iterations: int) -> None:
    """Raise ValueError naming the first problem with the design inputs."""
    if sample_rate <= 0:
        raise ValueError(f"sample_rate must be positive, got {sample_rate}")
    if period_samples < MIN_PERIOD_SAMPLES:
        raise ValueError(f"period_samples must be at least {MIN_PERIOD_SAMPLES}, got {period_samples}")
    if not (math.isfinite(f_min) and f_min > 0):
        raise ValueError(f"f_min must be a positive frequency, got {f_min}")
    if not math.isfinite(f_max):
        raise ValueError(f"f_max must be finite, got {f_max}")
    if f_min >= f_max:
        raise ValueError(f"f_min ({f_min} Hz) must be below f_max ({f_max} Hz)")
    if f_max >= sample_rate / 2:
        raise ValueError(f"f_max ({f_max} Hz) must be below the Nyquist frequency ({sample_rate / 2} Hz)")
    if not (math.isfinite(lines_per_octave) and lines_per_octave > 0):
        raise ValueError(f"lines_per_octave must be positive, got {lines_per_octave}")
    if operator.index(crest_iterations) < 0:
        raise ValueError(f"crest_iterations must be >= 0, got {crest_iterations}")


def _frozen_array(obj: Multitone, name: str, dtype: type) -> None:
    """Replace a field by a read-only copy of itself in ``dtype``."""
    array = np.array(getattr(obj, name), dtype=dtype, copy=True)
    array.setflags(write=False)
    object.__setattr__(obj, name, array)
