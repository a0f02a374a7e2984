"""The workstation's side of the virtual rig: a SoundDeviceAudio wired and calibrated for it."""
from __future__ import annotations

from pathlib import Path

from instruments.audio.config import JACK_HOSTAPI, AudioDeviceChoice
from instruments.rig.manager import RigError, RigHandle, find_rig
from instruments.rig.state import DEFAULT_NAME

# PortAudio's JACK host API lists the JACK server's system ports as the device "system".
RIG_DEVICE = AudioDeviceChoice("system", JACK_HOSTAPI)


def rig_audio(rig: RigHandle | str = DEFAULT_NAME, runtime_dir: Path | None = None, **options):
    """SoundDeviceAudio on the running rig: its JACK server, calibration, channel map and rate.

    Points PortAudio at the rig's JACK server first (instruments.audio.portaudio.use_jack_server),
    so no stream may be open. ``options`` go to SoundDeviceAudio (blocksize, queue_blocks).
    Call instruments.audio.portaudio.release() before stopping the rig.
    """
    from instruments.audio import portaudio
    from instruments.audio.factory import AudioSpec, open_audio

    handle = rig if isinstance(rig, RigHandle) else find_rig(rig, runtime_dir)
    if handle is None:
        raise RigError(f"rig {rig!r} is not running (start it with 'linpar rig start')")
    state = handle.state
    portaudio.use_jack_server(state.jack_server)
    return open_audio(AudioSpec("sounddevice", RIG_DEVICE, state.workstation_calibration, state.sample_rate,
                                state.workstation_channel_map, options))


def open_from_spec(spec):
    """The factory's back end "rig" (instruments/audio/factory.py): options rig (handle or name) and
    runtime_dir pick the rig, the others go to SoundDeviceAudio; a calibration or channel map given in
    the spec replaces the rig's own."""
    options = dict(spec.options)
    audio = rig_audio(options.pop("rig", DEFAULT_NAME), options.pop("runtime_dir", None), **options)
    audio.calibration = spec.calibration or audio.calibration
    audio.channel_map = spec.channel_map or audio.channel_map
    return audio
