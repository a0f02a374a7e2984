"""What one capture returns: the whole periods in SI units and how the capture went (no device code here)."""
from __future__ import annotations

from dataclasses import asdict, dataclass
from enum import StrEnum
from typing import Any, Mapping

import numpy as np

CLIP_LEVEL = 0.999   # |sample| at or above this (FS) counts as clipped


class CaptureEnd(StrEnum):
    """How a capture ended (instruments.audio.capture_loop.capture)."""

    COMPLETE = "complete"
    CANCELLED = "cancelled"
    FAILED = "failed"           # CaptureStats.failure says what went wrong


@dataclass(frozen=True, slots=True, kw_only=True)
class CaptureStats:
    """How a capture went. Counts are samples unless named otherwise."""

    sample_rate: int
    period_samples: int
    periods_kept: int
    fade_samples: int             # fade-in length; the fade is part of the discarded settle
    settle_samples: int           # asked-for settle after the fade (and after the first signal)
    discarded_samples: int        # input samples before the first kept one (fade + settle + latency)
    samples_received: int
    samples_lost: int             # gaps in the sample counter (blocks dropped on a full queue)
    gaps: int
    queue_overflows: int          # blocks the callback dropped
    input_overflows: int          # PortAudio status flags, counted per callback
    input_underflows: int
    output_underflows: int
    output_overflows: int
    restarts: int                 # times the kept periods were discarded after an xrun
    output_clipped_samples: int   # samples of one period above output full scale (clipped)
    output_peak_fs: float         # the requested output peak, FS
    clipped_inputs: tuple[tuple[str, int], ...]   # (signal, samples at >= CLIP_LEVEL FS) in kept periods
    full_scale_fraction: tuple[tuple[str, float], ...]   # (signal, peak |sample| / FS) in kept periods
    silent_channels: tuple[str, ...]              # signals exactly zero in every kept sample
    device: str = ""
    ended_by: CaptureEnd = CaptureEnd.COMPLETE
    failure: str = ""             # FAILED: the AudioError's words (the device stopped, too many dropouts, ...)

    @property
    def xruns(self) -> int:
        return self.input_overflows + self.input_underflows + self.output_underflows + self.output_overflows

    @property
    def dropouts(self) -> int:
        return self.xruns + self.gaps

    def problems(self) -> list[str]:
        """One line per thing the user should know, empty when the capture was clean."""
        out = []
        if self.output_clipped_samples:
            out.append(f"output clipped: the excitation asks for {self.output_peak_fs:.2f} FS, "
                       f"{self.output_clipped_samples} samples per period above full scale (lower the level)")
        for signal, count in self.clipped_inputs:
            if count:
                out.append(f"input {signal} clipped on {count} samples (lower the level or the input gain)")
        for signal in self.silent_channels:
            out.append(f"input {signal} is silent (exact zeros): nothing connected?")
        if self.xruns:
            out.append(f"{self.xruns} xrun(s) reported by the audio driver; {self.restarts} restart(s) of the "
                       f"averaging")
        if self.samples_lost:
            out.append(f"{self.samples_lost} input samples lost in {self.gaps} gap(s) (the measurement thread "
                       f"fell behind)")
        return out

    def as_dict(self) -> dict[str, Any]:
        """Every count, for the sidecar's "audio_capture" object. Its "ended_by" is "complete", "cancelled" or,
        for a failed capture, the failure's words (as the sidecars written before CaptureEnd say it)."""
        d = asdict(self)
        failure = d.pop("failure")
        d["ended_by"] = failure if self.ended_by is CaptureEnd.FAILED else str(self.ended_by)
        d["clipped_inputs"] = dict(self.clipped_inputs)
        d["full_scale_fraction"] = dict(self.full_scale_fraction)
        d["silent_channels"] = list(self.silent_channels)
        return d

    def capture_info(self) -> dict[str, Any]:
        """The recording sidecar's "capture" object (analysis.validity.capture.CaptureInfo).

        Dropouts and xruns are those inside the kept periods: always none,
        since a period with a gap is dropped and an xrun discards every period
        kept before it (instruments.audio.periods). How often that happened is
        in the "audio_capture" object (``as_dict``).
        """
        return {"full_scale_fraction": dict(self.full_scale_fraction),
                "clipped_samples": dict(self.clipped_inputs),
                "dropouts": {signal: 0 for signal, _ in self.clipped_inputs}, "xruns": 0}


@dataclass(frozen=True, slots=True, eq=False, kw_only=True)
class CapturedSignals:
    """Whole periods in SI units: voltage (V), current (A), displacement (m) or None. Read-only."""

    sample_rate: int
    period_samples: int
    voltage: np.ndarray
    current: np.ndarray
    displacement: np.ndarray | None
    stats: CaptureStats

    @property
    def n_periods(self) -> int:
        return self.voltage.size // self.period_samples

    def signals(self) -> dict[str, np.ndarray]:
        """Name -> samples, as analysis.recording.format.make_recording takes them."""
        out = {"voltage": self.voltage, "current": self.current}
        if self.displacement is not None:
            out["displacement"] = self.displacement
        return out

    def to_recording(self, excited_bins=None, driver: Mapping | None = None):
        """An analysis Recording of these periods (no settle left in them).

        The sidecar gets "capture" (what analysis.validity.assessment reads) and
        "audio_capture" (every count of CaptureStats, for the report).
        """
        from analysis.recording.format import make_recording
        return make_recording(self.sample_rate, self.signals(), self.period_samples, settle_periods=0,
                              excited_bins=None if excited_bins is None else tuple(int(b) for b in excited_bins),
                              driver=dict(driver or {}),
                              extra={"capture": self.stats.capture_info(), "audio_capture": self.stats.as_dict()})
