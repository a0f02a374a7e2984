"""The sound card as the measurement sees it: a typing.Protocol and the device list entry.

An AudioInterface plays a looped excitation and records its inputs in one
continuous full-duplex stream. ``start`` opens and starts the stream;
``read_blocks`` hands over the input blocks the callback queued (raw FS
samples with their sample counter); ``fade_out`` asks for the end of the
output; ``stop`` closes the stream and never hangs. Conversion to SI units
(calibration and channel map) happens on the consumer side, in
instruments.audio.capture_loop, identically for every implementation.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

from instruments.audio.config import AudioDeviceChoice, Calibration, ChannelMap
from instruments.audio.stream_core import InputBlock, LoopedExcitation, StreamCounters


@dataclass(frozen=True, slots=True)
class AudioDeviceInfo:
    """One entry of the device list."""

    index: int
    name: str
    hostapi: str
    max_input_channels: int
    max_output_channels: int
    default_samplerate: float

    @property
    def choice(self) -> AudioDeviceChoice:
        return AudioDeviceChoice(self.name, self.hostapi)

    @property
    def full_duplex(self) -> bool:
        return self.max_input_channels > 0 and self.max_output_channels > 0


@runtime_checkable
class AudioInterface(Protocol):
    sample_rate: int
    channel_map: ChannelMap
    calibration: Calibration

    def start(self, excitation: LoopedExcitation) -> None:
        """Open and start the stream; the excitation plays from its first sample, faded in."""
        ...

    def read_blocks(self, timeout: float) -> tuple[InputBlock, ...]:
        """The queued input blocks, oldest first; waits up to ``timeout`` s for the first. () if none came."""
        ...

    @property
    def running(self) -> bool:
        """False once the stream ended by itself (device or server gone) or was stopped."""
        ...

    def fade_out(self) -> None:
        """Start the fade-out; ``output_finished`` turns True when it has been played."""
        ...

    @property
    def output_finished(self) -> bool:
        ...

    def counters(self) -> StreamCounters:
        """What the callback counted: samples, status flags, dropped blocks."""
        ...

    def stop(self) -> None:
        """Stop and close the stream. Returns within about a second even if the device hangs."""
        ...

    def describe(self) -> str:
        """One line for logs and recordings: implementation, device, rate."""
        ...
