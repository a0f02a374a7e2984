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
      "laser_out_of_range_share": 0.0                             share of laser measurements outside the range
    }

Laser measurements that are not distances (spec/laser-ild1420.md) are never
averaged into the signal: the runner holds the last valid distance in their
place and counts them here. Codes 262077/262078 (peak before / after the
range) are judged as out of range, the others as laser errors.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Mapping

from analysis.thresholds import ValidityThresholds
from analysis.validity_findings import (
    CLIPPING, DROPOUTS, HEADROOM_LOW, LASER_ERRORS, LASER_OUT_OF_RANGE, Finding, Severity)

SOUND_CARD_SIGNALS = ("voltage", "current")
OUT_OF_RANGE_CODES = (262077, 262078)


class CaptureInfoError(ValueError):
    """A "capture" object that cannot be read; the message names the key, on one line."""

    def __init__(self, message: str):
        super().__init__(" ".join(str(message).splitlines()))   # keys copied into it may hold line breaks


@dataclass(frozen=True, slots=True)
class CaptureInfo:
    full_scale_fraction: Mapping[str, float] = field(default_factory=dict)
    clipped_samples: Mapping[str, int] = field(default_factory=dict)
    dropouts: Mapping[str, int] = field(default_factory=dict)
    xruns: int = 0
    laser_samples: int = 0
    laser_error_counts: Mapping[int, int] = field(default_factory=dict)
    laser_out_of_range_share: float = 0.0

    def __post_init__(self) -> None:
        for name in ("full_scale_fraction", "clipped_samples", "dropouts", "laser_error_counts"):
            object.__setattr__(self, name, MappingProxyType(dict(getattr(self, name))))

    def as_json(self) -> dict[str, Any]:
        return {"full_scale_fraction": dict(self.full_scale_fraction),
                "clipped_samples": dict(self.clipped_samples), "dropouts": dict(self.dropouts),
                "xruns": self.xruns, "laser_samples": self.laser_samples,
                "laser_error_counts": {str(k): v for k, v in self.laser_error_counts.items()},
                "laser_out_of_range_share": self.laser_out_of_range_share}

    @classmethod
    def from_json(cls, doc: Any) -> "CaptureInfo":
        if not isinstance(doc, Mapping):
            raise CaptureInfoError(f"capture: found {type(doc).__name__}, expected an object")
        known = {"full_scale_fraction", "clipped_samples", "dropouts", "xruns", "laser_samples",
                 "laser_error_counts", "laser_out_of_range_share"}
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
                                             "capture.laser_out_of_range_share", float))


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
    if errors > 0:
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
