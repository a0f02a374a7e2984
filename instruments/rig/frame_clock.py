"""The emulated hardware's one clock: the audio frame counter, placed on the host's time line.

Everything an emulation simulates happens at an audio frame: the rig's cone
is at frame f where its FIR put it, the emulated laser takes sample k at
frame offset + ratio * k. Host times are only how the emulation tells the
workstation when a block or a measurement arrives, and they follow from the
frames through one straight line,

    host time of frame f = t0 + f / sample_rate,

never from when an emulator's thread happened to wake up. So what a test
checks (where laser sample k sits in the excitation, what delay the fit must
find) is the same on an idle and on a busy machine; only the workstation's
own threads (its audio pump, its laser reader) see real wake-ups, and the
workstation has to cope with those as it would with real hardware.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, slots=True)
class FrameClock:
    """host time (time.monotonic seconds) = t0 + frame / sample_rate."""

    t0: float
    sample_rate: float

    def host_time(self, frame) -> np.ndarray | float:
        return self.t0 + np.asarray(frame, dtype=np.float64) / self.sample_rate

    def frame_at(self, host_time) -> np.ndarray | float:
        return (np.asarray(host_time, dtype=np.float64) - self.t0) * self.sample_rate
