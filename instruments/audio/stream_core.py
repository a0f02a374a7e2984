"""The part of a full-duplex stream that runs in the audio callback, shared by every backend.

One ``DuplexCore.process(indata, outdata, flags)`` per callback:

- output: the next samples of the looped excitation, from a precomputed
  period, under a raised-cosine fade-in (from the first sample) and, once
  asked for, a fade-out, then silence;
- input: a copy of the block (the callback's buffer is reused by the
  driver), tagged with the running input sample counter and the callback's
  status flags, put on a bounded queue without ever blocking; when the queue
  is full the block is dropped and counted, and the consumer sees the gap in
  the counter.

Nothing else happens in the callback: no allocation that grows, no locks, no
logging. The counters are plain ints written only by the callback thread
(# NB: shared with the consumer, which only reads them; CPython's int
assignment is atomic).
"""
from __future__ import annotations

import queue
from dataclasses import dataclass

import numpy as np

from instruments.audio.config import Calibration

# PortAudio's PaStreamCallbackFlags bits (portaudio.h).
INPUT_UNDERFLOW = 0x01
INPUT_OVERFLOW = 0x02
OUTPUT_UNDERFLOW = 0x04
OUTPUT_OVERFLOW = 0x08
PRIMING_OUTPUT = 0x10
# The flags that mean samples were lost or invented somewhere in the chain.
XRUN_FLAGS = INPUT_UNDERFLOW | INPUT_OVERFLOW | OUTPUT_UNDERFLOW | OUTPUT_OVERFLOW


@dataclass(frozen=True, slots=True, eq=False)
class LoopedExcitation:
    """One period of output samples (FS units, already clipped to +-1) and the fade length.

    Build it with ``from_volts``: the requested terminal voltage goes through
    the calibration, and samples that would exceed full scale are clipped and
    counted (``clipped_per_period``) so the capture can report it.
    """

    period: np.ndarray          # float32, read-only
    fade_samples: int
    clipped_per_period: int = 0
    requested_peak_fs: float = 0.0

    @classmethod
    def from_volts(cls, waveform_volts: np.ndarray, calibration: Calibration,
                   fade_samples: int) -> LoopedExcitation:
        wanted = calibration.volts_to_output(np.asarray(waveform_volts, dtype=np.float64).ravel())
        if wanted.size == 0:
            raise ValueError("the excitation has no samples")
        if not np.all(np.isfinite(wanted)):
            raise ValueError("the excitation has samples that are not finite")
        if fade_samples < 0:
            raise ValueError(f"fade_samples must be >= 0, got {fade_samples}")
        clipped = int(np.count_nonzero(np.abs(wanted) > 1.0))
        period = np.clip(wanted, -1.0, 1.0).astype(np.float32)
        period.flags.writeable = False
        return cls(period, int(fade_samples), clipped, float(np.max(np.abs(wanted))))

    @property
    def period_samples(self) -> int:
        return self.period.size


@dataclass(frozen=True, slots=True, eq=False)
class InputBlock:
    """Input samples of one callback: (frames, n_inputs) float32 FS, first sample's index, status flags."""

    start: int
    samples: np.ndarray
    flags: int = 0

    @property
    def stop(self) -> int:
        return self.start + self.samples.shape[0]


@dataclass(frozen=True, slots=True)
class StreamCounters:
    """A snapshot of what the callback counted since the stream started."""

    callbacks: int = 0
    frames_in: int = 0
    frames_out: int = 0
    input_underflows: int = 0
    input_overflows: int = 0
    output_underflows: int = 0
    output_overflows: int = 0
    priming_output: int = 0
    queue_overflows: int = 0

    @property
    def xruns(self) -> int:
        """Callbacks whose status flags say samples were lost or invented."""
        return self.input_underflows + self.input_overflows + self.output_underflows + self.output_overflows


class DuplexCore:
    """Callback-side state of one stream: the output player and the input queue."""

    def __init__(self, excitation: LoopedExcitation, n_inputs: int, n_outputs: int, output_channel: int,
                 queue_blocks: int = 256):
        if not 0 <= output_channel < n_outputs:
            raise ValueError(f"output channel {output_channel} is not among the {n_outputs} output channels")
        self.excitation = excitation
        self.n_inputs = n_inputs
        self.n_outputs = n_outputs
        self.output_channel = output_channel
        self.blocks: queue.Queue[InputBlock] = queue.Queue(maxsize=queue_blocks)
        self._period = excitation.period
        self._fade = max(int(excitation.fade_samples), 0)
        # Raised-cosine fade windows, computed once: the callback allocates no array of its own.
        ramp = np.pi * np.arange(self._fade, dtype=np.float64) / max(self._fade, 1)
        self._fade_in = 0.5 - 0.5 * np.cos(ramp)
        self._fade_out = 0.5 + 0.5 * np.cos(ramp)
        # NB: written by the callback thread only; read by the consumer.
        self._callbacks = 0
        self._in_index = 0
        self._out_index = 0
        self._flag_counts = [0, 0, 0, 0, 0]
        self._queue_overflows = 0
        self._fade_out_start: int | None = None
        self.output_finished = False
        # NB: written by the consumer, read by the callback.
        self._fade_out_requested = False

    # --- consumer side -----------------------------------------------------
    def request_fade_out(self) -> None:
        """Fade the output out from the next callback on; ``output_finished`` turns True after."""
        self._fade_out_requested = True

    def take_blocks(self, timeout: float) -> tuple[InputBlock, ...]:
        """Every queued block, oldest first; waits up to ``timeout`` s for the first; () if none came."""
        try:
            blocks = [self.blocks.get(timeout=max(timeout, 0.0))]
        except queue.Empty:
            return ()
        while True:
            try:
                blocks.append(self.blocks.get_nowait())
            except queue.Empty:
                return tuple(blocks)

    def counters(self) -> StreamCounters:
        f = self._flag_counts
        return StreamCounters(self._callbacks, self._in_index, self._out_index, f[0], f[1], f[2], f[3], f[4],
                              self._queue_overflows)

    # --- callback side -----------------------------------------------------
    def process(self, indata: np.ndarray | None, outdata: np.ndarray | None, flags: int) -> None:
        """One callback: fill ``outdata`` (frames, n_outputs), enqueue a copy of ``indata``."""
        self._callbacks += 1
        if flags:
            for bit in range(5):
                if flags & (1 << bit):
                    self._flag_counts[bit] += 1
        if outdata is not None:
            self._fill_output(outdata)
        if indata is not None:
            frames = indata.shape[0]
            block = InputBlock(self._in_index, indata.copy(), int(flags))   # the (necessary!) copy
            self._in_index += frames
            try:
                self.blocks.put_nowait(block)
            except queue.Full:
                self._queue_overflows += 1

    def _fill_output(self, outdata: np.ndarray) -> None:
        """The looped period into the output channel, faded in and out, in place (no array allocated)."""
        frames = outdata.shape[0]
        start = self._out_index
        self._out_index += frames
        outdata.fill(0.0)
        if self.output_finished:
            return
        if self._fade_out_requested and self._fade_out_start is None:
            self._fade_out_start = start
        into = None if self._fade_out_start is None else start - self._fade_out_start   # samples into the fade-out
        if into is not None and (self._fade == 0 or into >= self._fade):
            self.output_finished = True
            return
        column = outdata[:, self.output_channel]
        period = self._period
        done, position = 0, start % period.size
        while done < frames:
            n = min(frames - done, period.size - position)
            column[done:done + n] = period[position:position + n]
            done, position = done + n, 0
        if start < self._fade:
            k = min(frames, self._fade - start)
            column[:k] *= self._fade_in[start:start + k]
        if into is not None:
            k = min(frames, self._fade - into)
            column[:k] *= self._fade_out[into:into + k]
            column[k:] = 0.0
            if into + frames >= self._fade:
                self.output_finished = True
