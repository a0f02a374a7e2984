"""The validity checks that need only the averaged spectra (docs/physics.md section 5).

For each channel, from the coherent mean X[k] and the variance of the mean
var[k] of every bin (analysis.spectra):

    line SNR          SNR_k = |X_k|^2 / <var>_k  at the excited lines, with the noise
                      pooled over `noise_pool_lines` neighbouring lines (a variance
                      from P periods alone scatters by sqrt(1/(P-1)))
    noise+distortion  D_b = sum_k |R_k|^2 / sum_k V_k  over the unexcited lines of a
                      band b (analysis.validity.unexcited: R_k is what the voltage
                      does not explain).

The lines of every channel are gathered once, their variances floored at
float64 rounding (analysis.validity.line_spectra); the SNRs and the residuals
are worked out for all channels at once.

A channel that is a scaled copy of another (two inputs on one sense) is
found by analysis.validity.wiring, from the same lines.

The same functions serve the whole recording (analysis.validity.assessment) and the live
per-period frames (analysis.live, which gathers its band's lines itself and calls line_checks);
they hold no state.
"""
from __future__ import annotations

import math
from typing import Mapping

import numpy as np

from analysis.spectra import ChannelSpectrum
from analysis.thresholds import ValidityThresholds
from analysis.validity.findings import (
    DISTORTION_HIGH, NO_SIGNAL, SNR_LOW, X_BAND_LOW, X_FEW_LINES, Finding, Severity, graded)
from analysis.validity.line_spectra import LineSpectra
from analysis.validity.pooling import pooled_mean
from analysis.validity.unexcited import distortion_bands, unexcited_measures
from analysis.validity.wiring import copy_findings

SIGNALS = ("voltage", "current", "displacement")

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
    power = np.square(lines.real)
    power += np.square(lines.imag)
    noise = pooled_mean(var, pool)
    with np.errstate(divide="ignore", invalid="ignore"):
        snr = 10.0 * np.log10(power / noise)
    return np.where(np.isnan(snr), -np.inf, snr)


def spectral_checks(channels: Mapping[str, ChannelSpectrum], excited: np.ndarray, unexcited: np.ndarray,
                    bin_width: float, th: ValidityThresholds, bands: np.ndarray | None = None,
                    first_bin: int = 0) -> dict[str, tuple[list[Finding], dict[str, float]]]:
    """Findings and measured numbers per channel present in `channels`.

    `excited` and `unexcited` index the channels' arrays, whose element 0 is
    FFT bin `first_bin` (0 for whole spectra). `bands`: distortion_bands of
    the unexcited lines, if already known. See line_checks.
    """
    excited = np.asarray(excited, dtype=np.int64)
    unexcited = np.asarray(unexcited, dtype=np.int64)
    line_freqs = (excited + first_bin) * bin_width
    other_freqs = (unexcited + first_bin) * bin_width
    if bands is None:
        bands = distortion_bands(other_freqs, th.distortion_band_octaves, th.distortion_min_bins)
    ordered = {name: channels[name] for name in SIGNALS if name in channels}
    return line_checks(LineSpectra.of_spectra(ordered, excited, unexcited), line_freqs, other_freqs, th, bands)


def line_checks(spectra: LineSpectra, line_freqs: np.ndarray, other_freqs: np.ndarray, th: ValidityThresholds,
                bands: np.ndarray) -> dict[str, tuple[list[Finding], dict[str, float]]]:
    """Findings and measured numbers per channel of `spectra` (those among SIGNALS) at the excited lines
    `line_freqs` and the unexcited `other_freqs` (Hz), whose distortion bands are `bands`.

    Measures (keys of the dict): snr_db, present_share, distortion_db,
    distortion_re_signal_db; for the displacement also x_band_hz and x_lines.
    A channel with no signal gets only the no-signal finding; one that is a
    scaled copy of another gets the channel-copy finding first
    (analysis.validity.wiring).
    """
    out: dict[str, tuple[list[Finding], dict[str, float]]] = {}
    silent: set[str] = set()
    snrs = line_snr_db(spectra.lines, spectra.line_var, th.noise_pool_lines)     # every channel at once
    for name in (s for s in SIGNALS if s in spectra.signals):
        snr = snrs[spectra.row(name)]
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

    lines = {name: spectra.lines[row] for row, name in enumerate(spectra.signals)}
    for name, finding in copy_findings(lines, silent, th).items():
        out[name][0].insert(0, finding)

    # Distortion last: the displacement's remedy depends on whether the current is distorted.
    judged = [s for s in SIGNALS if s in out and s not in silent]
    for name, measure in unexcited_measures(spectra, judged, line_freqs, other_freqs, bands).items():
        findings, measures = out[name]
        d_db = measure.distortion_db
        measures["distortion_db"] = d_db
        measures["distortion_re_signal_db"] = measure.re_signal_db
        severity = graded(d_db, th.distortion_yellow_db, th.distortion_red_db, below=False)
        if severity is Severity.GREEN:
            continue
        if name == "displacement":
            current = out.get("current", ([], {}))[1]
            distorted = current.get("distortion_db", 0.0) >= th.distortion_yellow_db
            remedy = _DRIVER_NONLINEAR if distorted else _SENSOR_NONLINEAR
        else:
            remedy = _DISTORTION_REMEDY[name]
        findings.append(Finding(
            name, DISTORTION_HIGH, severity,
            f"{name}: noise + distortion on the unexcited lines stands {d_db:.1f} dB above the noise floor "
            f"at {measure.lo_hz:.0f}-{measure.hi_hz:.0f} Hz (distortion {measure.re_signal_db:.0f} dB re the "
            f"excited lines; limits: yellow {th.distortion_yellow_db:g} dB, red {th.distortion_red_db:g} dB)",
            remedy, d_db))
    return out


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
