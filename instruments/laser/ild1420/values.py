"""What the ILD1420's 18-bit output values mean.

Every value on the RS422 line is an 18-bit word (see ``frames.py`` for how it
is cut into bytes). Depending on its slot in a measurement it is a distance
(or an error code in its place), a measurement counter, or one 16-bit half of
a time stamp. This module turns those words into SI numbers and back, and
received measurements into the LaserBlocks every sensor delivers; it knows
nothing of bytes, ports or threads.
"""

from __future__ import annotations

import enum
from typing import TYPE_CHECKING

import numpy as np

from instruments.laser.sensor import NO_COUNTER, LaserBlock

if TYPE_CHECKING:
    from instruments.laser.ild1420.frames import RawMeasurements

#: Distance words from the manual: x in [X_MIN, X_MAX] is the measuring range,
#: 0..X_MIN-1 and X_MAX+1..65535 are the reserves at either end.
X_MIN = 643
X_MAX = 64877
X_FULL_SCALE = 65535
_X_SPAN = 65520.0
_X_GAIN = 1.02
_X_OFFSET = 0.01

#: The counter is 18 bits wide and wraps from 262143 back to 0.
COUNTER_MODULUS = 1 << 18
#: Time stamps count 10 us ticks in two 16-bit words, lo first.
TIMESTAMP_TICKS_PER_MS = 100
TIMESTAMP_MODULUS = 1 << 32


class LaserErrorCode(enum.IntEnum):
    """Codes the sensor sends in place of a distance word."""

    TOO_MUCH_DATA = 262075
    NO_PEAK = 262076
    PEAK_BEFORE_RANGE = 262077
    PEAK_AFTER_RANGE = 262078
    CANNOT_CALCULATE = 262080
    PEAK_TOO_LARGE = 262081
    LASER_OFF = 262082

    @property
    def description(self) -> str:
        return _DESCRIPTIONS[self]


_DESCRIPTIONS = {
    LaserErrorCode.TOO_MUCH_DATA: "too much data for the selected baud rate",
    LaserErrorCode.NO_PEAK: "no peak: target missing or too dark",
    LaserErrorCode.PEAK_BEFORE_RANGE: "peak before the measuring range (target too close)",
    LaserErrorCode.PEAK_AFTER_RANGE: "peak after the measuring range (target too far)",
    LaserErrorCode.CANNOT_CALCULATE: "measured value cannot be calculated",
    LaserErrorCode.PEAK_TOO_LARGE: "peak too large: target too bright or too close",
    LaserErrorCode.LASER_OFF: "laser is off",
}

#: Distance words above this are never distances (16-bit x), whatever code
#: they carry: an unknown code is still an error, not a far target.
_LARGEST_DISTANCE_WORD = X_FULL_SCALE


def describe_error(code: int) -> str:
    """A sentence for an error code, also for codes the manual does not list."""
    try:
        return LaserErrorCode(code).description
    except ValueError:
        return f"unknown error code {code}"


def x_to_distance_m(x: np.ndarray, measuring_range_m: float) -> np.ndarray:
    """Distance in metres from 16-bit words: d = (x*1.02/65520 - 0.01)*MR."""
    x = np.asarray(x, dtype=np.float64)
    return (x * _X_GAIN / _X_SPAN - _X_OFFSET) * measuring_range_m


def distance_to_x(distance_m: np.ndarray, measuring_range_m: float) -> np.ndarray:
    """The inverse of ``x_to_distance_m``, rounded, *not* clipped: values
    outside 0..65535 cannot be sent and callers turn them into error codes."""
    d = np.asarray(distance_m, dtype=np.float64)
    return np.rint((d / measuring_range_m + _X_OFFSET) * _X_SPAN / _X_GAIN).astype(np.int64)


def decode_distance(
    words: np.ndarray, measuring_range_m: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Split distance-slot words into (distance_m, error_code, in_range).

    Errors get NaN distance and their code (0 = valid); the reserves are real
    distances but flagged ``in_range = False`` so they can be counted in the
    validity check rather than silently averaged.
    """
    words = np.asarray(words, dtype=np.int64)
    is_error = words > _LARGEST_DISTANCE_WORD
    distance = x_to_distance_m(words, measuring_range_m)
    distance[is_error] = np.nan
    error_code = np.where(is_error, words, 0).astype(np.int32)
    in_range = (words >= X_MIN) & (words <= X_MAX)
    return distance, error_code, in_range


def timestamp_ms(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """t[ms] = (65536*hi + lo)/100, from the two 16-bit words."""
    lo = np.asarray(lo, dtype=np.int64) & 0xFFFF
    hi = np.asarray(hi, dtype=np.int64) & 0xFFFF
    return ((hi << 16) + lo) / TIMESTAMP_TICKS_PER_MS


def timestamp_words(ticks: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi) words of a time stamp given in 10 us ticks (wraps at 2**32)."""
    ticks = np.asarray(ticks, dtype=np.int64) % TIMESTAMP_MODULUS
    return ticks & 0xFFFF, ticks >> 16


class CounterUnwrapper:
    """Turns the 18-bit measurement counter into a running int64.

    Each step is taken as the *nearest* one modulo 2**18 (-2**17 .. 2**17-1),
    not as "always forward": then a single forged counter (line garbage that
    happened to look like a full measurement) costs two wrong steps and the
    sum heals, instead of leaving a permanent offset of one whole wrap. For a
    healthy stream the result is monotonic as long as fewer than 2**17
    measurements (32 s at 4 kHz) go missing in a row.
    """

    def __init__(self) -> None:
        self._last: int | None = None  # last unwrapped value

    def reset(self) -> None:
        """Forget the history: the next counter is taken as it is."""
        self._last = None

    def unwrap(self, counter: np.ndarray) -> np.ndarray:
        raw = np.asarray(counter, dtype=np.int64)
        if raw.size == 0:
            return raw.copy()
        half = COUNTER_MODULUS // 2
        if self._last is None:
            start = int(raw[0])
            steps = np.diff(raw)
        else:
            start = self._last
            steps = np.diff(raw, prepend=self._last % COUNTER_MODULUS)
        steps = (steps + half) % COUNTER_MODULUS - half
        if self._last is None:
            out = start + np.concatenate(([0], np.cumsum(steps)))
        else:
            out = start + np.cumsum(steps)
        self._last = int(out[-1])
        return out


def block_from_raw(raw: RawMeasurements, measuring_range_m: float,
                   unwrapper: CounterUnwrapper, host_time: float) -> LaserBlock:
    """Decode received measurements; the unwrapper carries the counter on."""
    distance, error_code, in_range = decode_distance(raw.column("distance"), measuring_range_m)
    counter = raw.column("counter")
    lo, hi = raw.column("timestamp_lo"), raw.column("timestamp_hi")
    n = len(raw)
    return LaserBlock(
        counter=unwrapper.unwrap(counter) if counter is not None else np.full(n, NO_COUNTER, np.int64),
        timestamp_ms=timestamp_ms(lo, hi) if lo is not None else np.full(n, np.nan),
        distance_m=distance,
        error_code=error_code,
        in_range=in_range,
        host_time=host_time,
    )
