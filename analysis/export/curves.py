"""Curves for loudspeaker design programs: impedance as .zma, sound pressure as .frd.

Both are the plain text tables those programs read (and analysis.importers
reads back): comment lines starting with '*', a column header line, then one
line per frequency, blank-separated, decimal point '.':

    .zma   frequency [Hz]   |Z| [ohm]          phase of Z [degrees]
    .frd   frequency [Hz]   SPL [dB re 20 uPa]  phase of p [degrees]

Numbers are written with Python's shortest round-trip repr, so a curve read
back is the curve written, bit for bit. Measured curves are at the measured
lines; model curves on a logarithmic grid (MODEL_PER_DECADE lines a decade)
over the measured band only, where the model was fitted. The .frd is the
predicted far-field SPL of docs/physics.md section 4 (half space, SPL_DISTANCE_M,
SPL_VOLTAGE), which needs Hx (the laser) and Sd.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Iterable, Mapping

import numpy as np

from analysis.errors import LinparError
from analysis.export.registry import Exporter
from analysis.session import trace_line
from analysis.spl import predicted_spl

if TYPE_CHECKING:      # a type only: listing the formats (the CLI's parser) loads no archive
    from analysis.archive.results import StoredResult

MODEL_PER_DECADE = 100
SPL_VOLTAGE = 2.83
SPL_DISTANCE_M = 1.0


class ExportError(LinparError, ValueError):
    """The measurement lacks what an export needs (one line for the user)."""


def _model_grid(freqs: np.ndarray) -> np.ndarray:
    lo, hi = float(np.min(freqs)), float(np.max(freqs))
    return np.geomspace(lo, hi, max(2, int(round(np.log10(hi / lo) * MODEL_PER_DECADE)) + 1))


def _table(comments: Iterable[str], header: str, columns: Iterable[np.ndarray]) -> str:
    lines = [f"* {c}" for c in comments] + [f"* {header}"]
    for row in zip(*columns):
        lines.append(" ".join(repr(float(v)) for v in row))
    return "\n".join(lines) + "\n"


def _wrap_degrees(phase_rad: np.ndarray) -> np.ndarray:
    """Degrees in (-180, 180]: the range every reader accepts."""
    deg = np.degrees(np.angle(np.exp(1j * phase_rad)))
    return np.where(deg <= -180.0, deg + 360.0, deg)


def impedance_curve(result: StoredResult, which: str = "measured") -> tuple[np.ndarray, np.ndarray]:
    """(freqs in Hz, complex Z in ohm): the measured lines or the model on a dense grid."""
    c = result.curves.get("impedance")
    if c is None:
        raise ExportError("no impedance curve in this result")
    if which == "measured":
        return c.freqs, c.measured
    f = _model_grid(c.freqs)
    return f, result.model_curve("impedance", f)


def hx_curve(result: StoredResult, which: str = "measured") -> tuple[np.ndarray, np.ndarray]:
    """(freqs in Hz, complex Hx in m/V) for an SPL export; ExportError without Hx or Sd."""
    c = result.curves.get("displacement")
    if c is None:
        raise ExportError("SPL needs the displacement channel (Hx): this measurement has none")
    if not result.sd_m2:
        raise ExportError("SPL needs Sd, the effective radiating area: give it with --sd")
    if which == "measured":
        return c.freqs, c.measured
    f = _model_grid(c.freqs)
    return f, result.model_curve("displacement", f)


def zma_text(result: StoredResult, which: str = "measured", title: str = "") -> str:
    f, z = impedance_curve(result, which)
    comments = [f"linpar impedance, {which}" + (f": {title}" if title else ""),
                "columns: frequency [Hz], |Z| [ohm], phase [degrees]"]
    return _table(comments, "Freq(Hz) Z(ohm) Phase(deg)", (f, np.abs(z), _wrap_degrees(np.angle(z))))


def frd_text(result: StoredResult, which: str = "measured", title: str = "") -> str:
    f, hx = hx_curve(result, which)
    spl = predicted_spl(f, hx, result.sd_m2, SPL_VOLTAGE, SPL_DISTANCE_M)
    # p ~ s^2 * Hx: the pressure leads the displacement by 180 degrees.
    phase = _wrap_degrees(np.angle(hx) + np.pi)
    comments = [f"linpar predicted SPL, {which}" + (f": {title}" if title else ""),
                f"{SPL_VOLTAGE:g} V rms, {SPL_DISTANCE_M:g} m, half space, Sd = {result.sd_m2:g} m^2",
                "columns: frequency [Hz], SPL [dB re 20 uPa], phase [degrees]"]
    return _table(comments, "Freq(Hz) SPL(dB) Phase(deg)", (f, spl, phase))


def _curve_file(text, which: str):
    def write(result: StoredResult, header: Mapping) -> bytes:
        return text(result, which, trace_line(header)).encode("utf-8")
    return write


EXPORTERS = (
    Exporter("zma", "Measured impedance", ".zma", _curve_file(zma_text, "measured"), rank=20),
    Exporter("zma_model", "Modelled impedance", ".zma", _curve_file(zma_text, "model"), in_menu=False, rank=21),
    Exporter("frd", "Predicted SPL from the measured displacement", ".frd", _curve_file(frd_text, "measured"), rank=22),
    Exporter("frd_model", "Modelled SPL", ".frd", _curve_file(frd_text, "model"), in_menu=False, rank=23),
)
