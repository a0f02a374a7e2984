"""The channels' averaged spectra at the excited and at the unexcited lines, gathered once for every check.

The spectral checks (analysis.validity.spectral, analysis.validity.unexcited)
read each channel's coherent mean and variance of the mean at two sets of
bins: the excited lines (~100) and the band's unexcited lines (~13,500 for a
65,536-sample period). Gathered here once, as rows of one array per set (one
row per channel, in the order of `signals`), the checks work on all channels
at once, and the voltage's unexcited lines, which the current's and the
displacement's residuals reuse, are read once. A live frame pays for this
every period.

Variances below float64 rounding ((1e-12 x the channel's strongest line)^2,
-240 dB) are raised to it: a noise-free synthetic recording has exactly zero
scatter, and its rounding residue would otherwise stand "infinitely" above it.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np

from analysis.spectra import ChannelSpectrum

# Relative amplitude below which a scatter is float64 rounding, not noise.
ROUNDING = 1e-12


@dataclass(frozen=True, slots=True, eq=False, kw_only=True)
class LineSpectra:
    """The channels' lines gathered in arrays, row by channel, for the checks."""

    signals: tuple[str, ...]
    lines: np.ndarray           # (channels, excited) complex: the coherent mean at the excited lines
    line_var: np.ndarray        # (channels, excited): its variance of the mean, floored
    other: np.ndarray           # (channels, unexcited) complex: the coherent mean at the unexcited lines
    other_var: np.ndarray       # (channels, unexcited): its variance of the mean, floored
    other_power: np.ndarray     # (channels, unexcited): |other|^2

    @classmethod
    def of_spectra(cls, channels: Mapping[str, ChannelSpectrum], excited: np.ndarray,
                   unexcited: np.ndarray) -> "LineSpectra":
        """From whole spectra (or a band of them) indexed by `excited` and `unexcited`."""
        signals = tuple(channels)
        mean = [channels[name].mean for name in signals]
        var = [channels[name].var_mean for name in signals]
        return cls.gathered(signals, np.stack([m[excited] for m in mean]), np.stack([v[excited] for v in var]),
                            np.stack([m[unexcited] for m in mean]), np.stack([v[unexcited] for v in var]))

    @classmethod
    def of_band(cls, signals: tuple[str, ...], mean: np.ndarray, var: np.ndarray, excited: np.ndarray,
                unexcited: np.ndarray) -> "LineSpectra":
        """From (channels, bins) arrays of the mean and the variance of the mean (the live accumulator's).
        np.take, not mean[:, index]: numpy's fancy indexing along the second axis takes 7-10 times as long."""
        return cls.gathered(signals, np.take(mean, excited, axis=1), np.take(var, excited, axis=1),
                            np.take(mean, unexcited, axis=1), np.take(var, unexcited, axis=1))

    @classmethod
    def gathered(cls, signals: tuple[str, ...], lines: np.ndarray, line_var: np.ndarray, other: np.ndarray,
                 other_var: np.ndarray) -> "LineSpectra":
        """The gathered arrays (owned: the variances are floored in place) with their floors applied."""
        # One floor per channel, in one call for all: a zero floor (a silent channel) leaves its variances as
        # they are, a NaN one (a NaN line) makes them NaN, as np.maximum always did here.
        floor = np.array([[(ROUNDING * float(strongest)) ** 2]
                          for strongest in np.max(np.abs(lines), axis=-1, initial=0.0)])
        np.maximum(line_var, floor, out=line_var)
        np.maximum(other_var, floor, out=other_var)
        other_power = np.square(other.real)
        other_power += np.square(other.imag)
        return cls(signals=tuple(signals), lines=lines, line_var=line_var, other=other, other_var=other_var,
                   other_power=other_power)

    def row(self, name: str) -> int:
        return self.signals.index(name)
