"""The ILD1420's analog output read by a sound-card input.

Then there is no serial stream, no counter and no time stamp: the
displacement is just another audio channel, already aligned with the
excitation by the sound card. What is left is the scale. The sensor maps its
measuring range linearly onto its output (e.g. 0-10 V, or 4-20 mA across a
shunt); the sound card's own gain is part of ``m_per_volt``, so calibrate the
chain as a whole (a gauge block at two positions), not from the datasheet.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, slots=True)
class AnalogLaserScale:
    """distance_m = offset_m + m_per_volt * volts."""

    m_per_volt: float
    offset_m: float = 0.0

    def to_metres(self, volts: np.ndarray) -> np.ndarray:
        return self.offset_m + self.m_per_volt * np.asarray(volts, dtype=np.float64)

    @classmethod
    def from_two_points(cls, volts_a: float, metres_a: float,
                        volts_b: float, metres_b: float) -> AnalogLaserScale:
        """The scale through two calibration points (e.g. two gauge blocks)."""
        if volts_a == volts_b:
            raise ValueError("two calibration points need two different voltages")
        slope = (metres_b - metres_a) / (volts_b - volts_a)
        return cls(m_per_volt=slope, offset_m=metres_a - slope * volts_a)
