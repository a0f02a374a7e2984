"""A simulated sound card wired to a simulated rig, in-process, no PortAudio needed.

A thread plays the part of the audio driver: every ``blocksize`` samples it
calls the same DuplexCore as the real callback (output from the looped
excitation, input copied into the bounded queue), and feeds the output
through a RigEngine (amplifier, BlockDriver, sensors, noise, faults) whose
response is the input of the next callback: one block of round-trip latency,
as on a real card. So the capture path, queue, counters and calibration are
the real ones; only the hardware is simulated.

``realtime=True`` paces the thread at the sample rate (an xrun is reported
when it falls more than a block behind, as PortAudio does); ``realtime=False``
runs as fast as the consumer takes the blocks (it waits while the queue is
full instead of dropping), for fast tests.
"""
from __future__ import annotations

import threading
import time

import numpy as np

from instruments.audio.core_device import CoreBackedDevice
from instruments.audio.config import AudioDeviceChoice, Calibration, ChannelMap
from instruments.audio.errors import AudioError
from instruments.audio.stream_core import (
    INPUT_OVERFLOW, OUTPUT_UNDERFLOW, DuplexCore, LoopedExcitation)
from instruments.rig.engine import RIG_CALIBRATION, RIG_CHANNEL_MAP, RigEngine, RigFaults, RigNoise
from instruments.simulation.block_driver import BlockDriver

SIMULATED_DEVICE = AudioDeviceChoice("simulated rig", "in-process")


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
                 seed: int | None = None, displacement_sinks=None):
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
        self.engine = RigEngine(driver, calibration, noise, faults, displacement_sinks, seed)
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
        t0, n = time.monotonic(), 0
        while not self._stop.is_set():
            if self.realtime:
                lag = time.monotonic() - (t0 + (n + B) / self.sample_rate)
                if lag < 0:
                    self._stop.wait(-lag)
                    continue
                if lag > B / self.sample_rate:       # more than a block late: an xrun, then carry on
                    self._add_flags(INPUT_OVERFLOW | OUTPUT_UNDERFLOW)
                    t0 = time.monotonic() - (n + B) / self.sample_rate
            elif core.blocks.full():
                self._stop.wait(0.001)
                continue
            if not self._delivering:
                self._stop.wait(0.01)
                continue
            with self._flags_lock:
                flags, self._pending_flags = self._pending_flags, 0
            core.process(indata, outdata, flags)
            answer = self.engine.process(outdata[:, cm.output], n)
            indata = np.zeros((B, cm.n_inputs), dtype=np.float32)
            for signal, channel in wired.items():
                indata[:, channel] = getattr(answer, signal)
            n += B

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
