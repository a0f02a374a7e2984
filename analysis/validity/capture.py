"""What the capture saw that the spectra cannot show: full scale, gaps, laser error codes.

The measurement runner fills a CaptureInfo while it records and stores it in
the recording's sidecar under the top-level key "capture" (CaptureInfo.as_json);
a recording without it (an imported one, a synthetic one) is judged on its
spectra alone.

Sidecar shape (every key optional):

    "capture": {
      "full_scale_fraction": {"voltage": 0.42, "current": 0.31},  peak |sample| / ADC full scale
      "clipped_samples":     {"voltage": 0},                      samples at full scale
      "dropouts":            {"displacement": 3},                 gaps filled in (lost blocks, lost laser samples)
      "xruns": 0,                                                 sound card over/underruns (voltage and current)
      "laser_samples": 262144,                                    laser measurements taken
      "laser_error_counts": {"262076": 12},                       error code -> measurements that carried it
      "laser_out_of_range_share": 0.0,                            share of laser measurements outside the range
      "laser_gaps": {"samples": 60, "periods": 2, "of_periods": 4,  laser samples without a distance, and
                     "longest_run": 30, "noise_factor": 1.03,       what leaving them out cost
                     "unseen_s": 0.0, "lost": 0, "outliers": 0}
    }

Laser measurements that are not distances (docs/laser-protocol.md) are never
averaged into the signal. The measurement runner treats them as missing data
(instruments/measurement/laser_gaps.py) and says in "laser_gaps" what that
cost: the displacement's noise grows by noise_factor (in variance), and
unseen_s of each period was measured in no period at all. The laser finding
then follows from that effect on the result; without "laser_gaps" (a
recording from elsewhere, which may have held or bridged them) from their
share alone. Codes 262077/262078 (peak before / after the range) are also
judged as out of range.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Mapping

from analysis.errors import LinparError
from analysis.thresholds import ValidityThresholds
from analysis.validity.findings import (
    CLIPPING, DROPOUTS, HEADROOM_LOW, LASER_ERRORS, LASER_OUT_OF_RANGE, Finding, Severity)

SOUND_CARD_SIGNALS = ("voltage", "current")
OUT_OF_RANGE_CODES = (262077, 262078)


class CaptureInfoError(LinparError, ValueError):
    """A "capture" object that cannot be read; the message names the key, on one line."""

    def __init__(self, message: str):
        super().__init__(" ".join(str(message).splitlines()))   # keys copied into it may hold line breaks


@dataclass(frozen=True, slots=True)
class LaserGapInfo:
    """What the laser did not deliver, and what leaving it out of the average cost (module doc)."""

    samples: int
    periods: int
    of_periods: int
    longest_run: int
    noise_factor: float | None      # None: no period measured some point twice, the noise is unknown there
    unseen_s: float
    lost: int = 0
    outliers: int = 0

    @property
    def uncertainty_growth(self) -> float:
        """How much wider the displacement's standard uncertainty is for the missing samples (0.1: 10 %)."""
        return math.inf if self.noise_factor is None else math.sqrt(max(self.noise_factor, 1.0)) - 1.0

    def as_json(self) -> dict[str, Any]:
        return {"samples": self.samples, "periods": self.periods, "of_periods": self.of_periods,
                "longest_run": self.longest_run, "noise_factor": self.noise_factor, "unseen_s": self.unseen_s,
                "lost": self.lost, "outliers": self.outliers}

    @classmethod
    def from_json(cls, doc: Any) -> "LaserGapInfo":
        if not isinstance(doc, Mapping):
            raise CaptureInfoError(f"capture.laser_gaps: found {type(doc).__name__}, expected an object")
        unknown = set(doc) - {f for f in cls.__slots__}
        if unknown:
            raise CaptureInfoError(f"capture.laser_gaps: unknown key(s) {', '.join(sorted(map(str, unknown)))}")
        ints = {name: _number(doc.get(name, 0), f"capture.laser_gaps.{name}", int)
                for name in ("samples", "periods", "of_periods", "longest_run", "lost", "outliers")}
        factor = doc.get("noise_factor")
        return cls(noise_factor=None if factor is None else _number(factor, "capture.laser_gaps.noise_factor",
                                                                    float),
                   unseen_s=_number(doc.get("unseen_s", 0.0), "capture.laser_gaps.unseen_s", float), **ints)


@dataclass(frozen=True, slots=True)
class CaptureInfo:
    full_scale_fraction: Mapping[str, float] = field(default_factory=dict)
    clipped_samples: Mapping[str, int] = field(default_factory=dict)
    dropouts: Mapping[str, int] = field(default_factory=dict)
    xruns: int = 0
    laser_samples: int = 0
    laser_error_counts: Mapping[int, int] = field(default_factory=dict)
    laser_out_of_range_share: float = 0.0
    laser_gaps: LaserGapInfo | None = None

    def __post_init__(self) -> None:
        for name in ("full_scale_fraction", "clipped_samples", "dropouts", "laser_error_counts"):
            object.__setattr__(self, name, MappingProxyType(dict(getattr(self, name))))

    def as_json(self) -> dict[str, Any]:
        return {"full_scale_fraction": dict(self.full_scale_fraction),
                "clipped_samples": dict(self.clipped_samples), "dropouts": dict(self.dropouts),
                "xruns": self.xruns, "laser_samples": self.laser_samples,
                "laser_error_counts": {str(k): v for k, v in self.laser_error_counts.items()},
                "laser_out_of_range_share": self.laser_out_of_range_share,
                **({} if self.laser_gaps is None else {"laser_gaps": self.laser_gaps.as_json()})}

    @classmethod
    def from_json(cls, doc: Any) -> "CaptureInfo":
        if not isinstance(doc, Mapping):
            raise CaptureInfoError(f"capture: found {type(doc).__name__}, expected an object")
        known = {"full_scale_fraction", "clipped_samples", "dropouts", "xruns", "laser_samples",
                 "laser_error_counts", "laser_out_of_range_share", "laser_gaps"}
        unknown = set(doc) - known
        if unknown:
            raise CaptureInfoError(f"capture: unknown key(s) {', '.join(sorted(map(str, unknown)))}")
        return cls(
            full_scale_fraction=_per_channel(doc, "full_scale_fraction", float),
            clipped_samples=_per_channel(doc, "clipped_samples", int),
            dropouts=_per_channel(doc, "dropouts", int),
            xruns=_number(doc.get("xruns", 0), "capture.xruns", int),
            laser_samples=_number(doc.get("laser_samples", 0), "capture.laser_samples", int),
            laser_error_counts={_code(k): _number(v, f"capture.laser_error_counts.{k}", int)
                                for k, v in _mapping(doc, "laser_error_counts").items()},
            laser_out_of_range_share=_number(doc.get("laser_out_of_range_share", 0.0),
                                             "capture.laser_out_of_range_share", float),
            laser_gaps=None if doc.get("laser_gaps") is None else LaserGapInfo.from_json(doc["laser_gaps"]))


def capture_findings(capture: CaptureInfo, present: tuple[str, ...], displacement_samples: int,
                     th: ValidityThresholds) -> dict[str, list[Finding]]:
    """Clipping, headroom, dropouts and laser findings per channel in `present`."""
    out: dict[str, list[Finding]] = {name: [] for name in present}
    for name in present:
        clipped = int(capture.clipped_samples.get(name, 0))
        peak = float(capture.full_scale_fraction.get(name, 0.0))
        if clipped > 0 or peak >= th.full_scale_red:
            out[name].append(Finding(
                name, CLIPPING, Severity.RED,
                f"{name}: {clipped} samples clipped, peak at {peak:.1%} of the input's full scale",
                f"lower the {name} input's gain (or the level) so that the peak stays below "
                f"{th.full_scale_yellow:.0%} of full scale", peak if clipped == 0 else 1.0))
        elif peak >= th.full_scale_yellow:
            out[name].append(Finding(
                name, HEADROOM_LOW, Severity.YELLOW,
                f"{name}: peak at {peak:.1%} of the input's full scale (less than "
                f"{-20 * math.log10(th.full_scale_yellow):.1f} dB headroom)",
                f"lower the {name} input's gain before raising the level", peak))
        gaps = int(capture.dropouts.get(name, 0)) + (capture.xruns if name in SOUND_CARD_SIGNALS else 0)
        if gaps > 0:
            out[name].append(Finding(
                name, DROPOUTS, Severity.RED,
                f"{name}: {gaps} dropouts during the recording (lost or filled-in blocks break the periodicity)",
                "repeat the measurement; close other programs or raise the audio buffer size", gaps))
    if "displacement" in present:
        out["displacement"] += _laser_findings(capture, displacement_samples, th)
    return out


def _laser_findings(capture: CaptureInfo, displacement_samples: int, th: ValidityThresholds) -> list[Finding]:
    findings = []
    total = capture.laser_samples or displacement_samples
    errors = sum(n for code, n in capture.laser_error_counts.items() if code not in OUT_OF_RANGE_CODES)
    beyond = sum(n for code, n in capture.laser_error_counts.items() if code in OUT_OF_RANGE_CODES)
    if capture.laser_gaps is not None:
        if capture.laser_gaps.samples > 0:
            findings.append(_gap_finding(capture, total, th))
    elif errors > 0:
        share = errors / total if total else 1.0
        codes = ", ".join(f"{code} x{n}" for code, n in sorted(capture.laser_error_counts.items())
                          if n and code not in OUT_OF_RANGE_CODES)
        severity = Severity.RED if share >= th.laser_error_red_share else Severity.YELLOW
        findings.append(Finding(
            "displacement", LASER_ERRORS, severity,
            f"displacement: {errors} laser measurements ({share:.3%}) were error codes, not distances ({codes})",
            "check the laser's aim and the cone's surface (a matt white dot helps), and that the baud rate "
            "carries the measuring rate", share))
    share = max(capture.laser_out_of_range_share, beyond / total if total else 0.0)
    if share > 0:
        severity = Severity.RED if share >= th.out_of_range_red_share else Severity.YELLOW
        findings.append(Finding(
            "displacement", LASER_OUT_OF_RANGE, severity,
            f"displacement: {share:.3%} of the laser measurements were outside its measuring range "
            f"(the cone left the range at its peaks)",
            "move the laser so that the cone at rest sits in the middle of its range, or lower the level", share))
    return findings


def _gap_finding(capture: CaptureInfo, total: int, th: ValidityThresholds) -> Finding:
    """The laser's missing samples judged by what leaving them out did to the result (module doc)."""
    gaps = capture.laser_gaps
    what = [f"error code {code} x{n}" for code, n in sorted(capture.laser_error_counts.items()) if n]
    what += [f"{gaps.lost} lost on the line"] if gaps.lost else []
    what += [f"{gaps.outliers} forged by line noise"] if gaps.outliers else []
    growth = gaps.uncertainty_growth
    unseen = gaps.unseen_s > th.laser_gap_unseen_red_s
    severity = (Severity.RED if unseen or growth >= th.laser_gap_growth_red else
                Severity.YELLOW if growth >= th.laser_gap_growth_yellow else Severity.GREEN)
    message = (f"displacement: {gaps.samples} of {total} laser measurements ({gaps.samples / max(total, 1):.2%}) "
               f"were not distances ({', '.join(what) or 'missing'}), in {gaps.periods} of {gaps.of_periods} "
               f"periods; left out of the average, they widen the displacement's uncertainty by "
               + (f"{growth:.1%}" if math.isfinite(growth) else "an unknown amount"))
    remedy = ("check the laser's aim and the cone's surface (a matt white dot helps), and that the baud rate "
              "carries the measuring rate")
    if unseen:
        message += (f"; {gaps.unseen_s * 1e3:.2f} ms of each period was measured in no period, and is only "
                    f"bridged")
        remedy = ("the laser lost the cone at the same point of every period: lower the level, or move the "
                  "laser so that the spot stays in its range; then " + remedy)
    return Finding("displacement", LASER_ERRORS, severity, message, remedy,
                   growth if math.isfinite(growth) else 1e9)


def _mapping(doc: Mapping, key: str) -> Mapping:
    value = doc.get(key, {})
    if not isinstance(value, Mapping):
        raise CaptureInfoError(f"capture.{key}: expected an object")
    return value


def _per_channel(doc: Mapping, key: str, kind: type) -> dict[str, Any]:
    return {str(ch): _number(v, f"capture.{key}.{ch}", kind) for ch, v in _mapping(doc, key).items()}


def _number(value: Any, where: str, kind: type):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not _finite(value) or value < 0:
        raise CaptureInfoError(f"{where}: found {value!r}, expected a non-negative number")
    if kind is int and value != int(value):
        raise CaptureInfoError(f"{where}: found {value!r}, expected a whole number")
    return kind(value)


def _finite(value: int | float) -> bool:
    try:
        return math.isfinite(value)
    except OverflowError:       # an integer beyond the float range
        return False


def _code(key: Any) -> int:
    try:
        return int(key)
    except (TypeError, ValueError):
        raise CaptureInfoError(f"capture.laser_error_counts: key {key!r} is not an error code") from None
