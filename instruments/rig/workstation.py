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
    from instruments.audio.sounddevice_audio import SoundDeviceAudio

    handle = rig if isinstance(rig, RigHandle) else find_rig(rig, runtime_dir)
    if handle is None:
        raise RigError(f"rig {rig!r} is not running (start it with 'linpar rig start')")
    state = handle.state
    portaudio.use_jack_server(state.jack_server)
    return SoundDeviceAudio(RIG_DEVICE, state.workstation_calibration, state.sample_rate,
                            state.workstation_channel_map, **options)
