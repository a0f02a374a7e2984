"""The serial laser read in a thread of its own while the sound card plays.

The sensor's own reader thread fills its bounded queue; this thread empties
it into a list as fast as blocks come (so the sensor's queue never drops
one), and turns a lost link into a stop of the whole measurement: it keeps
the reason and sets ``stop``, which capture() watches.
"""
from __future__ import annotations

import threading
import time

from instruments.laser.sensor import DEFAULT_OUTPUTS, DisplacementSensor, LaserBlock, LaserError, SensorInfo

_POLL_S = 0.05


class LaserReader:
    def __init__(self, sensor: DisplacementSensor, stop: threading.Event, rate_hz: float = 4000.0,
                 outputs: tuple[str, ...] = DEFAULT_OUTPUTS):
        self.sensor = sensor
        self.stop_event = stop
        self.rate_hz = float(rate_hz)
        self.outputs = outputs
        self.info: SensorInfo | None = None
        self.failure: str | None = None      # NB: set by the reader thread
        self._blocks: list[LaserBlock] = []  # NB: appended by the reader thread
        self._done = threading.Event()
        self._thread: threading.Thread | None = None

    def open(self) -> SensorInfo:
        """Connect, identify and configure; LaserError when the sensor does not answer or refuses."""
        self.info = self.sensor.open()
        try:
            self.sensor.configure(self.rate_hz, self.outputs)
        except LaserError:
            self.sensor.close()
            raise
        return self.info

    def start(self) -> None:
        self.sensor.start()
        self._thread = threading.Thread(target=self._run, name="laser-reader", daemon=True)
        self._thread.start()

    @property
    def blocks(self) -> list[LaserBlock]:
        return list(self._blocks)

    @property
    def last_arrival(self) -> float | None:
        blocks = self._blocks
        return blocks[-1].host_time if blocks else None

    def finish(self, until_host_time: float, timeout_s: float = 0.5) -> list[LaserBlock]:
        """Keep reading until a block arrived after ``until_host_time`` (or the timeout, or a lost link),
        then stop the sensor, take what it still holds, and close it. Every block received."""
        deadline = time.monotonic() + timeout_s
        while self.failure is None and time.monotonic() < deadline:
            last = self.last_arrival
            if last is not None and last >= until_host_time:
                break
            time.sleep(0.01)
        self._done.set()
        if self._thread is not None:
            self._thread.join(2 * _POLL_S + 1.0)
        try:
            self.sensor.stop()
            while (block := self.sensor.read_block(0.0)) is not None:
                self._blocks.append(block)
        except LaserError as exc:
            if self.failure is None and "link lost" in str(exc):
                self.failure = str(exc)
        finally:
            self.sensor.close()
        return list(self._blocks)

    def close(self) -> None:
        """Stop without waiting for more (an error before or during the capture); safe after finish()."""
        self._done.set()
        if self._thread is not None:
            self._thread.join(2 * _POLL_S + 1.0)
        try:
            self.sensor.close()
        except LaserError:
            pass

    def _run(self) -> None:
        while not self._done.is_set():
            try:
                block = self.sensor.read_block(_POLL_S)
            except LaserError as exc:
                self.failure = str(exc)
                self.stop_event.set()
                return
            if block is not None and len(block):
                self._blocks.append(block)
