"""Where a fit's residual sits, in words a technician can act on.

Each line's complex residual is split, relative to the model, into a
magnitude part and a phase part, both in units of the line's noise:

    measured / model - 1 = a + j b      a: relative magnitude error, b: phase error (rad)
    mag = a / sigma_rel,  phase = b / sigma_rel,  sigma_rel = std / |model| / sqrt(2)

The band reported is where the (slightly smoothed) squared residual stays
above 3 sigma and within 10 dB of its peak, holding the largest share of
the misfit: a missing effect leaves its mark everywhere (the other
parameters bend to absorb it) but most where it acts.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.fit.least_squares import ChannelFit, FitResult

THRESHOLD_SIGMA = 3.0
PEAK_FRACTION = 0.1
CHANNEL_WORDS = {"impedance": "impedance Z", "displacement": "displacement Hx"}


@dataclass(frozen=True, slots=True)
class ResidualFinding:
    channel: str
    f_low: float
    f_high: float
    part: str            # "magnitude" or "phase"
    sign: int            # +1: measured above the model (magnitude) / leads it (phase)
    peak_sigma: float    # largest |residual| in the band, in noise units
    share: float         # share of the channel's chi^2 inside the band

    def text(self) -> str:
        if self.part == "magnitude":
            how = "measured above the model" if self.sign > 0 else "measured below the model"
        else:
            how = "measured phase leads the model" if self.sign > 0 else "measured phase lags the model"
        return (f"{CHANNEL_WORDS.get(self.channel, self.channel)}, {self.f_low:.3g} to {self.f_high:.3g} Hz: "
                f"{self.part} residual, {how}, up to {self.peak_sigma:.0f} sigma "
                f"({100 * self.share:.0f} % of that channel's misfit)")


def split_residual(ch: ChannelFit) -> tuple[np.ndarray, np.ndarray]:
    """(magnitude part, phase part) of each line's residual, in noise units."""
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = ch.measured / ch.model - 1.0
        sigma_rel = ch.std / np.abs(ch.model) / np.sqrt(2.0)
        return ratio.real / sigma_rel, ratio.imag / sigma_rel


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    edges = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)))


def channel_finding(ch: ChannelFit) -> ResidualFinding | None:
    mag, phase = split_residual(ch)
    power = np.nan_to_num(mag**2 + phase**2)
    if power.size == 0:
        return None
    smooth = np.convolve(power, np.ones(3) / 3, mode="same")
    if smooth.max() <= THRESHOLD_SIGMA**2:
        return None
    # The band around the worst lines: where the misfit stays within 10 dB of its peak.
    runs = _runs(smooth > max(THRESHOLD_SIGMA**2, PEAK_FRACTION * smooth.max()))
    total = power.sum()
    lo, hi = max(runs, key=lambda r: power[r[0]:r[1]].sum())
    band = slice(lo, hi)
    mag_power, phase_power = np.sum(mag[band] ** 2), np.sum(phase[band] ** 2)
    part, values = ("magnitude", mag[band]) if mag_power >= phase_power else ("phase", phase[band])
    return ResidualFinding(ch.name, float(ch.freqs[lo]), float(ch.freqs[hi - 1]), part,
                           int(np.sign(np.sum(values)) or 1), float(np.sqrt(power[band].max())),
                           float(power[band].sum() / total) if total > 0 else 0.0)


def findings(fit: FitResult) -> list[ResidualFinding]:
    """One finding per channel with a misfit, the worst channel first."""
    found = [f for ch in fit.channels.values() if (f := channel_finding(ch)) is not None]
    return sorted(found, key=lambda f: -fit.channels[f.channel].chi2_red)


def describe(fit: FitResult) -> str:
    found = findings(fit)
    if not found:
        return "the residual is at the noise floor on every channel"
    return "; ".join(f.text() for f in found)
