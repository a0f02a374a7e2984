"""The sound card: a full-duplex stream that loops the excitation and records
voltage, current and (optionally) the laser's analog output.

``SoundDeviceAudio`` is the real one (python-sounddevice / PortAudio),
``SimulatedAudio`` the in-process simulation with the same constructor shape;
both satisfy ``AudioInterface`` and are made by ``open_audio(AudioSpec(...))``
(factory.py). ``capture`` runs one measurement on either.

Names are loaded on first use (PEP 562): importing the package loads neither
PortAudio (that happens when a real stream is opened or the devices are
listed; AudioUnavailable if it is missing) nor the simulated rig, whose
engine itself imports instruments.audio.config.
"""
from importlib import import_module

_EXPORTS = {
    "capture": "capture_loop", "CaptureStats": "captured", "CapturedSignals": "captured",
    "AudioConfigError": "config", "AudioDeviceChoice": "config", "Calibration": "config", "ChannelMap": "config",
    "JACK_HOSTAPI": "config",
    "AudioSpec": "factory", "audio_backends": "factory", "open_audio": "factory",
    "AudioError": "errors", "AudioUnavailable": "errors", "CaptureCancelled": "errors",
    "AudioDeviceInfo": "interface", "AudioInterface": "interface",
    "SimulatedAudio": "simulated",
    "SoundDeviceAudio": "sounddevice_audio", "find_device": "sounddevice_audio", "list_devices": "sounddevice_audio",
    "InputBlock": "stream_core", "LoopedExcitation": "stream_core", "StreamCounters": "stream_core",
}
__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    if name not in _EXPORTS:
        raise AttributeError(f"module 'instruments.audio' has no attribute {name!r}")
    value = getattr(import_module(f"instruments.audio.{_EXPORTS[name]}"), name)
    globals()[name] = value
    return value


def __dir__():
    return __all__
