"""Whether a measurement can be trusted, channel by channel (docs/physics.md section 5).

`assess(recording)` runs every check and returns a Validity:

- from the spectra (analysis.validity.spectral): no signal, SNR on the excited
  lines, noise + distortion on the unexcited lines, and for the displacement
  its usable band and the number of lines above the noise;
- from the periods (analysis.validity.drift): drift between the first and the
  last periods;
- from the capture (analysis.validity.capture, when a CaptureInfo is given or
  the recording's sidecar holds one under "capture"): clipping, headroom,
  dropouts, laser error codes and out-of-range share. A "capture" object
  that cannot be read raises CaptureInfoError (it names the key). The module
  is loaded only then: a recording without one does not pay for it.

Each channel's status is its worst finding (green when it has none); the
overall light is the worst channel's. A recording without displacement has
the displacement status "absent", which does not count towards the overall
light. `Validity.as_json()` is the checks' part of what `linpar analyze
--json` prints under "validity" (a result carries an
analysis.validity.result.ResultValidity, which adds what the fit found):

    {"overall": "green" | "yellow" | "red",
     "channels": {"voltage": {"status": ..., "findings": [{"code", "severity", "message", "remedy", "value"}]},
                  "current": {...}, "displacement": {...}},
     "peak_displacement_m": float | null}

Every limit is in analysis.thresholds.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING, Mapping, Sequence

from analysis.excursion import recording_peak_displacement
from analysis.recording.format import Recording
from analysis.spectra import Spectra, estimate_spectra
from analysis.thresholds import DEFAULT_THRESHOLDS, ValidityThresholds
from analysis.validity.drift import drift_findings
from analysis.validity.findings import Finding, Severity, worst
from analysis.validity.spectral import SIGNALS, spectral_checks

if TYPE_CHECKING:   # analysis.validity.capture is loaded when a capture is there to judge (start-up time)
    from analysis.validity.capture import CaptureInfo

__all__ = ["ABSENT", "ChannelValidity", "Finding", "Severity", "Validity", "assess", "capture_of"]

ABSENT = "absent"
CAPTURE_KEY = "capture"


@dataclass(frozen=True, slots=True)
class ChannelValidity:
    """One channel's light, its findings and the numbers the checks measured."""

    signal: str
    # "green" | "yellow" | "red" | "absent"; None for imported curves' channel, which carries findings alone
    status: str | None
    findings: tuple[Finding, ...] = ()
    # The numbers the checks measured (snr_db, distortion_db, x_band_hz, drift, ...): for the GUI, not the JSON.
    measures: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "measures", MappingProxyType(dict(self.measures)))

    def __reduce__(self):
        # A mapping proxy cannot be pickled (nor deep-copied): the measures as a dict, made read-only again.
        return ChannelValidity, (self.signal, self.status, self.findings, dict(self.measures))

    def as_json(self) -> dict:
        findings = [f.as_json() for f in self.findings]
        return {"findings": findings} if self.status is None else {"status": self.status, "findings": findings}


@dataclass(frozen=True, slots=True)
class Validity:
    """The checks' judgement of a recording: the overall light and each channel's (module doc)."""

    overall: Severity
    channels: Mapping[str, ChannelValidity]      # always voltage, current and displacement
    peak_displacement_m: float | None

    def __post_init__(self) -> None:
        object.__setattr__(self, "channels", MappingProxyType(dict(self.channels)))

    @property
    def findings(self) -> tuple[Finding, ...]:
        return tuple(f for ch in self.channels.values() for f in ch.findings)

    def codes(self, channel: str) -> set[str]:
        return {f.code for f in self.channels[channel].findings}

    def with_findings(self, extra: Mapping[str, Sequence[Finding]]) -> "Validity":
        """This validity with more findings on some channels (the fit's, analysis.validity.fit), lights redone."""
        channels = {}
        for name, ch in self.channels.items():
            added = tuple(extra.get(name, ()))
            if not added or ch.status == ABSENT:
                channels[name] = ch
                continue
            findings = ch.findings + added
            channels[name] = ChannelValidity(name, str(worst(f.severity for f in findings)), findings, ch.measures)
        overall = worst(Severity(ch.status) for ch in channels.values() if ch.status != ABSENT)
        return Validity(overall, channels, self.peak_displacement_m)

    def as_json(self) -> dict:
        peak = self.peak_displacement_m
        return {"overall": str(self.overall),
                "channels": {name: ch.as_json() for name, ch in self.channels.items()},
                "peak_displacement_m": peak if peak is not None and math.isfinite(peak) else None}


def capture_of(recording: Recording) -> CaptureInfo | None:
    """The CaptureInfo stored in the recording's sidecar, if any (CaptureInfoError if unreadable)."""
    doc = recording.extra.get(CAPTURE_KEY) if recording.extra else None
    if doc is None:
        return None
    from analysis.validity.capture import CaptureInfo
    return CaptureInfo.from_json(doc)


def assess(recording: Recording, spectra: Spectra | None = None, capture: CaptureInfo | None = None,
           thresholds: ValidityThresholds = DEFAULT_THRESHOLDS) -> Validity:
    """Every validity check on a recording (its spectra are computed unless given)."""
    if spectra is None:
        spectra = estimate_spectra(recording)
    if capture is None:
        capture = capture_of(recording)
    present = tuple(s for s in SIGNALS if s in spectra.channels)
    spectral = spectral_checks(spectra.channels, spectra.excited_bins, spectra.unexcited_bins,
                               spectra.bin_width, thresholds)
    drift = drift_findings(recording, spectra, thresholds)
    captured: dict[str, list[Finding]] = {}
    if capture is not None:
        from analysis.validity.capture import capture_findings
        x = recording.signal("displacement")
        captured = capture_findings(capture, present, 0 if x is None else x.size, thresholds)

    channels = {}
    for name in SIGNALS:
        if name not in present:
            channels[name] = ChannelValidity(name, ABSENT)
            continue
        findings, measures = spectral[name]
        drift_found, drift_value = drift[name]
        measures = {**measures, "drift": drift_value}
        everything = tuple(captured.get(name, [])) + tuple(findings) + tuple(drift_found)
        status = worst(f.severity for f in everything)
        channels[name] = ChannelValidity(name, str(status), everything, measures)
    overall = worst(Severity(ch.status) for ch in channels.values() if ch.status != ABSENT)
    return Validity(overall, channels, recording_peak_displacement(recording))
