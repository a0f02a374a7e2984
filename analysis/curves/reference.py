"""The exporting tool's own fitted curve (a Klippel LPM export's "Fitted" columns) beside linpar's fit.

An LPM export carries LPM's fitted |Z| and |Hx| beside the measured ones (analysis.importers.lpm keeps them
as the curve's reference). For each channel fitted, over its fitted band: how far the tool's fitted curve
misses the measured one (its fit error, as LPM prints it), how far linpar's does, and how far the two fitted
curves are apart, each the rms of the magnitude ratio minus one, in %.
"""
from __future__ import annotations

from typing import Mapping

import numpy as np

from analysis.fit.least_squares import FitResult
from analysis.spectra import TransferFunction


def _rms_percent(a: np.ndarray, b: np.ndarray) -> float:
    return float(100.0 * np.sqrt(np.mean((np.abs(a) / np.abs(b) - 1.0) ** 2)))


def compare_with_reference(fit: FitResult, references: Mapping[str, TransferFunction | None]) -> dict:
    """{channel: {"band_hz", "tool_fit_error_percent", "linpar_fit_error_percent", "tool_vs_linpar_percent"}}."""
    out = {}
    for name, channel in fit.channels.items():
        ref = references.get(name)
        if ref is None:
            continue
        inside = (channel.freqs >= ref.freqs[0]) & (channel.freqs <= ref.freqs[-1])
        if inside.sum() < 2:
            continue
        f = channel.freqs[inside]
        tool = np.interp(np.log(f), np.log(ref.freqs), np.abs(ref.value))
        measured, model = np.abs(channel.measured[inside]), np.abs(channel.model[inside])
        out[name] = {"band_hz": [float(f[0]), float(f[-1])],
                     "tool_fit_error_percent": _rms_percent(tool, measured),
                     "linpar_fit_error_percent": _rms_percent(model, measured),
                     "tool_vs_linpar_percent": _rms_percent(model, tool)}
    return out


def comparison_words(name: str, c: Mapping) -> str:
    """One line on one channel (`compare_with_reference`'s entry): the CLI, the Results page and the report say it."""
    return f"the export's own fit of {name}, {comparison_detail(c)}"


def comparison_detail(c: Mapping) -> str:
    """"5-180 Hz: fit error 1.2 % (linpar's 0.8 %), 0.9 % rms from linpar's fitted curve"."""
    from analysis.report.numbers import readable_number as n      # never Python's exponent for people
    return (f"{c['band_hz'][0]:.4g}-{c['band_hz'][1]:.4g} Hz: fit error {n(c['tool_fit_error_percent'])} % "
            f"(linpar's {n(c['linpar_fit_error_percent'])} %), {n(c['tool_vs_linpar_percent'])} % rms from "
            "linpar's fitted curve")
