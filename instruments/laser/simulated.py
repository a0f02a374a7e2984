"""SimulatedLaser: the DisplacementSensor protocol in-process, no port.

Same constructor shape as ILD1420 (a port name it ignores, a baud rate it
uses for the bandwidth check), plus the virtual sensor's physics. It has no
thread: ``read_block`` hands out, in real time, the samples the virtual
sensor has taken since the last call. Byte-level faults of the ErrorPlan
(garbage, truncated frames) have no meaning without bytes and are ignored;
error codes and a lost link are honoured.
"""

from __future__ import annotations

import time

from instruments.laser import commands
from instruments.laser.frames import RawMeasurements, value_slots
from instruments.laser.ild1420 import DEFAULT_BAUDRATE
from instruments.laser.sensor import (
    DEFAULT_OUTPUTS, FrameTally, LaserBlock, LaserError, LaserStats, SensorInfo, block_from_raw)
from instruments.laser.sensor_model import Displacement, ErrorPlan, SensorModel
from instruments.laser.values import CounterUnwrapper

#: Blocks come every CHUNK_S, like the serial reader's chunks, and never
#: hold more than MAX_BLOCK measurements (0.25 s at 4 kHz).
CHUNK_S = 0.004
MAX_BLOCK = 1000


class SimulatedLaser:
    def __init__(self, port: str = "sim://ild1420", baudrate: int = DEFAULT_BAUDRATE, *,
                 displacement: Displacement | None = None, measuring_range_mm: int = 10,
                 clock_ppm: float = 0.0, start_latency_s: float = 0.0, noise_m: float = 0.0,
                 error_plan: ErrorPlan | None = None, counter_start: int = 0,
                 connected: bool = True, link_latency_s: float = 0.0) -> None:
        self._url = port
        self._baudrate = baudrate
        self._connected = connected
        self.model = SensorModel(displacement, measuring_range_mm, 4000.0, clock_ppm, start_latency_s,
                                 noise_m, error_plan, counter_start=counter_start, link_latency_s=link_latency_s)
        self._open = False
        self._slots = value_slots(DEFAULT_OUTPUTS)
        self._unwrapper = CounterUnwrapper()
        self._tally = FrameTally()
        self._started = False
        self._sent = 0
        self._end_time: float | None = None  # host time after which nothing more is measured
        self._failure: str | None = None

    @property
    def t0(self) -> float | None:
        return self.model.t0

    def open(self) -> SensorInfo:
        if not self._connected:
            raise LaserError(f"no ILD1420 answering on {self._url}: the simulated laser is not connected")
        self._open = True
        mr_mm = round(self.model.measuring_range_m * 1000)
        return SensorInfo(name=f"ILD1420-{mr_mm} (simulated)", serial="00000000",
                          measuring_range_m=self.model.measuring_range_m, firmware="simulated")

    def configure(self, rate_hz: float, outputs: tuple[str, ...] = DEFAULT_OUTPUTS) -> None:
        self._require_open()
        if self._started:
            raise LaserError("stop the laser before configuring it")
        commands.check_rate(rate_hz)
        try:
            slots = value_slots(tuple(outputs))
        except ValueError as exc:
            raise LaserError(str(exc)) from exc
        commands.check_bandwidth(self._baudrate, rate_hz, len(slots))
        self.model.rate_hz = float(rate_hz)
        self._slots = slots

    def start(self) -> None:
        self._require_open()
        self.model.reset_counter()
        self._unwrapper.reset()
        self._sent = 0
        self._end_time = None
        self.model.begin(time.monotonic())
        self._started = True

    def read_block(self, timeout: float) -> LaserBlock | None:
        self._require_open()
        deadline = time.monotonic() + max(0.0, timeout)
        while True:
            now = time.monotonic()
            available = self._available(now)
            wanted = self._sent + max(1, round(self.model.rate_hz * CHUNK_S))
            ended = self._end_time is not None or self._failure is not None
            if available >= wanted or (available > self._sent and (ended or now >= deadline)):
                return self._block(self._sent, min(available, self._sent + MAX_BLOCK))
            if self._failure is not None:
                raise LaserError(f"laser link lost: {self._failure}")
            if now >= deadline:
                return None
            wake = deadline
            if self._started and self.model.t0 is not None:
                wake = min(deadline, float(self.model.arrival_time(wanted - 1)))
            time.sleep(max(0.0, wake - now) + 1e-4)  # the virtual sensor's own pace

    def stop(self) -> None:
        if self._started:
            self._started = False
            self._end_time = time.monotonic()

    def close(self) -> None:
        self.stop()
        self._open = False

    def disconnect(self) -> None:
        """The cable is pulled now: what was measured so far is still read."""
        self._end_time = time.monotonic()
        self._failure = "simulated cable pulled"

    @property
    def stats(self) -> LaserStats:
        return LaserStats(frames=self._tally.frames, values=self._tally.frames * len(self._slots),
                          errors_by_code=self._tally.errors_snapshot(),
                          reserve_frames=self._tally.reserve_frames)

    # -- internals ----------------------------------------------------------------
    def _available(self, now: float) -> int:
        if self.model.t0 is None:
            return 0
        due = self.model.due(now if self._end_time is None else min(now, self._end_time))
        limit = self.model.error_plan.disconnect_after
        if limit is not None and due >= limit:
            due = limit
            if self._failure is None:
                self._failure = f"simulated cable pulled after {limit} measurements"
        return due

    def _block(self, k0: int, k1: int) -> LaserBlock:
        raw = RawMeasurements(self._slots, self.model.rows(k0, k1, self._slots))
        # When the block is due by the schedule, not when this thread got to it (frame_clock.py): the
        # emulated device's latency is the link's, as chosen; the reader's own lateness is the host's.
        host_time = float(self.model.arrival_time(k1 - 1))
        block = block_from_raw(raw, self.model.measuring_range_m, self._unwrapper, host_time)
        self._sent = k1
        self._tally.count(block)
        return block

    def _require_open(self) -> None:
        if not self._open:
            raise LaserError(f"laser on {self._url} is not open")

