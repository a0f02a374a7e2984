"""What the results page draws, computed from an AnalysisResult (no Qt here).

The fit gives the model only at the measured lines; a smooth model line needs
it on a dense grid, and phases need unwrapping consistently between the
measured points and the model line. Computed in the worker thread and handed
over frozen, so the GUI thread only draws.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.pipeline import AnalysisResult

DENSE_POINTS = 600


@dataclass(frozen=True, slots=True)
class ChannelCurves:
    """One transfer function: measured lines, model at those lines and on a dense grid."""

    name: str                  # "impedance" | "displacement"
    freqs: np.ndarray          # Hz, measured lines
    measured: np.ndarray       # complex, SI (ohm or m/V)
    std: np.ndarray            # complex standard uncertainty per line
    residual: np.ndarray       # complex, (model - measured) per component in units of sigma
    chi2_red: float
    dense_freqs: np.ndarray
    dense_model: np.ndarray    # complex, SI
    has_phase: bool = True     # False: magnitude-only curves (imported), `measured` holds |value|

    def measured_phase_deg(self) -> np.ndarray:
        return aligned_phase_deg(self.measured, self.dense_freqs, self.dense_phase_deg(), self.freqs)

    def dense_phase_deg(self) -> np.ndarray:
        return np.degrees(np.unwrap(np.angle(self.dense_model)))

    def phase_std_deg(self) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.degrees(self.std / np.abs(self.measured))


@dataclass(frozen=True, slots=True)
class ResultCurves:
    impedance: ChannelCurves
    displacement: ChannelCurves | None


def aligned_phase_deg(values: np.ndarray, ref_freqs: np.ndarray, ref_phase_deg: np.ndarray,
                      freqs: np.ndarray) -> np.ndarray:
    """Unwrapped phase of `values`, shifted by whole turns to lie on the reference curve.

    Measured lines unwrapped on their own could start one turn away from the
    model line (noise at a wrap point); the shift keeps both on one branch.
    """
    phase = np.degrees(np.unwrap(np.angle(values)))
    if phase.size == 0:
        return phase
    ref = np.interp(freqs, ref_freqs, ref_phase_deg)
    turns = np.round(np.median(ref - phase) / 360.0)
    return phase + 360.0 * turns


def _channel(result: AnalysisResult, name: str, dense: np.ndarray) -> ChannelCurves | None:
    fit = result.fit.channels.get(name)
    if fit is None:
        return None
    s = 2j * np.pi * dense
    model = result.fit.model
    values = result.fit.values
    dense_model = model.impedance(s, values) if name == "impedance" else model.displacement(s, values)
    return ChannelCurves(name, fit.freqs, fit.measured, fit.std, fit.normalized_residual, fit.chi2_red,
                         dense, dense_model, bool(getattr(fit, "has_phase", True)))


def result_curves(result: AnalysisResult, points: int = DENSE_POINTS) -> ResultCurves | None:
    """The curves of a fitted result; None when nothing was fitted (a broken measurement, judged)."""
    if result.fit is None:
        return None
    freqs = result.fit.channels["impedance"].freqs
    dense = np.geomspace(freqs.min(), freqs.max(), points)
    return ResultCurves(_channel(result, "impedance", dense), _channel(result, "displacement", dense))
