"""What every audio device does through its DuplexCore: the part the real and the simulated device share.

Both devices hand their callback's work to one DuplexCore (stream_core.py);
reading blocks, the fade-out, the counters go straight to it. The devices
differ only in how they start and stop the stream that drives the core.
"""
from __future__ import annotations

from instruments.audio.errors import AudioError
from instruments.audio.stream_core import DuplexCore, InputBlock, StreamCounters


class CoreBackedDevice:
    """Mixin: the device sets `self._core` (None until started)."""

    _core: DuplexCore | None

    def read_blocks(self, timeout: float) -> tuple[InputBlock, ...]:
        return self._require_core().take_blocks(timeout)

    def fade_out(self) -> None:
        self._require_core().request_fade_out()

    @property
    def output_finished(self) -> bool:
        return self._core is not None and self._core.output_finished

    def counters(self) -> StreamCounters:
        return self._core.counters() if self._core is not None else StreamCounters()

    def _require_core(self) -> DuplexCore:
        if self._core is None:
            raise AudioError("the stream was never started: call start() first")
        return self._core
