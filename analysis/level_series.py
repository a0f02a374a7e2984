"""A level series: the "linear" parameters against peak excursion (docs/physics.md section 6, the paper's Table II).

Measured at rising drive levels, the parameters a linear model fits drift: they
are weighted means of the nonlinear curves Bl(x), Kms(x), Le(x) over the
excursion the level reached (the paper: fs 70.5 -> 57.1 Hz, Cms +50 % from
0.17 mm to 8.6 mm peak). `level_series(results or paths)` puts one row per
level, sorted by peak excursion:

    drive level (V RMS), peak excursion, fs, Mms, Cms, Kms, Bl, Rms, RE, Qts, lambda (with 1-sigma),
    the drift of each relative to the smallest excursion,  d = 100 (p - p0) / p0  [%],
    with  sigma_d = 100 |p / p0| sqrt((s / p)^2 + (s0 / p0)^2)  (separate recordings: independent errors),

and the data of the paper's Fig. 14 (fs against peak excursion). A level is
small-signal when its validity is green and no channel reports distortion: the
validity's distortion check compares the unexcited lines with the noise floor,
so it says when the nonlinearity has risen out of the noise, whatever the
parameters did.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import MappingProxyType
from typing import Mapping, Sequence

import numpy as np

from analysis.derived import ParameterValue
from analysis.effects import Effect
from analysis.errors import LinparError
from analysis.pipeline import AnalysisResult, analyze_path, analyze_recording, require_fit
from analysis.recording.format import Recording
from analysis.validity.findings import DISTORTION_HIGH
from analysis.validity.result import ResultValidity

# The columns of the paper's Table II (and this module's), in order.
TABLE_PARAMETERS = ("fs", "Mms", "Cms", "Kms", "Bl", "Rms", "RE", "Qts", "lambda")
GREEN = "green"


class LevelSeriesError(LinparError, ValueError):
    """Results that cannot make a level series (none, or one without displacement). One line."""


@dataclass(frozen=True, slots=True, kw_only=True)
class Drift:
    percent: float
    std: float | None          # percent

    def as_json(self) -> dict:
        return {"percent": self.percent, "std": self.std}


@dataclass(frozen=True, slots=True, kw_only=True)
class Level:
    """One measurement of the series."""

    source: str | None
    drive_rms_v: float                       # AC RMS of the measured voltage's mean period
    peak_displacement_m: float
    parameters: Mapping[str, ParameterValue]  # TABLE_PARAMETERS the analysis gave, in that order
    validity: str                             # the overall light
    small_signal: bool
    reasons: tuple[str, ...] = ()             # why not small-signal ("distortion-high on current (red)", ...)
    drift: Mapping[str, Drift] = field(default_factory=dict)   # relative to the series' smallest level

    def __post_init__(self) -> None:
        object.__setattr__(self, "parameters", MappingProxyType(dict(self.parameters)))
        object.__setattr__(self, "drift", MappingProxyType(dict(self.drift)))

    def value(self, name: str) -> float | None:
        p = self.parameters.get(name)
        return None if p is None else p.value

    def as_json(self) -> dict:
        return {"source": self.source, "drive_rms_v": self.drive_rms_v,
                "peak_displacement_m": self.peak_displacement_m, "validity": self.validity,
                "small_signal": self.small_signal, "reasons": list(self.reasons),
                "parameters": {n: p.as_json() for n, p in self.parameters.items()},
                "drift": {n: d.as_json() for n, d in self.drift.items()}}


@dataclass(frozen=True, slots=True)
class LevelSeries:
    levels: tuple[Level, ...]               # by rising peak excursion; levels[0] is the drift's reference

    @property
    def reference(self) -> Level:
        return self.levels[0]

    def column(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """(values, 1-sigma) of one parameter over the levels, SI; NaN where missing."""
        values, stds = [], []
        for level in self.levels:
            p = level.parameters.get(name)
            values.append(np.nan if p is None or p.value is None else p.value)
            stds.append(np.nan if p is None or p.std is None else p.std)
        return np.array(values), np.array(stds)

    @property
    def peaks_m(self) -> np.ndarray:
        return np.array([level.peak_displacement_m for level in self.levels])

    def fs_curve(self) -> dict[str, list]:
        """The paper's Fig. 14: fs against peak excursion (SI), with which points are small-signal."""
        fs, fs_std = self.column("fs")
        return {"peak_displacement_m": self.peaks_m.tolist(), "fs_hz": fs.tolist(), "fs_std_hz": fs_std.tolist(),
                "small_signal": [level.small_signal for level in self.levels]}

    def as_json(self) -> dict:
        return {"n_levels": len(self.levels), "parameters": list(TABLE_PARAMETERS),
                "reference": 0, "levels": [level.as_json() for level in self.levels],
                "fs_vs_peak": self.fs_curve()}


def level_series(items: Sequence[AnalysisResult | Recording | str | Path], sd_m2: float | None = None,
                 effects: Sequence[Effect] | None = None) -> LevelSeries:
    """The series of analysed results, or of recordings (in memory or paths) analysed here, by peak excursion.

    sd_m2 and effects apply to what is analysed here, not to results given analysed.
    """
    if not items:
        raise LevelSeriesError("a level series needs at least one recording")
    results = [_analysed(item, sd_m2, effects) for item in items]
    unsorted = [_level(result, i) for i, result in enumerate(results)]
    # A stable sort: equal peaks keep the given order.
    ordered = sorted(unsorted, key=lambda level: level.peak_displacement_m)
    reference = ordered[0]
    return LevelSeries(tuple(_with_drift(level, reference) for level in ordered))


def drive_rms(result: AnalysisResult) -> float:
    """AC RMS of the voltage's coherent mean period, V (a voltmeter's reading of the drive, DC excluded)."""
    mean = result.spectra.channels["voltage"].mean
    # One-sided peak amplitudes (analysis.spectra.period_spectra): a line of amplitude A carries A^2 / 2;
    # the Nyquist bin of an even period, A cos(pi n), carries A^2.
    power = np.sum(np.abs(mean[1:]) ** 2) / 2.0
    if result.spectra.period_samples % 2 == 0:
        power += np.abs(mean[-1]) ** 2 / 2.0
    return float(math.sqrt(power))


def small_signal_reasons(validity: ResultValidity) -> tuple[str, ...]:
    """Why a result's validity (AnalysisResult.validity) says it is not small-signal; () when it is."""
    reasons = []
    for name, channel in validity.channels.items():
        for f in channel.findings:
            if f.code == DISTORTION_HIGH:
                reasons.append(f"{DISTORTION_HIGH} on {name} ({f.severity})")
    overall = validity.overall
    if overall != GREEN:
        others = sorted({f.code for f in validity.findings if f.code != DISTORTION_HIGH})
        if others or not reasons:
            reasons.append(f"validity {overall}" + (f": {', '.join(others)}" if others else ""))
    return tuple(reasons)


def _analysed(item, sd_m2: float | None, effects: Sequence[Effect] | None) -> AnalysisResult:
    if isinstance(item, AnalysisResult):
        result = item
    elif isinstance(item, Recording):
        result = analyze_recording(item, sd_m2, effects)
    else:
        result = analyze_path(item, sd_m2, effects)
    require_fit(result, "be a level of the series")
    return result


def _level(result: AnalysisResult, index: int) -> Level:
    name = str(result.source) if result.source else None
    peak = result.validity.peak_displacement_m
    if peak is None or not math.isfinite(peak):
        label = result.source.name if result.source else f"result {index + 1}"
        raise LevelSeriesError(f"{label}: no displacement channel: a level series is sorted by the peak "
                               f"excursion, which needs the laser")
    parameters = {n: result.parameters[n] for n in TABLE_PARAMETERS if n in result.parameters}
    reasons = small_signal_reasons(result.validity)
    return Level(source=name, drive_rms_v=drive_rms(result), peak_displacement_m=float(peak), parameters=parameters,
                 validity=str(result.validity.overall), small_signal=not reasons, reasons=reasons)


def _with_drift(level: Level, reference: Level) -> Level:
    drift = {}
    for name, p in level.parameters.items():
        p0 = reference.parameters.get(name)
        if p.value is None or p0 is None or p0.value is None or p0.value == 0:
            continue
        ratio = p.value / p0.value
        std = None
        if level is not reference and p.std is not None and p0.std is not None and p.value != 0:
            std = 100.0 * abs(ratio) * math.hypot(p.std / p.value, p0.std / p0.value)
        drift[name] = Drift(percent=100.0 * (ratio - 1.0), std=0.0 if level is reference else std)
    return replace(level, drift=drift)


# --- text ----------------------------------------------------------------------------------------

def concise(value: float | None, std: float | None) -> str:
    """value(uncertainty) in the last two digits, as metrology writes it: 70.561(12), 0.4296(21)."""
    if value is None or not math.isfinite(value):
        return "n/a"
    if std is None or not math.isfinite(std) or std <= 0:
        return f"{value:.5g}"
    decimals = 1 - math.floor(math.log10(std))
    if decimals <= 0:            # sigma >= 10: whole units, the uncertainty written out
        return f"{value:.0f}({std:.0f})"
    if decimals > 12:
        return f"{value:.6g}"
    return f"{value:.{decimals}f}({round(std * 10 ** decimals):d})"


def format_series(series: LevelSeries) -> str:
    """Table II as text: one row per level (customary units), then the drift in percent of the smallest level."""
    names = [n for n in TABLE_PARAMETERS if any(n in level.parameters for level in series.levels)]
    units = {}
    for level in series.levels:
        for n in names:
            if n in level.parameters:
                units.setdefault(n, level.parameters[n].display_unit)
    width = 13
    head = f"{'level V':>8}{'peak mm':>9}  {'small':<6}" + "".join(f"{n:>{width}}" for n in names)
    unit_row = f"{'RMS':>8}{'':>9}  {'signal':<6}" + "".join(f"{'[' + units[n] + ']':>{width}}" for n in names)
    lines = [f"{len(series.levels)} levels, sorted by peak excursion", head, unit_row]
    for level in series.levels:
        cells = []
        for n in names:
            p = level.parameters.get(n)
            scale = p.display_scale if p is not None else 1.0
            cells.append(concise(None if p is None or p.value is None else p.value * scale,
                                 None if p is None or p.std is None else p.std * abs(scale)))
        lines.append(f"{level.drive_rms_v:>8.3g}{level.peak_displacement_m * 1e3:>9.3f}  "
                     f"{'yes' if level.small_signal else 'no':<6}" + "".join(f"{c:>{width}}" for c in cells))
    lines += ["", "drift relative to the smallest level, %",
              f"{'level V':>8}{'peak mm':>9}  {'':<6}" + "".join(f"{n:>{width}}" for n in names)]
    for level in series.levels:
        cells = [concise(level.drift[n].percent, level.drift[n].std) if n in level.drift else "n/a" for n in names]
        lines.append(f"{level.drive_rms_v:>8.3g}{level.peak_displacement_m * 1e3:>9.3f}  {'':<6}"
                     + "".join(f"{c:>{width}}" for c in cells))
    flagged = [level for level in series.levels if not level.small_signal]
    if flagged:
        lines += ["", "not small-signal:"]
        lines += [f"  {level.drive_rms_v:.3g} V, {level.peak_displacement_m * 1e3:.3f} mm: {'; '.join(level.reasons)}"
                  for level in flagged]
    return "\n".join(lines)
