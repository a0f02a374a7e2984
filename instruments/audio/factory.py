"""Sound cards by specification: ``open_audio(AudioSpec(...))`` is the one
place an AudioInterface is made, whatever its back end.

A back end is a module with ``open_from_spec(spec) -> AudioInterface``,
named in BACKENDS by its import path: the table loads nothing, so PortAudio
and the rig's JACK code load only when their card is opened.
``register_audio_backend`` adds one from elsewhere (a plug-in, a test).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from importlib import import_module
from typing import Any, Callable, Mapping

from instruments.audio.config import AudioDeviceChoice, Calibration, ChannelMap
from instruments.audio.errors import AudioError
from instruments.audio.interface import AudioInterface

#: back end -> the module whose open_from_spec makes it.
BACKENDS: dict[str, str] = {
    "sounddevice": "instruments.audio.sounddevice_audio",    # a PortAudio device: WASAPI, ASIO, CoreAudio, ALSA, JACK
    "simulated": "instruments.audio.simulated",              # the in-process simulated rig
    "rig": "instruments.rig.workstation",                    # the JACK virtual rig, through PortAudio
}
_registered: dict[str, Callable[[AudioSpec], AudioInterface]] = {}


@dataclass(frozen=True)
class AudioSpec:
    """Which sound card and how it is wired. None: the back end's own
    (the simulated and the virtual rig know their calibration, channel map and
    rate). ``options`` are the back end's: blocksize, queue_blocks; simulated:
    driver, realtime, seed, noise, faults, feed; rig: rig (a handle or a
    name), runtime_dir."""

    backend: str = "sounddevice"
    device: AudioDeviceChoice | None = None
    calibration: Calibration | None = None
    sample_rate: int | None = None
    channel_map: ChannelMap | None = None
    options: Mapping[str, Any] = field(default_factory=dict)


def audio_backends() -> tuple[str, ...]:
    return tuple(sorted({*BACKENDS, *_registered}))


def register_audio_backend(name: str, opener: Callable[[AudioSpec], AudioInterface]) -> None:
    _registered[name] = opener


def open_audio(spec: AudioSpec) -> AudioInterface:
    """The sound card ``spec`` names; its stream opens at ``start()``."""
    opener = _registered.get(spec.backend)
    if opener is None:
        if spec.backend not in BACKENDS:
            raise AudioError(f"unknown audio back end {spec.backend!r}; known: {', '.join(audio_backends())}")
        opener = import_module(BACKENDS[spec.backend]).open_from_spec
    return opener(spec)
