"""A virtual ILD1420 on a pseudo-terminal, for tests and the virtual rig.

The emulator owns the master end of a pty; ``port_path`` names the slave end,
which ILD1420 (or any pyserial program) opens like a USB-RS422 converter. A
thread answers ASCII commands (echo, lines, ``->``; Exxx for what it does not
know) and, once the output is switched on, streams binary measurements in
real time, a chunk every few milliseconds, with the clock error, latency,
noise and faults given to it (see sensor_model.py for the clocks).
"""

from __future__ import annotations

import errno
import fcntl
import os
import select
import struct
import termios
import threading
import time
import tty
from typing import Mapping

import numpy as np

from instruments.laser.ild1420 import commands
from instruments.laser.ild1420.frames import encode_measurements, value_slots
from instruments.laser.ild1420.sensor_model import Displacement, ErrorPlan, SensorModel

#: The emulator's own error lines (the manual's numbers are not in the spec).
UNKNOWN_COMMAND = "E200 Unknown command"
BAD_PARAMETER = "E210 Parameter out of range"
#: Bytes waiting for a reader beyond this are dropped, oldest first, as a
#: sensor's transmit buffer would overrun.
_MAX_PENDING_BYTES = 1 << 20
_DRAIN_LIMIT_S = 1.0


class LaserEmulator:
    def __init__(self, displacement: Displacement | None = None, measuring_range_mm: int = 10,
                 rate_hz: float = 4000.0, clock_ppm: float = 0.0, start_latency_s: float = 0.0,
                 noise_m: float = 0.0, error_plan: ErrorPlan | None = None, *,
                 counter_start: int = 0, rest_distance_m: float | None = None,
                 serial_number: str = "11240001", firmware: str = "004.093.087.02",
                 warnings: Mapping[str, str] | None = None, reply_bytes_per_measurement: int = 0,
                 chunk_s: float = 0.002, link_latency_s: float = 0.0, link_jitter_s: float = 0.0) -> None:
        self.model = SensorModel(displacement, measuring_range_mm, rate_hz, clock_ppm, start_latency_s,
                                 noise_m, error_plan, counter_start=counter_start,
                                 rest_distance_m=rest_distance_m, link_latency_s=link_latency_s,
                                 link_jitter_s=link_jitter_s)
        self.plan = self.model.error_plan
        self.measuring_range_mm = measuring_range_mm
        self.serial_number = serial_number
        self.firmware = firmware
        self.warnings = dict(warnings or {})
        self.reply_bytes_per_measurement = reply_bytes_per_measurement
        self.chunk_s = chunk_s
        self.outputs: tuple[str, ...] = ("distance",)
        self.commands_received: list[str] = []  # NB: appended by the emulator thread
        self.samples_sent = 0  # NB: samples of the current stream written so far
        self.t0: float | None = None  # host time.monotonic() when output went on

        self._master, self._slave = os.openpty()
        tty.setraw(self._slave)  # no echo, no CR/LF translation: bytes pass untouched
        self.port_path = os.ttyname(self._slave)
        os.set_blocking(self._master, False)
        self._streaming = False
        self._inbox = bytearray()
        self._out = bytearray()
        self._reply_queue = bytearray()  # reply text still to interleave with values
        self._stop = threading.Event()
        self._hang_up_requested = threading.Event()
        self._thread: threading.Thread | None = None
        self._closed = False
        self._fd_lock = threading.Lock()

    # -- life cycle -------------------------------------------------------------
    def start(self) -> LaserEmulator:
        if self._thread is None:
            self._thread = threading.Thread(target=self._run, name="ild1420-emulator", daemon=True)
            self._thread.start()
        return self

    def close(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
        self._close_fds()

    def disconnect(self) -> None:
        """The cable is pulled: whatever was written is still delivered (the
        pty would otherwise throw it away), then both pty ends close and the
        reader gets an error."""
        self._hang_up_requested.set()
        if self._thread is not None:
            self._thread.join()
        self._close_fds()

    def __enter__(self) -> LaserEmulator:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def streaming(self) -> bool:
        return self._streaming

    def sample_times(self, k: np.ndarray) -> np.ndarray:
        """Host seconds after ``t0`` at which samples k were taken."""
        return self.model.sample_times(k)

    # -- the thread -------------------------------------------------------------
    def _run(self) -> None:
        try:
            while not self._stop.is_set():
                writable = [self._master] if self._out else []
                readable, _, _ = select.select([self._master], writable, [], self.chunk_s)
                if readable:
                    self._read_commands()
                if self._streaming:
                    self._emit_due(time.monotonic())
                elif self._reply_queue:  # nothing left to interleave it with
                    self._out += self._reply_queue
                    self._reply_queue.clear()
                self._write_pending()
                if self._hang_up_requested.is_set():
                    self._drain()
                    self._close_fds()
                    return
        except OSError as exc:
            if exc.errno not in (errno.EIO, errno.EBADF):
                raise

    def _read_commands(self) -> None:
        try:
            self._inbox += os.read(self._master, 4096)
        except BlockingIOError:
            return
        while b"\n" in self._inbox:
            line, _, rest = self._inbox.partition(b"\n")
            self._inbox = bytearray(rest)
            text = line.decode("ascii", errors="replace").strip()
            if text:
                self.commands_received.append(text)
                reply = self._answer(text).encode("ascii")
                if self._streaming and self.reply_bytes_per_measurement:
                    self._reply_queue += reply
                else:
                    self._out += reply

    def _emit_due(self, now: float) -> None:
        due = self.model.due(now)
        if self.plan.disconnect_after is not None:
            due = min(due, self.plan.disconnect_after)
        k0 = self.samples_sent
        if due > k0:
            slots = value_slots(self.outputs)
            rows = encode_measurements(self.model.rows(k0, due, slots))
            if self._plain_stream():
                self._out += rows.tobytes()
            else:
                for i, row in enumerate(rows, start=k0):
                    self._out += self._faulted(i, row.tobytes())
            self.samples_sent = due
        if self.plan.disconnect_after is not None and self.samples_sent >= self.plan.disconnect_after:
            self._hang_up_requested.set()

    def _plain_stream(self) -> bool:
        plan = self.plan
        return not (plan.garbage_every or plan.truncate_every or self._reply_queue)

    def _faulted(self, index: int, row: bytes) -> bytes:
        plan = self.plan
        number = index + 1
        if plan.truncate_every and number % plan.truncate_every == 0:
            row = row[:-1]
        if plan.garbage_every and number % plan.garbage_every == 0:
            row += self.model.garbage()
        if self._reply_queue:
            take = self.reply_bytes_per_measurement
            row += bytes(self._reply_queue[:take])
            del self._reply_queue[:take]
        return row

    def _write_pending(self) -> None:
        if len(self._out) > _MAX_PENDING_BYTES:
            del self._out[:len(self._out) - _MAX_PENDING_BYTES]
        while self._out:
            try:
                written = os.write(self._master, self._out[:4096])
            except BlockingIOError:
                return
            del self._out[:written]

    def _drain(self) -> None:
        """Let the reader take what was written before the line goes dead."""
        deadline = time.monotonic() + _DRAIN_LIMIT_S
        quiet = 0
        while time.monotonic() < deadline and quiet < 10:
            self._write_pending()
            unread = struct.unpack("I", fcntl.ioctl(self._slave, termios.TIOCINQ, b"\0" * 4))[0]
            quiet = quiet + 1 if not (self._out or unread) else 0
            time.sleep(0.005)  # the kernel moves pty data asynchronously; look again

    def _close_fds(self) -> None:
        with self._fd_lock:
            if not self._closed:
                self._closed = True
                os.close(self._master)
                os.close(self._slave)

    # -- the command set ---------------------------------------------------------
    def _answer(self, line: str) -> str:
        words = line.split()
        name, args = words[0].upper(), [w.upper() for w in words[1:]]
        handler = {
            commands.GETINFO: self._getinfo,
            commands.MEASRATE: self._measrate,
            commands.OUTPUT: self._output,
            commands.OUTPUT_ADD: self._output_add,
            commands.OUTPUT_INFO: self._output_info,
            commands.RESET_COUNTER: self._reset_counter,
        }.get(name)
        body = handler(args) if handler else [f"{UNKNOWN_COMMAND}: {words[0]}"]
        if name in self.warnings:
            body.insert(0, self.warnings[name])
        return line + "\r\n" + "".join(f"{b}\r\n" for b in body) + "->"

    def _getinfo(self, args: list[str]) -> list[str]:
        return [f"Name:            ILD1420-{self.measuring_range_mm}",
                f"Serial:          {self.serial_number}",
                "Option:          000",
                "Article:         4120136",
                f"Measuring range: {self.measuring_range_mm} mm",
                f"Version:         {self.firmware}"]

    def _measrate(self, args: list[str]) -> list[str]:
        if not args:
            return [f"MEASRATE {self.model.rate_hz / 1000:g}"]
        try:
            rate_hz = float(args[0]) * 1000.0
        except ValueError:
            return [BAD_PARAMETER]
        if rate_hz not in commands.RATES_HZ:
            return [BAD_PARAMETER]
        self.model.rate_hz = rate_hz
        return []

    def _output(self, args: list[str]) -> list[str]:
        if args == ["RS422"]:
            if not self._streaming:
                self.samples_sent = 0
                self.t0 = time.monotonic()
                self.model.begin(self.t0)
                self._streaming = True
            return []
        if args in (["NONE"], ["ANALOG"]):
            self._streaming = False
            return []
        return [BAD_PARAMETER]

    def _output_add(self, args: list[str]) -> list[str]:
        if args == ["NONE"]:
            self.outputs = ("distance",)
            return []
        names = {"COUNTER": "counter", "TIMESTAMP": "timestamp"}
        if not args or any(a not in names for a in args):
            return [BAD_PARAMETER]
        chosen = {names[a] for a in args}
        self.outputs = tuple(n for n in ("distance", "counter", "timestamp") if n == "distance" or n in chosen)
        return []

    def _output_info(self, args: list[str]) -> list[str]:
        return [commands.output_info_line(self.outputs)]

    def _reset_counter(self, args: list[str]) -> list[str]:
        self.model.reset_counter()
        return []
