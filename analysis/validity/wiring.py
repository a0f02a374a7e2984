"""A channel that is a scaled copy of another: a wiring fault, not a measurement.

Two inputs wired to the same sense (the current input on the voltage sense,
the laser input on the current's) record the same signal up to a gain. For
the impedance that is Z = U / I constant at every line, to the noise: a
reduced chi^2 of 1e10 once fitted, yet every spectral check is green, since
each channel on its own is a clean, strong signal. No driver gives that: the
motional branch alone moves |Z| by a factor of 2 to 10 around the resonance,
and Hx falls by 40 dB per decade above it.

For a pair (x, y) of channels with a signal, over the excited lines, the
best complex gain a = sum(conj(x) y) / sum(|x|^2) leaves

    r = sum |y - a x|^2 / sum |y|^2          (0 for an exact copy, ~1/SNR for a noisy one)

and r below `copy_residual_red` (analysis.thresholds) is a red finding on y:
the current for (voltage, current), the displacement for the other pairs.
A resistor in place of the driver gives the same finding, and rightly so: it
has no driver parameters to give.
"""
from __future__ import annotations

from typing import Mapping

import numpy as np

from analysis.thresholds import ValidityThresholds
from analysis.validity.findings import CHANNEL_COPY, Finding, Severity

# (reference, copy suspect): the finding goes on the second.
PAIRS = (("voltage", "current"), ("voltage", "displacement"), ("current", "displacement"))
_UNITS = {("voltage", "current"): "Ω", ("voltage", "displacement"): "m/V", ("current", "displacement"): "m/A"}
_REMEDY = {
    "current": "check the wiring: the current input may be connected to the voltage sense, or a resistor sits "
               "where the driver should be",
    "displacement": "check the wiring: the laser input may be connected to the voltage or current sense",
}


def copy_findings(lines: Mapping[str, np.ndarray], silent: set[str], th: ValidityThresholds) -> dict[str, Finding]:
    """The channel-copy finding of each channel that copies another (at most one per channel), from each
    channel's coherent mean at the excited lines."""
    found: dict[str, Finding] = {}
    far = _far_from_copies(lines, th)
    power: dict[str, float] = {}
    for reference, suspect in PAIRS:
        if suspect in found or reference not in lines or suspect not in lines or {reference, suspect} & silent:
            continue
        if (reference, suspect) in far:
            continue
        for name in (reference, suspect):
            if name not in power:
                power[name] = float(np.sum(np.abs(lines[name]) ** 2))
        x, y = lines[reference], lines[suspect]
        x_power, y_power = power[reference], power[suspect]
        if not (x_power > 0 and y_power > 0 and np.isfinite(x_power) and np.isfinite(y_power)):
            continue
        gain = complex(np.sum(np.conj(x) * y) / x_power)
        residual = float(np.sum(np.abs(y - gain * x) ** 2) / y_power)
        if residual >= th.copy_residual_red:
            continue
        ratio = 1.0 / abs(gain) if suspect == "current" else abs(gain)
        what = (f"the impedance is {ratio:.4g} Ω at every line" if suspect == "current"
                else f"{suspect} / {reference} is {ratio:.4g} {_UNITS[(reference, suspect)]} at every line")
        found[suspect] = Finding(
            suspect, CHANNEL_COPY, Severity.RED,
            f"{suspect}: a scaled copy of the {reference}: {what}, which no driver gives (rms deviation "
            f"{100 * residual ** 0.5:.2g} %; limit: red below {100 * th.copy_residual_red ** 0.5:.2g} %)",
            _REMEDY[suspect], residual)
    return found


def _far_from_copies(lines: Mapping[str, np.ndarray], th: ValidityThresholds) -> set[tuple[str, str]]:
    """The pairs whose residual is surely above the limit, from one product of every channel's lines with
    every other's: r = 1 - |sum(conj(x) y)|^2 / (sum|x|^2 sum|y|^2), the same residual to float64 rounding
    (~1e-15 off). A measurement of a driver leaves r of order 0.1-1 for every pair, so the residuals
    themselves (one pass over each pair's lines, ~0.1 ms a live frame for the three) are worked out only
    near the limit, where a finding's numbers must be the residual's own. A NaN leaves its pairs to them."""
    names = [name for name in lines]
    stacked = np.stack([lines[name] for name in names])
    gram = stacked.conj() @ stacked.T                   # gram[i, j] = sum(conj(x_i) x_j)
    power = gram.diagonal().real
    with np.errstate(divide="ignore", invalid="ignore"):
        residual = 1.0 - (gram.real ** 2 + gram.imag ** 2) / np.outer(power, power)
    margin = 2.0 * th.copy_residual_red + 1e-9
    index = {name: i for i, name in enumerate(names)}
    return {(a, b) for a, b in PAIRS if a in index and b in index and residual[index[a], index[b]] > margin}
