"""What a virtual ILD1420 measures: the shared physics of the emulator
(bytes on a pseudo-terminal) and SimulatedLaser (in-process blocks, through
``decoded_block``: the words decoded as the driver decodes them).

Clocks: the sensor's crystal runs ``clock_ppm`` fast, so on the host clock it
measures at ``rate_hz * (1 + ppm*1e-6)``. Sample k of a stream is taken at
``t0 + start_latency_s + k / host_rate`` (host time), where ``t0`` is the
moment measurement output was switched on; its own time stamp advances by
exactly 1/rate_hz per sample because it counts its own crystal. It reaches
the host ``link_latency_s`` after it was taken (the sensor's processing, a
USB adapter's latency timer): a latency no host time can see, only a
calibration (the plan's ``laser_latency_s``) or the delay found from the
data. With ``link_jitter_s`` or ``packet_samples`` > 1 the samples arrive
in packets, late by the latency plus a random share of the jitter, as
through a USB serial adapter (instruments/laser/usb_link.py).

Host times here are the emulation's schedule, the audio frame counter's line
when the displacement comes from a rig (instruments/rig/frame_clock.py):
they say when a measurement is taken and when it is due, whatever the
emulator's thread is doing.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable, Mapping

import numpy as np

from instruments.laser.ild1420.frames import RawMeasurements
from instruments.laser.ild1420.values import (
    COUNTER_MODULUS, X_FULL_SCALE, CounterUnwrapper, LaserErrorCode, block_from_raw, distance_to_x,
    timestamp_words)
from instruments.laser.sensor import LaserBlock
from instruments.laser.usb_link import PACKET_SAMPLES, UsbLink

Displacement = Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class ErrorPlan:
    """What goes wrong on purpose. Indices count measurements since the
    output was switched on (0 = first measurement of the stream)."""

    error_share: float = 0.0  # random share of measurements that carry error_code
    error_code: int = LaserErrorCode.NO_PEAK
    codes_at: Mapping[int, int] = field(default_factory=dict)  # index -> code
    garbage_every: int = 0  # a burst of random bytes after every k-th measurement
    garbage_bytes: int = 16
    truncate_every: int = 0  # every k-th measurement loses its last byte
    disconnect_after: int | None = None  # the link dies after this many measurements
    seed: int = 0


def _at_rest(t: np.ndarray) -> np.ndarray:
    return np.zeros_like(t)


class SensorModel:
    """Turns a displacement function into the sensor's 18-bit words."""

    def __init__(self, displacement: Displacement | None = None, measuring_range_mm: float = 10,
                 rate_hz: float = 4000.0, clock_ppm: float = 0.0, start_latency_s: float = 0.0,
                 noise_m: float = 0.0, error_plan: ErrorPlan | None = None, *,
                 counter_start: int = 0, timestamp_start_s: float = 0.0,
                 rest_distance_m: float | None = None, link_latency_s: float = 0.0,
                 link_jitter_s: float = 0.0, packet_samples: int | None = None) -> None:
        self.displacement = displacement or _at_rest
        self.measuring_range_m = measuring_range_mm / 1000.0
        self.rate_hz = float(rate_hz)
        self.clock_ppm = clock_ppm
        self.start_latency_s = start_latency_s
        self.link_latency_s = link_latency_s
        self.link_jitter_s = link_jitter_s
        self.packet_samples = packet_samples      # None: packets of PACKET_SAMPLES when there is jitter
        self.noise_m = noise_m
        self.error_plan = error_plan or ErrorPlan()
        self.counter_start = counter_start
        self.rest_distance_m = self.measuring_range_m / 2 if rest_distance_m is None else rest_distance_m
        self._rng = np.random.default_rng(self.error_plan.seed)
        self._powered_on = time.monotonic()
        self._timestamp_start_s = timestamp_start_s
        self._counter_next = counter_start
        self._unwrapper = CounterUnwrapper()  # decoded_block's, as the driver's reader keeps one
        self.t0: float | None = None
        self._link: UsbLink | None = None     # packets and jitter of the link, from begin() on

    @property
    def host_rate_hz(self) -> float:
        """The rate as the host clock sees it."""
        return self.rate_hz * (1.0 + self.clock_ppm * 1e-6)

    def begin(self, t0: float) -> None:
        """Measurement output switched on at host time t0 (the link's packets start again)."""
        self.t0 = t0
        packets = self.packet_samples or (PACKET_SAMPLES if self.link_jitter_s else 1)
        plain = packets == 1 and not self.link_jitter_s
        self._link = None if plain else UsbLink(self.link_latency_s, self.link_jitter_s, packets,
                                                  seed=self.error_plan.seed)

    @property
    def disconnect_after(self) -> int | None:
        """The link dies after this many measurements (None: never)."""
        return self.error_plan.disconnect_after

    def reset_counter(self) -> None:
        """RESETCNT: the next measurement carries ``counter_start``."""
        self._counter_next = self.counter_start
        self._unwrapper.reset()

    def sample_times(self, k: np.ndarray) -> np.ndarray:
        """Host seconds after t0 at which samples k of this stream are taken."""
        return self.start_latency_s + np.asarray(k, dtype=np.float64) / self.host_rate_hz

    def arrival_time(self, k) -> np.ndarray | float:
        """Host time at which sample k reaches the host: taken, plus the link's latency (with its packet)."""
        if self._link is not None:
            return self.t0 + self._link.arrival(k, self.sample_times)
        return self.t0 + self.sample_times(k) + self.link_latency_s

    def due(self, now: float) -> int:
        """How many samples of this stream have reached the host by host time now."""
        if self.t0 is None:
            return 0
        if self._link is not None:
            return self._link.arrived(now - self.t0, self.sample_times, self.host_rate_hz, self.start_latency_s)
        elapsed = now - self.t0 - self.start_latency_s - self.link_latency_s
        return 0 if elapsed < 0 else int(np.floor(elapsed * self.host_rate_hz)) + 1

    def words(self, k0: int, k1: int) -> dict[str, np.ndarray]:
        """The 18-bit words of samples k0..k1-1 per slot. Call in order: the
        counter and the random plan move on with every call."""
        assert self.t0 is not None, "begin() first"
        k = np.arange(k0, k1)
        t = self.sample_times(k)
        distance = self.rest_distance_m + np.asarray(self.displacement(t), dtype=np.float64)
        if self.noise_m:
            distance = distance + self._rng.normal(0.0, self.noise_m, len(k))
        x = distance_to_x(np.nan_to_num(distance, nan=-1.0), self.measuring_range_m)
        word = np.where(x < 0, int(LaserErrorCode.PEAK_BEFORE_RANGE),
                        np.where(x > X_FULL_SCALE, int(LaserErrorCode.PEAK_AFTER_RANGE), x))
        word[np.isnan(distance)] = LaserErrorCode.NO_PEAK
        plan = self.error_plan
        if plan.error_share:
            word[self._rng.random(len(k)) < plan.error_share] = plan.error_code
        for index, code in plan.codes_at.items():
            if k0 <= index < k1:
                word[index - k0] = code

        counter = (self._counter_next + np.arange(len(k))) % COUNTER_MODULUS
        self._counter_next = (self._counter_next + len(k)) % COUNTER_MODULUS
        sensor_s = (self._timestamp_start_s + (self.t0 - self._powered_on + t) * (1.0 + self.clock_ppm * 1e-6))
        lo, hi = timestamp_words(np.rint(sensor_s * 1e5).astype(np.int64))
        return {"distance": word.astype(np.int64), "counter": counter,
                "timestamp_lo": lo, "timestamp_hi": hi}

    def rows(self, k0: int, k1: int, slots: tuple[str, ...]) -> np.ndarray:
        """(k1-k0, len(slots)) words in slot order, ready to encode."""
        words = self.words(k0, k1)
        return np.stack([words[slot] for slot in slots], axis=1)

    def decoded_block(self, k0: int, k1: int, slots: tuple[str, ...], host_time: float) -> LaserBlock:
        """Samples k0..k1-1 as the driver would deliver them, without the bytes."""
        raw = RawMeasurements(slots, self.rows(k0, k1, slots))
        return block_from_raw(raw, self.measuring_range_m, self._unwrapper, host_time)

    def garbage(self) -> bytes:
        return self._rng.integers(0, 256, self.error_plan.garbage_bytes, dtype=np.uint8).tobytes()
