"""What a validity check reports: a finding with a traffic light, a stable code and a remedy."""
from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum
from typing import Iterable


class Severity(StrEnum):
    GREEN = "green"
    YELLOW = "yellow"
    RED = "red"

    @property
    def rank(self) -> int:
        return _RANK[self]


_RANK = {Severity.GREEN: 0, Severity.YELLOW: 1, Severity.RED: 2}

# The stable codes; the GUI and reports key their texts on these.
SNR_LOW = "snr-low"
DISTORTION_HIGH = "distortion-high"
NO_SIGNAL = "no-signal"
CLIPPING = "clipping"
HEADROOM_LOW = "headroom-low"
X_BAND_LOW = "x-band-low"
X_FEW_LINES = "x-few-lines"
LASER_ERRORS = "laser-errors"
LASER_OUT_OF_RANGE = "laser-out-of-range"
DROPOUTS = "dropouts"
DRIFT = "drift"
CHANNEL_COPY = "channel-copy"       # a scaled copy of another channel: a wiring fault (analysis.validity.wiring)
MODEL_MISFIT = "model-misfit"       # the fit's misfit far above the noise (analysis.validity.fit)
LASER_DELAY_NOT_FOUND = "laser-delay-not-found"   # a serial laser's delay the data cannot place (analysis.laser_delay)


@dataclass(frozen=True, slots=True)
class Finding:
    """One problem on one channel. A check that passes gives no finding."""

    channel: str            # "voltage" | "current" | "displacement"
    code: str
    severity: Severity
    message: str            # what was measured, with the numbers
    remedy: str             # what to do about it
    value: float            # the measured number the severity was decided on

    def as_json(self) -> dict:
        value = float(self.value)
        return {"code": self.code, "severity": str(self.severity), "message": self.message,
                "remedy": self.remedy, "value": value if math.isfinite(value) else None}


def worst(severities: Iterable[Severity]) -> Severity:
    """The worst light of several; green when there are none."""
    return max(severities, key=lambda s: s.rank, default=Severity.GREEN)


def graded(value: float, yellow: float, red: float, *, below: bool) -> Severity:
    """GREEN / YELLOW / RED for a value that is bad when below (or above) its limits."""
    if below:
        return Severity.RED if value < red else Severity.YELLOW if value < yellow else Severity.GREEN
    return Severity.RED if value >= red else Severity.YELLOW if value >= yellow else Severity.GREEN
