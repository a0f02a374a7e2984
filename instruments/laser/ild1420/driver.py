"""The optoNCDT ILD1420 over its RS422 link (a serial port to pyserial).

One reader thread owns the port's input: it feeds every byte to the
FrameParser, turns measurements into LaserBlocks for a bounded queue, and
hands command replies to the thread waiting in ``command()``. Replies are
taken from the parser, never by reading the port, because binary values keep
flowing while a command is answered.
"""

from __future__ import annotations

import logging
import threading
import time
from dataclasses import dataclass, field
from typing import Callable

import serial

from instruments.laser.block_queue import BlockQueue
from instruments.laser.ild1420 import commands
from instruments.laser.ild1420.frames import OUTPUT_NAMES, FrameParser, RawMeasurements, Reply
from instruments.laser.ild1420.values import CounterUnwrapper, block_from_raw
from instruments.laser.sensor import DEFAULT_OUTPUTS, FrameTally, LaserBlock, LaserError, LaserStats, SensorInfo

log = logging.getLogger(__name__)

#: How long the reader waits for a byte before it calls the line idle: this
#: bounds the reply latency on a quiet line and how long close() waits.
_IDLE_S = 0.02


@dataclass
class _PendingCommand:
    text: str
    on_reply: Callable[[Reply], None] | None
    done: threading.Event = field(default_factory=threading.Event)
    reply: Reply | None = None
    failure: str | None = None


class ILD1420:
    """The real sensor. ``port`` is a pyserial URL (a device path, a pty
    name, ``loop://``, ``socket://host:port``) or an already made pyserial
    port, which is then handed over: close() closes it."""

    def __init__(self, port: str | serial.SerialBase, baudrate: int = commands.DEFAULT_BAUDRATE, *,
                 reply_timeout_s: float = 1.0, queue_blocks: int = 1024) -> None:
        self._url = port if isinstance(port, str) else getattr(port, "port", None) or repr(port)
        self._given_port = None if isinstance(port, str) else port
        self._baudrate = baudrate if isinstance(port, str) else port.baudrate
        self._reply_timeout_s = reply_timeout_s
        self._queue_blocks = queue_blocks
        self._port: serial.SerialBase | None = None
        self._reader: threading.Thread | None = None
        self._closing = threading.Event()
        self._command_lock = threading.Lock()
        self._reset_state()

    def _reset_state(self) -> None:
        self._parser = FrameParser(DEFAULT_OUTPUTS)
        self._blocks = BlockQueue(self._queue_blocks)
        self._unwrapper = CounterUnwrapper()
        self._tally = FrameTally()
        self._info: SensorInfo | None = None
        self._outputs: tuple[str, ...] = ()
        self._measuring_range_m = 0.0  # NB: set in the reader, in stream order
        self._pending: _PendingCommand | None = None  # NB: shared with the reader
        self._accepting = False  # NB: reader keeps measurements only after RESETCNT
        self._started = False
        self._stray_replies = 0
        self._junk_text_bytes = 0
        self._ignored_frames = 0

    # -- DisplacementSensor ---------------------------------------------------
    def open(self) -> SensorInfo:
        if self._port is not None:
            raise LaserError(f"laser on {self._url} is already open")
        self._reset_state()
        self._port = self._open_port()
        self._closing.clear()
        self._reader = threading.Thread(target=self._read_loop, name="ild1420-reader", daemon=True)
        self._reader.start()
        try:
            info_reply = self.command(commands.GETINFO, on_reply=self._take_info)
            info = commands.parse_info(info_reply)
            outputs = commands.parse_output_info(self.command(
                commands.OUTPUT_INFO, on_reply=lambda r: self._parser.set_outputs(
                    commands.parse_output_info(r))))
        except LaserError as exc:
            self.close()
            raise LaserError(f"no ILD1420 answering on {self._url} at {self._baudrate} baud: {exc}") from exc
        self._info, self._outputs = info, outputs
        return info

    def configure(self, rate_hz: float, outputs: tuple[str, ...] = DEFAULT_OUTPUTS) -> None:
        self._require_open()
        if self._started:
            raise LaserError("stop the laser before configuring it")
        commands.check_configuration(self._baudrate, rate_hz, outputs)
        self.command(commands.measrate_command(rate_hz))
        self.command(commands.output_add_command(tuple(outputs)),
                     on_reply=lambda r: self._parser.set_outputs(tuple(outputs)))
        reported = commands.parse_output_info(self.command(commands.OUTPUT_INFO))
        wanted = tuple(name for name in OUTPUT_NAMES if name in outputs)
        if reported != wanted:
            raise LaserError(f"asked the laser for {wanted} but it sends {reported}")
        self._outputs = reported

    def start(self) -> None:
        self._require_open()
        self._blocks.clear()
        self.command(commands.RESET_COUNTER, on_reply=self._on_counter_reset)
        self.command(commands.OUTPUT_ON)
        self._started = True

    def read_block(self, timeout: float) -> LaserBlock | None:
        self._require_open()
        return self._blocks.get(timeout)

    def stop(self) -> None:
        if self._port is None or not self._started:
            return
        self._started = False
        self.command(commands.OUTPUT_OFF, on_reply=self._on_output_off)

    def close(self) -> None:
        if self._port is None:
            return
        if self._started and self._blocks.failure is None:
            try:  # leave the sensor quiet for the next user; not worth failing close()
                self.command(commands.OUTPUT_OFF, timeout=0.2)
            except LaserError as exc:
                log.warning("could not stop the laser output on close: %s", exc)
        self._started = False
        port, self._port = self._port, None
        self._closing.set()
        if hasattr(port, "cancel_read"):
            try:
                port.cancel_read()
            except (serial.SerialException, OSError):
                pass
        if self._reader is not None:
            self._reader.join()
            self._reader = None
        port.close()
        self._fail_pending("the laser was closed")

    @property
    def stats(self) -> LaserStats:
        parser = self._parser.stats
        return LaserStats(
            frames=self._tally.frames,
            values=parser.values,
            discarded_bytes=parser.discarded_bytes + self._junk_text_bytes,
            incomplete_measurements=parser.incomplete_measurements + parser.orphan_values,
            errors_by_code=self._tally.errors_snapshot(),
            reserve_frames=self._tally.reserve_frames,
            queue_overflows=self._blocks.overflows,
            stray_replies=self._stray_replies,
            ignored_frames=self._ignored_frames,
        )

    # -- beyond the protocol --------------------------------------------------
    @property
    def info(self) -> SensorInfo | None:
        return self._info

    @property
    def outputs(self) -> tuple[str, ...]:
        """What each measurement carries, as the sensor last said."""
        return self._outputs

    def command(self, text: str, *, timeout: float | None = None,
                on_reply: Callable[[Reply], None] | None = None) -> Reply:
        """Send one ASCII command and wait for its reply (echo ... ->).

        ``on_reply`` runs in the reader thread, in stream order: the values
        after the reply are parsed after it ran (that is how a new output
        layout or a counter reset takes effect at the right byte). Raises
        LaserError for an Exxx reply, no reply in time, or a lost link;
        Wxxx warnings are logged.
        """
        port = self._require_open()
        timeout = self._reply_timeout_s if timeout is None else timeout
        with self._command_lock:
            if self._blocks.failure is not None:
                raise LaserError(f"laser link lost: {self._blocks.failure}")
            pending = _PendingCommand(text, on_reply)
            self._pending = pending
            self._parser.expect_reply()
            try:
                port.write(f"{text}\r\n".encode("ascii"))
            except (serial.SerialException, OSError) as exc:
                self._pending = None
                raise LaserError(f"laser link lost: cannot send {text!r}: {exc}") from exc
            if not pending.done.wait(timeout):
                self._pending = None
                raise LaserError(f"no reply to {text!r} within {timeout:g} s")
        reply = pending.reply
        if pending.failure is not None:
            if reply is not None:
                raise LaserError(f"cannot use the reply to {text!r}: {pending.failure}")
            raise LaserError(f"laser link lost: {pending.failure}")
        assert reply is not None
        if reply.errors:
            raise LaserError(f"the laser refused {text!r}: {'; '.join(reply.errors)}")
        for warning in reply.warnings:
            log.warning("laser warns on %r: %s", text, warning)
        return reply

    # -- reader thread --------------------------------------------------------
    def _read_loop(self) -> None:
        port = self._port
        assert port is not None
        try:
            while not self._closing.is_set():
                data = port.read(1)
                if not data:
                    for reply in self._parser.flush_idle():
                        self._on_reply(reply)
                    continue
                waiting = port.in_waiting
                if waiting:
                    data += port.read(waiting)
                host_time = time.monotonic()
                for event in self._parser.feed(data):
                    if isinstance(event, Reply):
                        self._on_reply(event)
                    else:
                        self._on_measurements(event, host_time)
        except (serial.SerialException, OSError) as exc:
            if not self._closing.is_set():
                self._lose_link(str(exc) or type(exc).__name__)
        except Exception as exc:  # a bug here must not leave read_block waiting forever
            log.exception("laser reader crashed")
            self._lose_link(f"reader crashed: {exc!r}")

    def _lose_link(self, reason: str) -> None:
        self._blocks.fail(reason)
        self._fail_pending(reason)

    def _on_measurements(self, raw: RawMeasurements, host_time: float) -> None:
        if not self._accepting:
            self._ignored_frames += len(raw)
            return
        block = block_from_raw(raw, self._measuring_range_m, self._unwrapper, host_time)
        self._tally.count(block)
        self._blocks.put(block)

    def _on_reply(self, reply: Reply) -> None:
        pending = self._pending
        found = reply.from_echo(pending.text) if pending is not None else None
        if pending is None or found is None:
            self._stray_replies += 1
            if pending is not None:
                self._parser.expect_reply()  # the awaited reply is still to come
            return
        junk, reply = found
        self._junk_text_bytes += junk
        if pending.on_reply is not None and not reply.errors:
            try:
                pending.on_reply(reply)
            except (LaserError, ValueError) as exc:  # a reply we cannot use; the link is fine
                pending.failure = str(exc)
        pending.reply = reply
        self._pending = None
        pending.done.set()

    def _take_info(self, reply: Reply) -> None:
        self._measuring_range_m = commands.parse_info(reply).measuring_range_m

    def _on_counter_reset(self, reply: Reply) -> None:
        self._unwrapper.reset()
        self._parser.reset_grouping()
        self._accepting = True

    def _on_output_off(self, reply: Reply) -> None:
        self._accepting = False

    # -- helpers ----------------------------------------------------------------
    def _open_port(self) -> serial.SerialBase:
        if self._given_port is not None:
            port = self._given_port
            port.timeout = _IDLE_S
            if not port.is_open:
                port.open()
            return port
        try:
            return serial.serial_for_url(self._url, baudrate=self._baudrate, timeout=_IDLE_S)
        except (serial.SerialException, OSError, ValueError) as exc:
            raise LaserError(f"cannot open the laser port {self._url}: {exc}") from exc

    def _fail_pending(self, reason: str) -> None:
        pending, self._pending = self._pending, None
        if pending is not None:
            pending.failure = reason
            pending.done.set()

    def _require_open(self) -> serial.SerialBase:
        if self._port is None:
            raise LaserError(f"laser on {self._url} is not open")
        return self._port
