"""The validity checks that need only the averaged spectra (docs/physics.md section 5).

For each channel, from the coherent mean X[k] and the variance of the mean
var[k] of every bin (analysis.spectra):

    line SNR          SNR_k = |X_k|^2 / <var>_k  at the excited lines, with the noise
                      pooled over `noise_pool_lines` neighbouring lines (a variance
                      from P periods alone scatters by sqrt(1/(P-1)))
    noise+distortion  D_b = sum_k |R_k|^2 / sum_k V_k  over the unexcited lines of a
                      band b; noise alone gives E|R_k|^2 = V_k, so D_b ~ 1 (0 dB), and
                      D_b - 1 is the distortion power over the noise power.

R_k is the unexcited line itself for the voltage. For the current and the
displacement it is what the voltage does not explain: R_k = Y_k - H(f_k) U_k,
with H = Y/U interpolated from the excited lines (cubic spline in log f,
~1e-3 accurate on the project's grid). So an amplifier that clips shows in the
voltage only, and a distorted current means the driver itself is nonlinear.
The voltage part is removed only on lines where the voltage carries more than
noise, |U_k|^2 > 10 <var_U>_k (the voltage's noise pooled over 33 lines, so
that a line whose own variance came out low by chance is not picked); there
V_k = var_Y,k + |H_k|^2 <var_U>_k.

Variances below float64 rounding ((1e-12 x the strongest line)^2, -240 dB)
are raised to it: a noise-free synthetic recording has exactly zero scatter,
and its rounding residue would otherwise stand "infinitely" above it.

A channel that is a scaled copy of another (two inputs on one sense) is
found by analysis.validity.wiring, from the same lines.

The same functions serve the whole recording (analysis.validity.assessment) and the live
per-period frames (analysis.live); they hold no state.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from analysis.spectra import ChannelSpectrum
from analysis.thresholds import ValidityThresholds
from analysis.validity.findings import (
    DISTORTION_HIGH, NO_SIGNAL, SNR_LOW, X_BAND_LOW, X_FEW_LINES, Finding, Severity, graded)
from analysis.validity.wiring import copy_findings

SIGNALS = ("voltage", "current", "displacement")
# A voltage line counts as carrying something (amplifier distortion) above this |U|^2 / <var_U>.
_VOLTAGE_CARRIES = 10.0
_VOLTAGE_POOL = 33
# Relative amplitude below which a scatter is float64 rounding, not noise.
_ROUNDING = 1e-12

_NO_SIGNAL_REMEDY = {
    "voltage": "check that the amplifier is on and that the voltage sense is wired to the driver's terminals",
    "current": "check the current sense (shunt or probe) and its wiring to the sound card input",
    "displacement": "check that the laser is connected, switched on and aimed at the cone",
}
_SNR_REMEDY = {
    "voltage": "raise the level or average more periods",
    "current": "raise the level, average more periods, or raise the current input's gain",
    "displacement": "raise the level (within the excursion limit) or average more periods",
}
_DISTORTION_REMEDY = {
    "voltage": "the amplifier is limiting: lower the level (or use an amplifier with more headroom)",
    "current": "the driver is leaving its linear range: lower the level",
}
_DRIVER_NONLINEAR = "the current is distorted too, so the driver is leaving its linear range: lower the level"
_SENSOR_NONLINEAR = ("the current is clean, so this is the triangulation sensor's own nonlinearity: raise the "
                     "level (use more of the sensor's range) and check that the laser is square to the cone")


def pooled_mean(values: np.ndarray, window: int) -> np.ndarray:
    """Centred moving mean over `window` (made odd) neighbours, the window shrinking at the ends.

    Each window is a sum of its own values (_window_sums), never a difference of running sums: the values
    span many decades (a line's SNR as a power ratio, 10^2 to 10^30), and a difference of running sums
    would lose every window after a large value to cancellation, or to inf - inf.
    """
    window = max(1, int(window)) | 1
    if window == 1 or values.size < 2:
        return values
    return _window_sums(np.asarray(values, dtype=np.float64), window) / _window_counts(values.size, window)


def _window_sums(values: np.ndarray, window: int) -> np.ndarray:
    """The sum of each centred window of `window` (odd) values, zeros beyond the ends.

    Built from blocks whose sizes are the powers of two in `window`: a block of 2s values is two blocks of s
    side by side, so a window of 33 takes 6 additions of the whole array where a convolution takes 33
    multiply-adds per value (the voltage's pool of 33 over ~13,500 unexcited lines: 0.37 -> ~0.05 ms, every
    live period). Only additions of the values themselves: the same rounding as any sum of 33 terms, no
    cancellation.
    """
    half, n = window // 2, values.size
    padded = np.concatenate((np.zeros(half), values, np.zeros(half)))
    block, size, offset, sums = padded, 1, 0, None       # block[i] = sum(padded[i:i + size])
    remaining = window
    while True:
        if remaining & 1:
            part = block[offset:offset + n]
            sums = part.copy() if sums is None else np.add(sums, part, out=sums)
            offset += size
        remaining >>= 1
        if not remaining:
            return sums
        block = block[:-size] + block[size:]
        size *= 2


@functools.lru_cache(maxsize=32)
def _window_counts(n: int, window: int) -> np.ndarray:
    """How many of the n values each centred window holds, counted rather than convolved; kept, since a live
    frame pools arrays of the same few sizes every period."""
    half = window // 2
    index = np.arange(n)
    counts = np.minimum(index + half, n - 1) - np.maximum(index - half, 0) + 1
    counts.flags.writeable = False
    return counts


def quantile(values: np.ndarray, q: float) -> float:
    """np.quantile(values, q) with its default (linear) method: the same partition and the same arithmetic,
    without its ~0.1 ms of general-purpose set-up per call (a live frame takes three every period).
    NaN if any value is NaN, as numpy's."""
    n = values.size
    if n == 0:
        raise ValueError("the quantile of no values")
    virtual = (n - 1) * q
    if virtual >= n - 1:                # numpy takes the last value twice, weight virtual + 1
        lo = hi = n - 1
        gamma = virtual + 1.0
    else:
        lo = int(math.floor(virtual))
        hi, gamma = lo + 1, virtual - lo
    ordered = np.partition(values, sorted({0, lo, hi, n - 1}))
    if np.isnan(ordered[-1]):           # NaN sorts last
        return float("nan")
    a, b = ordered[lo], ordered[hi]
    diff = b - a
    return float(b - diff * (1.0 - gamma) if gamma >= 0.5 else a + diff * gamma)


def line_snr_db(lines: np.ndarray, var: np.ndarray, pool: int) -> np.ndarray:
    """SNR of each excited line in dB against the pooled noise; a silent, noise-free line is -inf."""
    power = np.abs(lines) ** 2
    noise = pooled_mean(var, pool)
    with np.errstate(divide="ignore", invalid="ignore"):
        snr = 10.0 * np.log10(power / noise)
    return np.where(np.isnan(snr), -np.inf, snr)


def distortion_bands(other_freqs: np.ndarray, octaves: float, min_bins: int) -> np.ndarray:
    """Start indices (for np.add.reduceat) of fractional-octave bands of the unexcited lines.

    Neighbouring bands are merged until each holds at least `min_bins` lines,
    so that the noise-only ratio of every band stays close to 0 dB.
    """
    if other_freqs.size == 0:
        return np.zeros(0, dtype=np.int64)
    group = np.floor(np.log2(other_freqs / other_freqs[0]) / octaves).astype(np.int64)
    natural = np.flatnonzero(np.diff(group)) + 1
    starts = [0]
    for s in natural:
        if s - starts[-1] >= min_bins:
            starts.append(int(s))
    if len(starts) > 1 and other_freqs.size - starts[-1] < min_bins:
        starts.pop()        # a short last band joins the one before
    return np.asarray(starts, dtype=np.int64)


def interpolated_transfer(line_freqs: np.ndarray, h: np.ndarray, freqs: np.ndarray) -> np.ndarray:
    """H at `freqs` from its values at the excited lines: cubic spline of Re and Im in log f."""
    if line_freqs.size < 4:
        return np.interp(freqs, line_freqs, h.real) + 1j * np.interp(freqs, line_freqs, h.imag)
    from scipy.interpolate import CubicSpline      # 0.1 s to import: only when the voltage carries off its lines
    return CubicSpline(np.log(line_freqs), h, extrapolate=True)(np.log(freqs))


@dataclass(frozen=True, slots=True)
class _VoltageOther:
    """The voltage on the unexcited lines, shared by the current's and the displacement's residuals."""

    u: np.ndarray
    var_pooled: np.ndarray
    carries: np.ndarray         # lines where the voltage holds more than noise

    @classmethod
    def of(cls, voltage: ChannelSpectrum, other: np.ndarray) -> "_VoltageOther":
        u = voltage.mean[other]
        var = pooled_mean(voltage.var_mean[other], _VOLTAGE_POOL)
        return cls(u, var, u.real**2 + u.imag**2 > _VOLTAGE_CARRIES * var)


def _transfers(channels: Mapping[str, ChannelSpectrum], names: list[str], ref: _VoltageOther | None,
               voltage: ChannelSpectrum | None, excited: np.ndarray, line_freqs: np.ndarray,
               other_freqs: np.ndarray) -> dict[str, np.ndarray]:
    """H = Y/U of the channels `names` where the voltage carries, from one spline of their columns (the same
    values as a spline each, at half the cost: a live frame runs this every period). Empty unless every one
    of them is finite at every excited line and there are enough lines for a spline; _unexplained then
    interpolates each on its own."""
    if len(names) < 2 or ref is None or voltage is None or not ref.carries.any() or excited.size < 4:
        return {}
    with np.errstate(divide="ignore", invalid="ignore"):
        h_lines = np.stack([channels[name].mean[excited] / voltage.mean[excited] for name in names], axis=-1)
    if not np.isfinite(h_lines).all():
        return {}
    h = interpolated_transfer(line_freqs, h_lines, other_freqs[ref.carries])
    return {name: h[:, i] for i, name in enumerate(names)}


def _unexplained(spec: ChannelSpectrum, ref: _VoltageOther | None, voltage: ChannelSpectrum | None,
                 excited: np.ndarray, other: np.ndarray, line_freqs: np.ndarray,
                 other_freqs: np.ndarray, h: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """|R_k|^2 and V_k on the unexcited lines (see the module docstring); `h`: H where the voltage carries,
    when already interpolated (_transfers)."""
    y = spec.mean[other]
    var = spec.var_mean[other]
    if ref is None or voltage is None or not ref.carries.any():
        return y.real**2 + y.imag**2, var
    carries = ref.carries
    if h is None:
        with np.errstate(divide="ignore", invalid="ignore"):
            h_lines = spec.mean[excited] / voltage.mean[excited]
        ok = np.isfinite(h_lines)
        if ok.sum() < 2:
            return y.real**2 + y.imag**2, var
        h = interpolated_transfer(line_freqs[ok], h_lines[ok], other_freqs[carries])
    y[carries] -= h * ref.u[carries]           # y and var are copies (fancy indexing)
    var[carries] += np.abs(h) ** 2 * ref.var_pooled[carries]
    return y.real**2 + y.imag**2, var


def _band_ratio(residual: np.ndarray, var: np.ndarray, bands: np.ndarray) -> np.ndarray:
    """D_b per band; a noise-free band is 1 when empty and infinite when it holds anything."""
    r = np.add.reduceat(residual, bands)
    v = np.add.reduceat(var, bands)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = r / v
    return np.where(v > 0, ratio, np.where(r > 0, np.inf, 1.0))


def spectral_checks(channels: Mapping[str, ChannelSpectrum], excited: np.ndarray, unexcited: np.ndarray,
                    bin_width: float, th: ValidityThresholds, bands: np.ndarray | None = None,
                    first_bin: int = 0) -> dict[str, tuple[list[Finding], dict[str, float]]]:
    """Findings and measured numbers per channel present in `channels`.

    `excited` and `unexcited` index the channels' arrays, whose element 0 is
    FFT bin `first_bin` (0 for whole spectra; the live accumulator keeps only
    the analysed band). `bands`: distortion_bands of the unexcited lines, if
    already known. Measures (keys of the dict): snr_db, present_share,
    distortion_db, distortion_re_signal_db; for the displacement also
    x_band_hz and x_lines. A channel with no signal gets only the no-signal
    finding; one that is a scaled copy of another gets the channel-copy
    finding first (analysis.validity.wiring).
    """
    excited = np.asarray(excited, dtype=np.int64)
    unexcited = np.asarray(unexcited, dtype=np.int64)
    line_freqs = (excited + first_bin) * bin_width
    other_freqs = (unexcited + first_bin) * bin_width
    if bands is None:
        bands = distortion_bands(other_freqs, th.distortion_band_octaves, th.distortion_min_bins)
    channels = {name: _floored(spec, excited) for name, spec in channels.items()}
    voltage = channels.get("voltage")
    out: dict[str, tuple[list[Finding], dict[str, float]]] = {}
    silent: set[str] = set()
    for name in (s for s in SIGNALS if s in channels):
        spec = channels[name]
        lines = spec.mean[excited]
        snr = line_snr_db(lines, spec.var_mean[excited], th.noise_pool_lines)
        judged = np.ones(snr.size, dtype=bool)
        if name == "displacement" and np.any(line_freqs <= th.x_band_red_hz):
            judged = line_freqs <= th.x_band_red_hz       # above it the band checks speak
        findings: list[Finding] = []
        measures: dict[str, float] = {}
        share = float(np.mean(snr[judged] >= th.no_signal_line_snr_db))
        measures["present_share"] = share
        if share < th.no_signal_share:
            silent.add(name)
            findings.append(Finding(
                name, NO_SIGNAL, Severity.RED,
                f"{name}: only {share:.0%} of the {int(judged.sum())} excited lines"
                f"{_below(name, th)} stand {th.no_signal_line_snr_db:g} dB above the noise: no signal",
                _NO_SIGNAL_REMEDY[name], share))
            out[name] = (findings, measures)
            continue
        q = quantile(snr[judged], th.snr_quantile)
        measures["snr_db"] = q
        severity = graded(q, th.snr_yellow_db, th.snr_red_db, below=True)
        if severity is not Severity.GREEN:
            findings.append(Finding(
                name, SNR_LOW, severity,
                f"{name}: {1 - th.snr_quantile:.0%} of the excited lines{_below(name, th)} stand only "
                f"{q:.1f} dB above the noise (limits: red below {th.snr_red_db:g} dB, yellow below "
                f"{th.snr_yellow_db:g} dB)", _SNR_REMEDY[name], q))
        if name == "displacement":
            findings += _band_findings(snr, line_freqs, th, measures)
        out[name] = (findings, measures)

    for name, finding in copy_findings(channels, excited, silent, th).items():
        out[name][0].insert(0, finding)

    # Distortion last: the displacement's remedy depends on whether the current is distorted.
    shared = None
    if voltage is not None and "voltage" not in silent and unexcited.size:
        shared = _VoltageOther.of(voltage, unexcited)
    judged = [s for s in SIGNALS if s in out and s not in silent]
    transfers = _transfers(channels, [s for s in judged if s != "voltage"], shared, voltage, excited, line_freqs,
                           other_freqs) if unexcited.size else {}
    for name in judged:
        if unexcited.size == 0:
            continue
        ref = None if name == "voltage" else shared
        residual, var = _unexplained(channels[name], ref, voltage, excited, unexcited, line_freqs, other_freqs,
                                     transfers.get(name))
        ratio = _band_ratio(residual, var, bands)
        worst_band = int(np.argmax(ratio))
        d_db = float(10.0 * np.log10(ratio[worst_band]))
        lines = channels[name].mean[excited]
        signal_power = float(np.sum(lines.real**2 + lines.imag**2))
        excess = float(np.sum(np.maximum(residual - var, 0.0)))
        with np.errstate(divide="ignore"):
            re_signal = float(10.0 * np.log10(excess / signal_power)) if signal_power > 0 else float("inf")
        findings, measures = out[name]
        measures["distortion_db"] = d_db
        measures["distortion_re_signal_db"] = re_signal
        severity = graded(d_db, th.distortion_yellow_db, th.distortion_red_db, below=False)
        if severity is Severity.GREEN:
            continue
        stop = bands[worst_band + 1] if worst_band + 1 < bands.size else other_freqs.size
        lo, hi = other_freqs[bands[worst_band]], other_freqs[stop - 1]
        if name == "displacement":
            current = out.get("current", ([], {}))[1]
            distorted = current.get("distortion_db", 0.0) >= th.distortion_yellow_db
            remedy = _DRIVER_NONLINEAR if distorted else _SENSOR_NONLINEAR
        else:
            remedy = _DISTORTION_REMEDY[name]
        findings.append(Finding(
            name, DISTORTION_HIGH, severity,
            f"{name}: noise + distortion on the unexcited lines stands {d_db:.1f} dB above the noise floor "
            f"at {lo:.0f}-{hi:.0f} Hz (distortion {re_signal:.0f} dB re the excited lines; limits: "
            f"yellow {th.distortion_yellow_db:g} dB, red {th.distortion_red_db:g} dB)", remedy, d_db))
    return out


def _floored(spec: ChannelSpectrum, excited: np.ndarray) -> ChannelSpectrum:
    """The spectrum with its variances raised to float64 rounding (see the module docstring)."""
    floor = (_ROUNDING * float(np.max(np.abs(spec.mean[excited]), initial=0.0))) ** 2
    if floor <= 0.0 or float(spec.var_mean.min()) >= floor:
        return spec
    return ChannelSpectrum(spec.signal, spec.unit, spec.mean, np.maximum(spec.var_mean, floor))


def _below(name: str, th: ValidityThresholds) -> str:
    return f" below {th.x_band_red_hz:g} Hz" if name == "displacement" else ""


def _band_findings(snr: np.ndarray, line_freqs: np.ndarray, th: ValidityThresholds,
                   measures: dict[str, float]) -> list[Finding]:
    """x-band-low and x-few-lines from the displacement's line SNRs."""
    findings = []
    smooth = 10.0 * np.log10(np.maximum(pooled_mean(10.0 ** (snr / 10.0), th.noise_pool_lines), 1e-300))
    above = np.flatnonzero(smooth >= th.x_line_snr_db)
    band = float(line_freqs[above[-1]]) if above.size else 0.0
    n_lines = int(np.sum(snr >= th.x_line_snr_db))
    measures["x_band_hz"] = band
    measures["x_lines"] = float(n_lines)
    severity = graded(band, th.x_band_yellow_hz, th.x_band_red_hz, below=True)
    if severity is not Severity.GREEN:
        findings.append(Finding(
            "displacement", X_BAND_LOW, severity,
            f"displacement: the lines stand {th.x_line_snr_db:g} dB above the noise only up to {band:.0f} Hz "
            f"(limits: red below {th.x_band_red_hz:g} Hz, yellow below {th.x_band_yellow_hz:g} Hz)",
            "raise the level or average more periods; check the laser's measuring rate and filter "
            "(its bandwidth must reach well above the resonance)", band))
    severity = graded(n_lines, th.x_lines_yellow, th.x_lines_red, below=True)
    if severity is not Severity.GREEN:
        findings.append(Finding(
            "displacement", X_FEW_LINES, severity,
            f"displacement: only {n_lines} of {snr.size} lines stand {th.x_line_snr_db:g} dB above the noise "
            f"(limits: red below {th.x_lines_red}, yellow below {th.x_lines_yellow})",
            "the resonance is close to the sensor's bandwidth: raise the level, average more periods, or use "
            "a longer period (more lines at low frequencies)", n_lines))
    return findings
