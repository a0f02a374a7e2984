"""A simulated sound card wired to a simulated rig, in-process, no PortAudio needed.

A thread plays the part of the audio driver: every ``blocksize`` samples it
calls the same DuplexCore as the real callback (output from the looped
excitation, input copied into the bounded queue), and feeds the output
through a RigEngine (amplifier, BlockDriver, sensors, noise, faults) whose
response is the input of the next callback: one block of round-trip latency,
as on a real card. So the capture path, queue, counters and calibration are
the real ones; only the hardware is simulated.

``realtime=True`` runs the card on a clock of its own, a FrameClock from the
moment it is made (instruments/rig/frame_clock.py): the block that starts
at frame n is handed over, and the next one played, at the clock's host time
of frame n, as a card's crystal would time it. A thread that wakes late
(a busy machine) catches up: the hardware kept its time, so late hand-overs
are not xruns; the only xruns are the ones asked for (``inject_xrun``). A
DisplacementFeed given as ``feed`` takes the same clock, so a virtual laser
that measures the cone does so on the audio's frame counter, never on when a
thread woke up. ``realtime=False`` runs as fast as the consumer takes the
blocks (it waits while the queue is full instead of dropping), for fast tests.
"""
from __future__ import annotations

import threading
import time
from typing import TYPE_CHECKING

import numpy as np

from instruments.audio.core_device import CoreBackedDevice
from instruments.audio.config import AudioDeviceChoice, Calibration, ChannelMap
from instruments.audio.errors import AudioError
from instruments.audio.stream_core import (
    INPUT_OVERFLOW, OUTPUT_UNDERFLOW, DuplexCore, LoopedExcitation)
from instruments.rig.engine import RIG_CALIBRATION, RIG_CHANNEL_MAP, RigEngine, RigFaults, RigNoise
from instruments.rig.frame_clock import FrameClock
from instruments.simulation.block_driver import BlockDriver

if TYPE_CHECKING:      # the feed's module brings the pty emulator: not needed to run the card
    from instruments.rig.laser_feed import DisplacementFeed

SIMULATED_DEVICE = AudioDeviceChoice("simulated rig", "in-process")
PRECISE_S = 0.0005       # the last stretch before a hand-over is waited out in short sleeps


def open_from_spec(spec) -> SimulatedAudio:
    """The factory's back end "simulated" (instruments/audio/factory.py)."""
    return SimulatedAudio(spec.device, spec.calibration or RIG_CALIBRATION, spec.sample_rate or 48000,
                          spec.channel_map or RIG_CHANNEL_MAP, **spec.options)


class SimulatedAudio(CoreBackedDevice):
    """AudioInterface on a simulated rig. Constructor shape shared with SoundDeviceAudio.

    The simulated hardware follows ``calibration``, so a capture through it
    returns the driver's own volts, amperes and metres. ``driver`` defaults to
    the LinearBlockDriver of resources/drivers/paper.json.
    """

    def __init__(self, device: AudioDeviceChoice | None = None, calibration: Calibration = RIG_CALIBRATION,
                 sample_rate: int = 48000, channel_map: ChannelMap = RIG_CHANNEL_MAP, *,
                 blocksize: int = 1024, queue_blocks: int = 256, driver: BlockDriver | None = None,
                 noise: RigNoise = RigNoise(), faults: RigFaults = RigFaults(), realtime: bool = True,
                 seed: int | None = None, feed: DisplacementFeed | None = None):
        self.device = device or SIMULATED_DEVICE
        self.calibration = calibration
        self.sample_rate = int(sample_rate)
        self.channel_map = channel_map
        self.blocksize = int(blocksize)
        self.queue_blocks = int(queue_blocks)
        self.realtime = realtime
        if driver is None:
            from instruments.rig.engine import default_driver
            driver, _ = default_driver("paper", self.sample_rate)
        if driver.sample_rate != self.sample_rate:
            raise ValueError(f"the driver runs at {driver.sample_rate} Hz, the sound card at {self.sample_rate} Hz")
        # The card's crystal runs from now on, whether or not a stream is open.
        self.clock = FrameClock(time.monotonic(), self.sample_rate)
        self.engine = RigEngine(driver, calibration, noise, faults, None, seed)
        if feed is not None:
            self.engine.displacement_sinks.append(feed.use_clock(self.clock).sink)
        self.first_frame = 0       # the clock's frame of the running stream's first output sample
        self._core: DuplexCore | None = None
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        # NB: set by the consumer (fault injection), read by the simulation thread.
        self._flags_lock = threading.Lock()
        self._pending_flags = 0
        self._delivering = True

    @property
    def faults(self) -> RigFaults:
        return self.engine.faults

    @faults.setter
    def faults(self, faults: RigFaults) -> None:
        self.engine.faults = faults

    def inject_xrun(self) -> None:
        """The next callback reports an xrun (input overflow and output underflow), as PortAudio on JACK does."""
        self._add_flags(INPUT_OVERFLOW | OUTPUT_UNDERFLOW)

    def _add_flags(self, flags: int) -> None:
        with self._flags_lock:
            self._pending_flags |= flags

    def stop_delivering(self) -> None:
        """From now on no callback comes: what a dead audio server looks like from the stream."""
        self._delivering = False

    def start(self, excitation: LoopedExcitation) -> None:
        if self._thread is not None:
            raise AudioError("the stream is already running: stop() it first")
        cm = self.channel_map
        self._core = DuplexCore(excitation, cm.n_inputs, cm.n_outputs, cm.output, self.queue_blocks)
        self.engine.driver.reset()
        # The stream starts at the next block boundary of the running clock (module doc).
        self.first_frame = int(np.ceil(self.clock.frame_at(time.monotonic()) / self.blocksize)) * self.blocksize \
            if self.realtime else 0
        self._stop.clear()
        self._delivering = True
        self._thread = threading.Thread(target=self._run, args=(self._core,), name="simulated-audio",
                                        daemon=True)
        self._thread.start()

    def _run(self, core: DuplexCore) -> None:
        B, cm = self.blocksize, self.channel_map
        outdata = np.zeros((B, cm.n_outputs), dtype=np.float32)
        indata = np.zeros((B, cm.n_inputs), dtype=np.float32)   # the rig's answer to the previous block
        wired = cm.input_channels()
        n = self.first_frame
        while not self._stop.is_set():
            if self.realtime:
                wait = float(self.clock.host_time(n)) - time.monotonic()
                if wait > PRECISE_S:
                    self._stop.wait(wait - PRECISE_S)
                    continue
                if wait > 0:      # the last stretch in short sleeps: a timed wait overshoots by ~0.1 ms
                    time.sleep(0)
                    continue
            elif core.blocks.full():
                self._stop.wait(0.001)
                continue
            if not self._delivering:
                self._stop.wait(0.01)
                continue
            with self._flags_lock:
                flags, self._pending_flags = self._pending_flags, 0
            core.process(indata, outdata, flags)
            # The hardware's physics costs a real card no host time: let the host's threads take the block
            # before the driver's FIR holds the interpreter.
            time.sleep(0)
            answer = self.engine.process(outdata[:, cm.output], n)
            indata = np.zeros((B, cm.n_inputs), dtype=np.float32)
            for signal, channel in wired.items():
                indata[:, channel] = getattr(answer, signal)
            n += B

    def frame_of_input(self, index):
        """The clock's frame whose answer is input sample ``index`` of the running stream: the first block
        handed over is silence, the answer to output frame f comes a block later (one round trip)."""
        return self.first_frame - self.blocksize + np.asarray(index)

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def stop(self) -> None:
        thread, self._thread = self._thread, None
        if thread is None:
            return
        self._stop.set()
        thread.join(2.0)

    def describe(self) -> str:
        mode = "real time" if self.realtime else "as fast as read"
        return f"SimulatedAudio({self.engine.driver!r}, {self.sample_rate} Hz, {mode})"

    def __enter__(self) -> SimulatedAudio:
        return self

    def __exit__(self, *exc) -> None:
        self.stop()
