"""SimulatedLaser: the DisplacementSensor protocol in-process, no port.

Same constructor shape as a driver (a port name it ignores, a baud rate it
uses for the bandwidth check), after the LaserModel it simulates: the model's
physics measure, the model's ``check_configuration`` refuses what the real
sensor refuses. It has no thread: ``read_block`` hands out, in real time, the
samples the virtual sensor has taken since the last call. Byte-level faults
(garbage, truncated frames) have no meaning without bytes and are ignored;
error codes and a lost link are honoured.
"""

from __future__ import annotations

import time

from instruments.laser.model import LaserModel
from instruments.laser.sensor import DEFAULT_OUTPUTS, FrameTally, LaserBlock, LaserError, LaserStats, SensorInfo

#: Blocks come every CHUNK_S, like the serial reader's chunks, and never
#: hold more than MAX_BLOCK measurements (0.25 s at 4 kHz).
CHUNK_S = 0.004
MAX_BLOCK = 1000


class SimulatedLaser:
    def __init__(self, model: LaserModel, port: str | None = None, baudrate: int | None = None, *,
                 connected: bool = True, **physics) -> None:
        self.laser_model = model
        self._url = port or f"sim://{model.name}"
        self._baudrate = baudrate or model.default_baudrate
        self._connected = connected
        self.model = model.make_physics(**physics)
        self._open = False
        self._slots = model.layout(DEFAULT_OUTPUTS)
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
            raise LaserError(f"no {self.laser_model.family} answering on {self._url}: "
                             "the simulated laser is not connected")
        self._open = True
        mr_mm = round(self.model.measuring_range_m * 1000)
        return SensorInfo(name=f"{self.laser_model.family}-{mr_mm} (simulated)", serial="00000000",
                          measuring_range_m=self.model.measuring_range_m, firmware="simulated")

    def configure(self, rate_hz: float, outputs: tuple[str, ...] = DEFAULT_OUTPUTS) -> None:
        self._require_open()
        if self._started:
            raise LaserError("stop the laser before configuring it")
        self.laser_model.check_configuration(self._baudrate, rate_hz, outputs)
        self._slots = self.laser_model.layout(outputs)
        self.model.rate_hz = float(rate_hz)

    def start(self) -> None:
        self._require_open()
        self.model.reset_counter()
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
        limit = self.model.disconnect_after
        if limit is not None and due >= limit:
            due = limit
            if self._failure is None:
                self._failure = f"simulated cable pulled after {limit} measurements"
        return due

    def _block(self, k0: int, k1: int) -> LaserBlock:
        # When the block is due by the schedule, not when this thread got to it (frame_clock.py): the
        # emulated device's latency is the link's, as chosen; the reader's own lateness is the host's.
        host_time = float(self.model.arrival_time(k1 - 1))
        block = self.model.decoded_block(k0, k1, self._slots, host_time)
        self._sent = k1
        self._tally.count(block)
        return block

    def _require_open(self) -> None:
        if not self._open:
            raise LaserError(f"laser on {self._url} is not open")

