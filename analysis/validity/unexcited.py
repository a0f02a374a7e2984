"""Noise + distortion on the unexcited lines (docs/physics.md section 5), every judged channel at once.

For each channel, over the unexcited lines of a band b,

    D_b = sum_k |R_k|^2 / sum_k V_k

noise alone gives E|R_k|^2 = V_k, so D_b ~ 1 (0 dB), and D_b - 1 is the
distortion power over the noise power.

R_k is the unexcited line itself for the voltage. For the current and the
displacement it is what the voltage does not explain: R_k = Y_k - H(f_k) U_k,
with H = Y/U interpolated from the excited lines (cubic spline in log f,
~1e-3 accurate on the project's grid; analysis.validity.knot_spline keeps it
as a linear map per set of lines). So an amplifier that clips shows in the
voltage only, and a distorted current means the driver itself is nonlinear.
The voltage part is removed only on lines where the voltage carries more than
noise, |U_k|^2 > 10 <var_U>_k (the voltage's noise pooled over 33 lines, so
that a line whose own variance came out low by chance is not picked); there
V_k = var_Y,k + |H_k|^2 <var_U>_k.

The channels are rows of analysis.validity.line_spectra's arrays: the
residuals of all of them come from one copy of those rows, the band sums from
one reduceat each (a live frame runs this every period).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.validity.knot_spline import spline_at
from analysis.validity.line_spectra import LineSpectra
from analysis.validity.pooling import pooled_mean

# A voltage line counts as carrying something (amplifier distortion) above this |U|^2 / <var_U>.
_VOLTAGE_CARRIES = 10.0
_VOLTAGE_POOL = 33


@dataclass(frozen=True, slots=True, kw_only=True)
class UnexcitedMeasure:
    """One channel's worst band: D_b in dB, the excess over the noise re the excited lines, the band's ends."""

    distortion_db: float
    re_signal_db: float
    lo_hz: float
    hi_hz: float


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
    return spline_at(np.log(line_freqs), h, np.log(freqs))


def unexcited_measures(spectra: LineSpectra, judged: list[str], line_freqs: np.ndarray,
                       other_freqs: np.ndarray, bands: np.ndarray) -> dict[str, UnexcitedMeasure]:
    """The worst band of each channel in `judged` (those with a signal; the voltage's residual is removed from
    the others only when the voltage is among them). Empty without unexcited lines."""
    if not judged or other_freqs.size == 0:
        return {}
    rows = [spectra.row(name) for name in judged]
    residual, var = _residuals(spectra, judged, rows, line_freqs, other_freqs)
    r = np.add.reduceat(residual, bands, axis=-1)
    v = np.add.reduceat(var, bands, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(v > 0, r / v, np.where(r > 0, np.inf, 1.0))   # noise-free: 1 when empty, else inf
    worst = np.argmax(ratio, axis=-1)
    # sum max(|R|^2 - V, 0) as sum max(|R|^2, V) - sum V: no array of the differences (noise alone puts the
    # excess at ~e^-1 of sum V, so no cancellation to speak of; with |R|^2 <= V everywhere both sums are the
    # same terms in the same order, and the excess exactly 0, as before).
    excess = np.maximum(residual, var).sum(axis=-1) - var.sum(axis=-1)
    np.maximum(excess, 0.0, out=excess)
    out = {}
    for i, name in enumerate(judged):
        band = int(worst[i])
        lines = spectra.lines[rows[i]]
        signal_power = float(np.sum(lines.real**2 + lines.imag**2))
        with np.errstate(divide="ignore"):
            re_signal = float(10.0 * np.log10(float(excess[i]) / signal_power)) if signal_power > 0 else float("inf")
        stop = bands[band + 1] if band + 1 < bands.size else other_freqs.size
        out[name] = UnexcitedMeasure(distortion_db=float(10.0 * np.log10(ratio[i, band])), re_signal_db=re_signal,
                                     lo_hz=float(other_freqs[bands[band]]), hi_hz=float(other_freqs[stop - 1]))
    return out


def _residuals(spectra: LineSpectra, judged: list[str], rows: list[int], line_freqs: np.ndarray,
               other_freqs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """|R_k|^2 and V_k of the channels `judged` (rows `rows`): the gathered powers and variances themselves when
    nothing comes off them (the usual frame: no copy), else copies with the voltage's part removed."""
    removed = _voltage_parts(spectra, judged, line_freqs, other_freqs) if "voltage" in judged else []
    if not removed and rows == list(range(len(spectra.signals))):
        return spectra.other_power, spectra.other_var
    residual = np.take(spectra.other_power, rows, axis=0)
    var = np.take(spectra.other_var, rows, axis=0)
    for name, carries, residual_there, var_added in removed:
        i = judged.index(name)
        residual[i][carries] = residual_there
        var[i][carries] += var_added
    return residual, var


def _voltage_parts(spectra: LineSpectra, judged: list[str], line_freqs: np.ndarray,
                   other_freqs: np.ndarray) -> list[tuple[str, np.ndarray, np.ndarray, np.ndarray]]:
    """For the current and the displacement among `judged`, where the voltage carries: the lines (indices),
    |R_k|^2 there and what the voltage's noise adds to V_k there (|H_k|^2 <var_U>_k). Empty where nothing
    carries."""
    names = [name for name in judged if name != "voltage"]
    if not names:
        return []
    voltage = spectra.row("voltage")
    u_var = pooled_mean(spectra.other_var[voltage], _VOLTAGE_POOL)
    carries = np.flatnonzero(spectra.other_power[voltage] > _VOLTAGE_CARRIES * u_var)
    if not carries.size:
        return []
    u_var_carries = u_var[carries]
    u_lines = spectra.lines[voltage]
    h_all = _transfers(spectra, names, u_lines, line_freqs, other_freqs[carries])
    u_carries = spectra.other[voltage][carries]
    parts = []
    for name in names:
        row = spectra.row(name)
        h = h_all.get(name)
        if h is None:
            with np.errstate(divide="ignore", invalid="ignore"):
                h_lines = spectra.lines[row] / u_lines
            ok = np.isfinite(h_lines)
            if ok.sum() < 2:
                continue
            h = interpolated_transfer(line_freqs[ok], h_lines[ok], other_freqs[carries])
        y = spectra.other[row][carries] - h * u_carries
        parts.append((name, carries, y.real**2 + y.imag**2, np.abs(h) ** 2 * u_var_carries))
    return parts


def _transfers(spectra: LineSpectra, names: list[str], u_lines: np.ndarray, line_freqs: np.ndarray,
               freqs: np.ndarray) -> dict[str, np.ndarray]:
    """H = Y/U of the channels `names` at `freqs`, from one spline of their columns (the same values as a
    spline each, at half the cost). Empty unless there are two of them, every one is finite at every excited
    line and there are enough lines for a spline; _voltage_parts then interpolates each on its own."""
    if len(names) < 2 or line_freqs.size < 4:
        return {}
    with np.errstate(divide="ignore", invalid="ignore"):
        h_lines = np.stack([spectra.lines[spectra.row(name)] / u_lines for name in names], axis=-1)
    if not np.isfinite(h_lines).all():
        return {}
    h = interpolated_transfer(line_freqs, h_lines, freqs)
    return {name: h[:, i] for i, name in enumerate(names)}
