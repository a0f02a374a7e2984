"""The words of a report's customer page: parameters as the workstation names and orders them, the model by
what it includes, the recording by its file name, the calibration in a few lines of words.

The engineering detail (effect ids, the model's internal quantities, the fit's statistics and correlations,
the calibration's raw keys) goes to the report's appendix (analysis.report.content).
"""
from __future__ import annotations

import math
from pathlib import PurePath, PurePosixPath, PureWindowsPath
from typing import Any, Mapping

from analysis.derived import ParameterValue
from analysis.parameter_names import THIELE_SMALL, display_name
from analysis.report.numbers import format_number, parameter_cells

BASE_MODEL = "Lumped electro-mechanical model (Thiele-Small)"
SD_NOTE = "given, not measured"


def split_parameters(parameters: Mapping[str, ParameterValue], sd_m2: float | None
                     ) -> tuple[list[ParameterValue], list[ParameterValue]]:
    """(the Thiele-Small set in reading order with Sd among them, the model's internal quantities)."""
    named = dict(parameters)
    if sd_m2:
        named["Sd"] = ParameterValue("Sd", sd_m2, None, "m^2", "cm²", 1e4, reason=SD_NOTE)
    customer = [named[n] for n in THIELE_SMALL if n in named]
    internal = [p for n, p in named.items() if n not in THIELE_SMALL]
    return customer, internal


def model_title(effect_titles: list[str], with_displacement: bool) -> str:
    """"Lumped ... model with: voice-coil inductance losses, creep of the suspension": no file, no code id."""
    seen = " from voltage, current and cone displacement" if with_displacement else " from the impedance only"
    if not effect_titles:
        return BASE_MODEL + seen
    return f"{BASE_MODEL}{seen}, with: " + "; ".join(effect_titles)


def file_name(source: Any) -> str:
    """The recording's file name, never its folder (a temporary or private path means nothing to a customer)."""
    text = str(source or "").strip()
    if not text:
        return ""
    looks_like_path = (PurePosixPath(text).is_absolute() or PureWindowsPath(text).is_absolute()
                       or (not any(c.isspace() for c in text) and ("/" in text or "\\" in text)))
    if not looks_like_path:
        return text           # a description ("synthesized from ..."), not a file
    # Either separator: a Windows path read on Linux is still cut at its last folder.
    return PurePath(text.replace("\\", "/")).name


# The calibration's keys, as one line each: (words, unit, factor from SI to that unit).
_CALIBRATION_WORDS = {
    "volts_per_fs_out": ("Output: full scale at the driver's terminals", "V", 1.0),
    "volts_per_fs_voltage_sense": ("Voltage input: full scale", "V", 1.0),
    "volts_per_fs_current_sense": ("Current input: full scale of the sense amplifier", "V", 1.0),
    "shunt_ohm": ("Current shunt", "Ω", 1.0),
    "current_amp_gain": ("Current amplifier gain", "×", 1.0),
    "volts_per_fs_laser": ("Laser input: full scale", "V", 1.0),
    "laser_m_per_volt": ("Laser sensitivity", "mm/V", 1e3),
    "volts_per_fs": ("Input full scale", "V", 1.0),
}


def _calibration_numbers(calibration: Mapping, out: dict[str, float]) -> None:
    """Every known calibration key anywhere in the (nested) calibration document, the first one found."""
    for key, value in calibration.items():
        if isinstance(value, Mapping):
            _calibration_numbers(value, out)
        elif key in _CALIBRATION_WORDS and isinstance(value, (int, float)) and not isinstance(value, bool):
            if math.isfinite(value):
                out.setdefault(key, float(value))


def calibration_rows(calibration: Mapping | None) -> tuple[tuple[str, str], ...]:
    """A short table in words: what each input's full scale is, in its unit (the raw keys are in the appendix)."""
    numbers: dict[str, float] = {}
    _calibration_numbers(dict(calibration or {}), numbers)
    rows = []
    for key, (words, unit, factor) in _CALIBRATION_WORDS.items():
        if key in numbers:
            rows.append((words, f"{numbers[key] * factor:.4g} {unit}"))
    current = [numbers.get(k) for k in ("volts_per_fs_current_sense", "shunt_ohm", "current_amp_gain")]
    if all(v for v in current):
        rows.append(("Current input: full scale", f"{current[0] / (current[1] * current[2]):.4g} A"))
    laser = [numbers.get(k) for k in ("volts_per_fs_laser", "laser_m_per_volt")]
    if all(v for v in laser):
        rows.append(("Laser input: full scale", f"{laser[0] * laser[1] * 1e3:.4g} mm"))
    return tuple(rows) or (("Calibration", "not recorded with this measurement"),)


def parameter_row_cells(p: ParameterValue) -> tuple[str, str, str, str, str]:
    """(name as people say it, value rounded to its uncertainty, 1-sigma, unit, relative uncertainty)."""
    value, std, unit, relative = parameter_cells(p)
    return display_name(p.name), value, std, unit, relative


__all__ = ["BASE_MODEL", "calibration_rows", "file_name", "format_number", "model_title",
           "parameter_row_cells", "split_parameters"]
