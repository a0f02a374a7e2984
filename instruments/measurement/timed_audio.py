"""An AudioInterface around another one that notes when each input block arrived, and guards the capture.

A pump thread takes the blocks from the real stream as soon as the callback
queues them, notes (start, stop, time.monotonic()) for each (the audio's
time line for clocks.lower_envelope), keeps the last few periods of raw
input for the live panels, and hands the blocks on to ``capture`` through a
queue of its own. It also ends the capture, by setting ``stop`` (the event
capture() watches as its cancel), when:

- the caller's ``cancel`` is set;
- a block reports an xrun, ``end_on_xrun`` and periods are being kept
  (``keeping``, set by the measurement): the block and everything after it
  are withheld, so the periods captured before it stay whole (capture()
  would otherwise discard them and start averaging again). With a serial
  laser that is the only safe reaction: an xrun loses or invents audio
  samples, so the audio's sample counter no longer runs with the host clock
  the laser is aligned by, and the periods on either side of it do not line
  up with the laser's stream the same way. An xrun while the driver still
  settles (or with ``end_on_xrun`` False) is passed on: capture() settles,
  or averages, again after it, and the audio's time line is taken from the
  blocks after it (``arrivals(since_xrun=True)``).
"""
from __future__ import annotations

import queue
import threading
import time

import numpy as np

from instruments.audio.interface import AudioInterface
from instruments.audio.stream_core import XRUN_FLAGS, InputBlock, LoopedExcitation, StreamCounters


class TimedAudio:
    def __init__(self, audio: AudioInterface, stop: threading.Event, *, cancel: threading.Event | None = None,
                 end_on_xrun: bool = True, keep_samples: int = 0, queue_blocks: int = 4096):
        self.inner = audio
        self.sample_rate = audio.sample_rate
        self.channel_map = audio.channel_map
        self.calibration = audio.calibration
        self.stop_event = stop
        self.cancel = cancel
        self.end_on_xrun = end_on_xrun
        self._queue: queue.Queue[InputBlock] = queue.Queue(maxsize=queue_blocks)
        self._pump: threading.Thread | None = None
        self._quit = threading.Event()
        # NB: appended by the pump thread, read (copied) by the measurement thread.
        self._log: list[tuple[int, int, float]] = []
        self.xrun_at: int | None = None           # input index of the block whose xrun ended the capture
        self.passed_xruns: list[int] = []         # input index of the blocks with an xrun passed on
        self.keeping = False                      # NB: set by the measurement thread once a period is kept
        self.handed_out_until = 0                 # stop index of the last block given to capture()
        self._keep = max(int(keep_samples), 0)
        self._ring = np.zeros((self._keep, audio.channel_map.n_inputs), dtype=np.float32)
        self._ring_end = 0                        # input index after the newest sample in the ring
        self._ring_lock = threading.Lock()

    # --- AudioInterface -------------------------------------------------------------------------
    def start(self, excitation: LoopedExcitation) -> None:
        self.inner.start(excitation)
        self._quit.clear()
        self._pump = threading.Thread(target=self._run, name="timed-audio-pump", daemon=True)
        self._pump.start()

    def read_blocks(self, timeout: float) -> tuple[InputBlock, ...]:
        try:
            blocks = [self._queue.get(timeout=max(timeout, 0.0))]
        except queue.Empty:
            return ()
        while True:
            try:
                blocks.append(self._queue.get_nowait())
            except queue.Empty:
                break
        self.handed_out_until = blocks[-1].stop
        return tuple(blocks)

    @property
    def running(self) -> bool:
        return self.inner.running

    def fade_out(self) -> None:
        self.inner.fade_out()

    @property
    def output_finished(self) -> bool:
        return self.inner.output_finished

    def counters(self) -> StreamCounters:
        return self.inner.counters()

    def stop(self) -> None:
        try:
            self.inner.stop()
        finally:
            self._quit.set()
            if self._pump is not None:
                self._pump.join(1.0)

    def describe(self) -> str:
        return self.inner.describe()

    # --- what the measurement reads -----------------------------------------------------------
    def arrivals(self, since_xrun: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(start, stop, host arrival time) of every block taken from the stream so far; with
        ``since_xrun``, of those after the last xrun passed on (one time line: no samples lost between)."""
        log = list(self._log)
        if since_xrun and self.passed_xruns:
            after = self.passed_xruns[-1]
            log = [entry for entry in log if entry[0] > after]
        if not log:
            return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
        a = np.array(log, dtype=np.float64)
        return a[:, 0].astype(np.int64), a[:, 1].astype(np.int64), a[:, 2]

    def raw_samples(self, start: int, stop: int) -> np.ndarray | None:
        """Raw input (FS) of samples start .. stop-1 if still kept, else None."""
        with self._ring_lock:
            first = self._ring_end - self._keep
            if start < max(first, 0) or stop > self._ring_end or stop - start > self._keep:
                return None
            index = np.arange(start, stop) % self._keep
            return self._ring[index].copy()

    # --- the pump thread --------------------------------------------------------------------------
    def _run(self) -> None:
        while not self._quit.is_set():
            if self.cancel is not None and self.cancel.is_set():
                self.stop_event.set()
            try:
                blocks = self.inner.read_blocks(0.02)
            except Exception:       # the stream is gone: capture() sees no more blocks and says why
                return
            now = time.monotonic()
            for block in blocks:
                self._log.append((block.start, block.stop, now))
                if self.xrun_at is not None:
                    continue
                if block.flags & XRUN_FLAGS:
                    if self.end_on_xrun and self.keeping:
                        self.xrun_at = block.start
                        self.stop_event.set()
                        continue
                    self.passed_xruns.append(block.start)
                self._remember(block)
                try:
                    self._queue.put_nowait(block)
                except queue.Full:    # capture() sees the gap in the counter and drops that period
                    pass

    def _remember(self, block: InputBlock) -> None:
        if not self._keep:
            return
        samples = block.samples[-self._keep:]
        start = block.stop - samples.shape[0]
        with self._ring_lock:
            self._ring[np.arange(start, block.stop) % self._keep] = samples
            self._ring_end = max(self._ring_end, block.stop)
