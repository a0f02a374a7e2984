"""The band a recording's parameters come from when the lumped model misses the whole band.

A real driver follows the lumped piston model over a band, not everywhere: above a few times fs its cone
stops moving as a piston (a mode near 1-2 kHz, seen partly at the laser's spot), and over decades of
frequency its coil's eddy currents follow no lumped law of the catalogue. Fitted over every line, the
model then bends its parameters to imitate what it lacks, and its fit error counts physics the parameters
do not describe (and the laser's noise floor far above fs) as misfit: the tests' realistic woofer,
midrange and subwoofer (tests/realistic_drivers.py) are missed by 8, 4.5 and 17 % on Z and 31, 25 and
198 % on Hx over 15 Hz-10 kHz, their RE 2.5-3.2 % high.

So when the default fit misses the displacement by more than the fit error a real driver measured well
shows (analysis.fit.error.FIT_ERROR_DEFAULTS: the laser sees the cone stop moving as a piston;
analysis.pipeline.misses_the_band says why Z alone does not decide), it is fitted again over the piston
band, read from the data as the curves' path does (analysis.curves.fitting), fs from the first fit:

- Z up to Z_MAX_OVER_FS * fs (50: 0.9-4.8 kHz on the three): the motional parameters and RE, LE and the
  blocked impedance's, which need the band where the inductance rises (up to 5 or 10 fs RE trades with
  lr2's branch: -18 % on the woofer and midrange);
- Hx up to HX_MAX_OVER_FS * fs (4, as for imported curves), at the lines standing above the laser's noise:
  Bl and the creep come from around and below fs.

Measured on the three realistic drivers (seeds 0 and 1): fit error 2.3-3.0 % on Z and 0.9-4.2 % on Hx,
RE, Bl, Mms and Kms within 4.2 % of the truth (full band: 0.7-5.7 %). The bands are in the result's
validity ("fit_band_hz"), beside the fit errors measured over them.
"""
from __future__ import annotations

import numpy as np

from analysis.fit.least_squares import FitData

Z_MAX_OVER_FS = 50.0
HX_MAX_OVER_FS = 4.0
# A displacement line counts when it stands this many of its standard deviations above its noise.
HX_MIN_SNR = 10.0
# Fewer lines than this in a channel's band: the band is not used (the whole band is fitted as before).
MIN_LINES = 5


def piston_band(data: FitData, fs: float) -> FitData | None:
    """`data` restricted to the piston band of a driver resonating at `fs` (module doc); None when the band
    leaves a channel too few lines or takes nothing away."""
    if not (np.isfinite(fs) and fs > 0):
        return None
    z = data.impedance
    band_z = z.restricted(z.freqs <= Z_MAX_OVER_FS * fs)
    x = data.displacement
    band_x = None
    if x is not None:
        keep = x.freqs <= HX_MAX_OVER_FS * fs
        if x.noise_known:
            keep &= np.abs(x.value) >= HX_MIN_SNR * np.nan_to_num(x.std, nan=np.inf)
        band_x = x.restricted(keep)
    if len(band_z.freqs) < MIN_LINES or (band_x is not None and len(band_x.freqs) < MIN_LINES):
        return None
    if len(band_z.freqs) == len(z.freqs) and (x is None or len(band_x.freqs) == len(x.freqs)):
        return None
    return FitData(band_z, band_x)


def bands_hz(data: FitData) -> dict[str, list[float]]:
    """channel -> [lowest, highest] line fitted, in Hz (JSON-ready)."""
    return curves_band_hz((data.impedance, data.displacement))


def curves_band_hz(curves) -> dict[str, list[float]]:
    """name -> [lowest, highest] line of each curve with lines (anything with `name` and `freqs`: a
    TransferFunction, a fit's ChannelFit), in Hz (JSON-ready)."""
    return {c.name: [float(c.freqs[0]), float(c.freqs[-1])] for c in curves if c is not None and len(c.freqs)}
