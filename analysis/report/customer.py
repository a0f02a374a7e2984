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
        named["Sd"] = ParameterValue(name="Sd", value=sd_m2, std=None, unit="m^2", display_unit="cm²",
                                     display_scale=1e4, reason=SD_NOTE)
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


_CALIBRATION_KEYS = ("volts_per_fs_out", "volts_per_fs_voltage_sense", "volts_per_fs_current_sense", "shunt_ohm",
                     "current_amp_gain", "volts_per_fs_laser", "laser_m_per_volt", "volts_per_fs")


def _calibration_numbers(calibration: Mapping, out: dict[str, float]) -> None:
    """Every known calibration key anywhere in the (nested) calibration document, the first one found."""
    for key, value in calibration.items():
        if isinstance(value, Mapping):
            _calibration_numbers(value, out)
        elif key in _CALIBRATION_KEYS and isinstance(value, (int, float)) and not isinstance(value, bool):
            if math.isfinite(value):
                out.setdefault(key, float(value))


def _g(x: float) -> str:
    return f"{x:.4g}"


IMPORTED_CALIBRATION = "imported curves, read from a file: calibrated by whoever measured them, not by this workstation"


def calibration_rows(calibration: Mapping | None, imported: bool = False) -> tuple[tuple[str, str], ...]:
    """A short table in words: what full scale means on each channel, with how it was got (the raw keys are
    in the appendix). Imported curves have no calibration of ours to say: someone else's instrument measured them."""
    if imported:
        return (("Calibration", IMPORTED_CALIBRATION),)
    n: dict[str, float] = {}
    _calibration_numbers(dict(calibration or {}), n)
    rows = []
    if "volts_per_fs_out" in n:
        rows.append(("Output to the driver", f"{_g(n['volts_per_fs_out'])} V at full scale"))
    if "volts_per_fs_voltage_sense" in n:
        rows.append(("Voltage input", f"{_g(n['volts_per_fs_voltage_sense'])} V at full scale"))
    sense, shunt, gain = (n.get(k) for k in ("volts_per_fs_current_sense", "shunt_ohm", "current_amp_gain"))
    if sense and shunt and gain:
        rows.append(("Current input", f"{_g(sense / (shunt * gain))} A at full scale (shunt {_g(shunt)} Ω, "
                                      f"amplifier ×{_g(gain)}, {_g(sense)} V at the converter)"))
    laser_v, laser_m = n.get("volts_per_fs_laser"), n.get("laser_m_per_volt")
    if laser_v and laser_m:
        rows.append(("Laser input", f"{_g(laser_v * laser_m * 1e3)} mm at full scale ({_g(laser_v)} V, "
                                    f"{_g(laser_m * 1e3)} mm/V)"))
    if "volts_per_fs" in n:
        rows.append(("Inputs", f"{_g(n['volts_per_fs'])} V at full scale"))
    return tuple(rows) or (("Calibration", "not recorded with this measurement"),)


def parameter_row_cells(p: ParameterValue) -> tuple[str, str, str, str, str]:
    """(name as people say it, value rounded to its uncertainty, 1-sigma, unit, relative uncertainty)."""
    value, std, unit, relative = parameter_cells(p)
    return display_name(p.name), value, std, unit, relative


__all__ = ["BASE_MODEL", "calibration_rows", "file_name", "format_number", "model_title",
           "parameter_row_cells", "split_parameters"]
