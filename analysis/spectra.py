"""Spectral estimation of a periodic multitone recording.

Each whole period after the settle periods is transformed on its own. For a
steady-state periodic excitation every period carries the same signal, so

    mean over periods       -> the coherent spectrum (signal + distortion)
    scatter between periods -> the noise on every line

Spectra are one-sided peak amplitudes: a sine of amplitude A on bin k gives
|X[k]| = A. Variances are of the complex mean, E|dX|^2 / P.

Transfer functions are formed from the per-period spectra so that noise that
is common to two channels (amplifier noise appears in both U and I, related
by Z) is propagated correctly:

    Z = mean(U) / mean(I),   dZ = (dU - Z*dI) / I   =>   var(Z) = var_mean(U - Z*I) / |I|^2
    Hx = mean(X) / mean(U),  var(Hx) = var_mean(X - Hx*U) / |U|^2
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from analysis.bounds import FREQUENCY
from analysis.errors import LinparError
from analysis.recording.format import Recording

ANALYSED_SIGNALS = ("voltage", "current", "displacement")
# A line counts as excited when it stands this far above the noise and is
# within this range of the strongest line (for recordings without excited_bins).
DETECT_SNR_DB = 20.0
DETECT_RANGE_DB = 60.0
# Degrees of freedom each line's noise estimate should rest on (see transfer_from_periods).
MIN_NOISE_DOF = 40


class SpectrumError(LinparError, ValueError):
    """The recording cannot give spectra (no excited line found, no voltage or current)."""


@dataclass(frozen=True, slots=True)
class ChannelSpectrum:
    """The averaged spectrum of one channel at every bin 0..N/2."""

    signal: str
    unit: str
    mean: np.ndarray        # complex, coherent mean per bin (peak amplitude)
    var_mean: np.ndarray    # float, variance of the mean per bin

    @property
    def noise_floor(self) -> np.ndarray:
        """Standard deviation of the averaged line: what noise leaves on each bin."""
        return np.sqrt(self.var_mean)

    @property
    def amplitude(self) -> np.ndarray:
        return np.abs(self.mean)


@dataclass(frozen=True, slots=True)
class TransferFunction:
    """A transfer function at the excited lines with its per-line standard uncertainty."""

    name: str               # "impedance" or "displacement"
    unit: str
    freqs: np.ndarray       # Hz
    bins: np.ndarray        # FFT bins of one period
    value: np.ndarray       # complex (real and >= 0 when has_phase is False: a magnitude)
    std: np.ndarray         # sqrt(E|dH|^2), the complex standard uncertainty; NaN when unknown
    has_phase: bool = True  # imported curves may carry the magnitude only
    noise_known: bool = True  # imported curves carry no per-line uncertainty

    def restricted(self, keep: np.ndarray) -> "TransferFunction":
        return TransferFunction(self.name, self.unit, self.freqs[keep], self.bins[keep],
                                self.value[keep], self.std[keep], self.has_phase, self.noise_known)


@dataclass(frozen=True, slots=True)
class Spectra:
    sample_rate: float
    period_samples: int
    n_periods: int
    excited_bins: np.ndarray
    unexcited_bins: np.ndarray          # bins between the first and last excited one, not excited
    channels: dict[str, ChannelSpectrum]
    impedance: TransferFunction
    displacement: TransferFunction | None
    # Each analysed channel's per-period spectra at the excited lines (periods x lines), as estimate_spectra
    # transformed them: the drift check compares the first periods with the last, and would otherwise transform
    # every period once more (a third of `linpar analyze`'s own work on a standard recording).
    excited_per_period: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def freqs(self) -> np.ndarray:
        return np.arange(self.period_samples // 2 + 1) * self.sample_rate / self.period_samples

    @property
    def bin_width(self) -> float:
        return self.sample_rate / self.period_samples


def period_spectra(periods: np.ndarray) -> np.ndarray:
    """One-sided peak-amplitude spectra of each row (shape P x N -> P x N/2+1)."""
    n = periods.shape[-1]
    spectra = np.fft.rfft(periods, axis=-1)
    spectra *= 2.0 / n
    spectra[..., 0] *= 0.5
    if n % 2 == 0:
        spectra[..., -1] *= 0.5
    return spectra


def _mean_and_var(per_period: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    mean = per_period.mean(axis=0)
    p = per_period.shape[0]
    dev = per_period - mean
    var_mean = (dev.real**2 + dev.imag**2).sum(axis=0) / (p * (p - 1))
    return mean, var_mean


def detect_excited_bins(voltage: ChannelSpectrum) -> np.ndarray:
    """Bins of the voltage spectrum that carry the excitation."""
    power = voltage.amplitude[1:] ** 2
    strongest = power.max(initial=0.0)
    if strongest <= 0.0:
        raise SpectrumError("the voltage channel is silent: no excited line found")
    above_noise = power > voltage.var_mean[1:] * 10 ** (DETECT_SNR_DB / 10)
    within_range = power > strongest * 10 ** (-DETECT_RANGE_DB / 10)
    bins = np.flatnonzero(above_noise & within_range) + 1
    return bins


def excited_lines(recording: Recording, voltage: ChannelSpectrum | None = None) -> np.ndarray:
    """The excitation's bins, sorted: the sidecar's when it lists them, else found in the voltage spectrum.

    The format makes the list optional (a recording made by a DAQ or a script has none). `voltage`: the
    voltage's averaged spectrum when the caller has it already. SpectrumError when no line is found.
    """
    if recording.excited_bins is not None:
        excited = np.asarray(recording.excited_bins, dtype=np.int64)
    else:
        if voltage is None:
            if recording.signal("voltage") is None:
                raise SpectrumError("the recording has no 'voltage' channel: its excited lines are found there")
            voltage = ChannelSpectrum("voltage", "V", *_mean_and_var(period_spectra(recording.periods("voltage"))))
        excited = detect_excited_bins(voltage)
    if excited.size == 0:
        raise SpectrumError("no excited line found in the voltage spectrum")
    return np.sort(excited)


def pooling_window(n_periods: int) -> int:
    """Lines pooled for each noise estimate, so that it rests on >= MIN_NOISE_DOF degrees of freedom."""
    dof = 2 * (n_periods - 1)
    lines = int(np.ceil(MIN_NOISE_DOF / dof))
    return lines + (1 - lines % 2)       # odd: centred on the line


def _pooled(var: np.ndarray, window: int) -> np.ndarray:
    if window <= 1 or var.size < 2:
        return var
    window = min(window, var.size - (1 - var.size % 2))
    kernel = np.ones(window)
    padded = np.pad(var, window // 2, mode="edge")
    return np.convolve(padded, kernel, mode="valid") / window


def transfer_from_periods(name: str, unit: str, num: np.ndarray, den: np.ndarray, bins: np.ndarray,
                          bin_width: float, noise_factor: float = 1.0) -> TransferFunction:
    """num / den at `bins` from per-period spectra (P x lines) with the propagated uncertainty.

    The variance of each line is estimated from only P periods. Its
    reciprocal (the fit's weight) is then biased: for a variance with nu
    degrees of freedom, E[1/var_hat] = nu/(nu-2) / var. Neighbouring lines
    are pooled until nu >= MIN_NOISE_DOF, and the rest of the bias is
    removed, so that a right model gives a reduced chi^2 of 1. ``noise_factor``
    scales the variance where samples missing from some periods were filled
    with the mean of the others, which the scatter cannot see.
    """
    p = num.shape[0]
    num_mean = num.mean(axis=0)
    den_mean = den.mean(axis=0)
    window = pooling_window(p)
    nu = 2 * (p - 1) * window
    with np.errstate(divide="ignore", invalid="ignore"):
        value = num_mean / den_mean
        error = num - value * den          # per period: the part that is not the transfer function
        dev = error - error.mean(axis=0)
        var_error = _pooled((dev.real**2 + dev.imag**2).sum(axis=0) / (p * (p - 1)), window)
        var = noise_factor * var_error * (nu / (nu - 2)) / np.abs(den_mean) ** 2
    return TransferFunction(name, unit, bins * bin_width, bins, value, np.sqrt(var))


def displacement_noise_factor(recording: Recording) -> float:
    """How much the displacement's noise exceeds the scatter between periods, for the laser samples left
    out of the average (capture.laser_gaps, instruments/measurement/laser_gaps.py); 1 without gaps."""
    capture = recording.extra.get("capture") if recording.extra else None
    gaps = capture.get("laser_gaps") if isinstance(capture, dict) else None
    if gaps is None:
        return 1.0
    from analysis.validity.capture import CaptureInfoError, LaserGapInfo
    try:
        factor = LaserGapInfo.from_json(gaps).noise_factor
    except CaptureInfoError as exc:
        raise SpectrumError(f"sidecar key {exc}") from None
    # Unknown (no point measured twice): the validity says so in red; the scatter is all there is.
    return 1.0 if factor is None else max(float(factor), 1.0)


def displacement_max_hz(recording: Recording, error: type[LinparError] = SpectrumError) -> float | None:
    """The top of a serial laser's band (the sidecar's displacement_max_hz), None when the laser has no band of
    its own; `error` (one line) when the key holds no frequency. The spectra and the large-signal data read it."""
    value = recording.extra.get("displacement_max_hz") if recording.extra else None
    if value is None:
        return None
    return FREQUENCY.check(value, "sidecar key displacement_max_hz (the top of the laser's band)", error)


def estimate_spectra(recording: Recording) -> Spectra:
    """Per-period spectra after the settle periods, averaged, with noise and transfer functions."""
    for required in ("voltage", "current"):
        if recording.signal(required) is None:
            raise SpectrumError(f"the recording has no {required!r} channel: Z = U / I needs both voltage and current")
    n = recording.period_samples
    bin_width = recording.sample_rate / n
    channels: dict[str, ChannelSpectrum] = {}
    per_period: dict[str, np.ndarray] = {}
    for ch in recording.channels:
        if ch.signal not in ANALYSED_SIGNALS:
            continue
        spec = period_spectra(recording.periods(ch.signal))
        mean, var_mean = _mean_and_var(spec)
        channels[ch.signal] = ChannelSpectrum(ch.signal, ch.unit, mean, var_mean)
        per_period[ch.signal] = spec

    excited = excited_lines(recording, channels["voltage"])
    span = np.arange(excited[0], excited[-1] + 1)
    unexcited = np.setdiff1d(span, excited, assume_unique=True)

    excited_per_period = {name: spec[:, excited] for name, spec in per_period.items()}
    u, i = excited_per_period["voltage"], excited_per_period["current"]
    impedance = transfer_from_periods("impedance", "ohm", u, i, excited, bin_width)
    displacement = None
    if "displacement" in per_period:
        # A serial laser samples slower than the sound card: the sidecar's
        # displacement_max_hz marks where its band ends; lines above carry no displacement.
        max_hz = displacement_max_hz(recording)
        x_lines = excited if max_hz is None else excited[excited * bin_width <= max_hz]
        in_band = np.isin(excited, x_lines)
        displacement = transfer_from_periods("displacement", "m/V", per_period["displacement"][:, x_lines],
                                             u[:, in_band], x_lines, bin_width, displacement_noise_factor(recording))
    return Spectra(recording.sample_rate, n, recording.n_periods, excited, unexcited,
                   channels, impedance, displacement,
                   excited_per_period=excited_per_period)
