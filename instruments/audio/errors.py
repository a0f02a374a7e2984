"""Errors of the audio path. Messages are one line, shown to the user as they are."""
from __future__ import annotations

from typing import TYPE_CHECKING

from analysis.errors import LinparError

if TYPE_CHECKING:
    from instruments.audio.captured import CapturedSignals


class AudioError(LinparError, RuntimeError):
    """The sound card cannot be used or stopped working.

    ``partial`` holds the whole periods captured before the failure (possibly
    none) when the error ends a capture; None when nothing was being captured.
    """

    def __init__(self, message: str, partial: CapturedSignals | None = None):
        super().__init__(" ".join(str(message).splitlines()))
        self.partial = partial


class AudioUnavailable(AudioError):
    """PortAudio (the library behind python-sounddevice) is not installed or cannot load."""


class CaptureCancelled(AudioError):
    """The caller cancelled the capture; ``partial`` keeps what was captured."""
