"""The displacement-sensor protocol and what crosses threads from a laser.

``DisplacementSensor`` is what the measurement code talks to; each sensor
model's driver (``instruments/laser/<model>/``) and ``SimulatedLaser``
(in-process) implement it. Nothing here knows a model's bytes or words.
"""

from __future__ import annotations

import threading
from collections import Counter
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Mapping, Protocol, Sequence, runtime_checkable

import numpy as np

from analysis.errors import LinparError

#: Distance, counter and time stamp: what alignment to the audio needs.
DEFAULT_OUTPUTS: tuple[str, ...] = ("distance", "counter", "timestamp")
#: ``LaserBlock.counter`` when the sensor was not asked for its counter.
NO_COUNTER = -1


class LaserError(LinparError, RuntimeError):
    """The laser cannot do what was asked: not connected, refused a command,
    a setting it cannot keep up with, or the link was lost."""


@dataclass(frozen=True, slots=True)
class SensorInfo:
    name: str
    serial: str
    measuring_range_m: float
    firmware: str
    text: str = ""  # the sensor's own words, for the report


@dataclass(frozen=True, slots=True)
class LaserBlock:
    """Measurements that arrived together. Arrays are read-only.

    counter: unwrapped measurement counter (int64), NO_COUNTER if not sent
    timestamp_ms: sensor time stamp (float64), NaN if not sent
    distance_m: distance (float64), NaN where the sensor sent an error code
    error_code: int32, 0 for a valid distance, else the model's error code
    in_range: False for errors and for distances in the reserves
    host_time: time.monotonic() when the bytes arrived
    """

    counter: np.ndarray
    timestamp_ms: np.ndarray
    distance_m: np.ndarray
    error_code: np.ndarray
    in_range: np.ndarray
    host_time: float

    def __post_init__(self) -> None:
        n = len(self.distance_m)
        for array in (self.counter, self.timestamp_ms, self.distance_m, self.error_code, self.in_range):
            if len(array) != n:
                raise ValueError("all arrays of a LaserBlock must have the same length")
            array.setflags(write=False)

    def __len__(self) -> int:
        return len(self.distance_m)


def concatenate_blocks(blocks: Sequence[LaserBlock]) -> LaserBlock:
    """One block from many, in order; host_time is the last block's."""
    if not blocks:
        raise ValueError("nothing to concatenate")
    return LaserBlock(
        counter=np.concatenate([b.counter for b in blocks]),
        timestamp_ms=np.concatenate([b.timestamp_ms for b in blocks]),
        distance_m=np.concatenate([b.distance_m for b in blocks]),
        error_code=np.concatenate([b.error_code for b in blocks]),
        in_range=np.concatenate([b.in_range for b in blocks]),
        host_time=blocks[-1].host_time,
    )


@dataclass(frozen=True, slots=True)
class LaserStats:
    """Counts since open(). ``frames`` are measurements delivered (or
    queued); errors and reserve frames are among them."""

    frames: int = 0
    values: int = 0
    discarded_bytes: int = 0
    incomplete_measurements: int = 0
    errors_by_code: Mapping[int, int] = field(default_factory=lambda: MappingProxyType({}))
    reserve_frames: int = 0
    queue_overflows: int = 0
    stray_replies: int = 0
    ignored_frames: int = 0  # arrived while not started


class FrameTally:
    """What a sensor counts about the blocks it delivers. The reader thread
    counts while any thread may ask; the lock keeps the dict copy safe."""

    def __init__(self) -> None:
        self.frames = 0
        self.reserve_frames = 0
        self._errors_by_code: Counter[int] = Counter()
        self._lock = threading.Lock()

    def count(self, block: LaserBlock) -> None:
        codes = block.error_code[block.error_code != 0]
        reserve = int(np.count_nonzero(~block.in_range & (block.error_code == 0)))
        with self._lock:
            self.frames += len(block)
            self.reserve_frames += reserve
            if codes.size:
                self._errors_by_code.update(codes.tolist())

    def errors_snapshot(self) -> Mapping[int, int]:
        with self._lock:
            return MappingProxyType(dict(self._errors_by_code))


@runtime_checkable
class DisplacementSensor(Protocol):
    """A displacement sensor streaming blocks of measurements."""

    def open(self) -> SensorInfo:
        """Connect and identify; raises LaserError when nothing answers."""
        ...

    def configure(self, rate_hz: float, outputs: tuple[str, ...] = DEFAULT_OUTPUTS) -> None:
        """Measuring rate and what each measurement carries; raises
        LaserError for a rate or bandwidth the sensor cannot do."""
        ...

    def start(self) -> None:
        """Reset the counter and start streaming."""
        ...

    def read_block(self, timeout: float) -> LaserBlock | None:
        """The next block, or None after ``timeout`` s; after a lost link,
        first the blocks already received, then LaserError."""
        ...

    def stop(self) -> None:
        """Stop streaming; blocks already received can still be read."""
        ...

    def close(self) -> None:
        """Release the port and threads; safe to call twice."""
        ...

    @property
    def stats(self) -> LaserStats:
        ...
