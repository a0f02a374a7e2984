"""The real sound card through python-sounddevice: one continuous full-duplex sd.Stream.

Not repeated ``playrec`` calls: the excitation loops from a precomputed
period for as long as the measurement needs, so the driver stays in its
periodic steady state and no period is ever cut by a stream restart.
"""
from __future__ import annotations

import threading
import time

from instruments.audio import portaudio
from instruments.audio.core_device import CoreBackedDevice
from instruments.audio.config import AudioDeviceChoice, Calibration, ChannelMap
from instruments.audio.errors import AudioError
from instruments.audio.interface import AudioDeviceInfo
from instruments.audio.stream_core import DuplexCore, LoopedExcitation

# How long stop() waits for PortAudio before it abandons the stream (see portaudio.py): a fixed
# allowance plus some callback blocks, since stopping and closing on JACK take effect at cycle
# boundaries (measured on the rig: about 4 cycles, 100 ms at 1024 frames, 360 ms at 4096; 530 ms at
# most with four CPU hogs on two cores).
STOP_TIMEOUT_S = 0.7
STOP_TIMEOUT_BLOCKS = 8


def list_devices(refresh: bool = False) -> list[AudioDeviceInfo]:
    """Every device PortAudio knows. Its list dates from its initialisation: ``refresh`` re-initialises
    it first (a card plugged in or a JACK server started since; no stream may be open)."""
    sd = portaudio.sounddevice_module()
    if refresh:
        portaudio.reinitialize()
    apis = sd.query_hostapis()
    return [AudioDeviceInfo(i, d["name"], apis[d["hostapi"]]["name"], d["max_input_channels"],
                            d["max_output_channels"], float(d["default_samplerate"]))
            for i, d in enumerate(sd.query_devices())]


def find_device(choice: AudioDeviceChoice | None, devices: list[AudioDeviceInfo] | None = None) -> AudioDeviceInfo:
    """The device of that name on that host API; the default full-duplex device for None."""
    devices = list_devices() if devices is None else devices
    if choice is None:
        duplex = [d for d in devices if d.full_duplex]
        if not duplex:
            raise AudioError("no full-duplex sound card found (PortAudio lists "
                             f"{', '.join(str(d.choice) for d in devices) or 'no device'})")
        return duplex[0]
    for device in devices:
        if device.name == choice.name and device.hostapi == choice.hostapi:
            return device
    listed = ", ".join(str(d.choice) for d in devices) or "none"
    hint = (" (is the JACK server running, and JACK_DEFAULT_SERVER set before PortAudio started?)"
            if choice.hostapi.startswith("JACK") else "")
    raise AudioError(f"sound card {choice} not found{hint}; PortAudio lists: {listed}")


def open_from_spec(spec) -> SoundDeviceAudio:
    """The factory's back end "sounddevice" (instruments/audio/factory.py)."""
    if spec.calibration is None:
        raise AudioError(f"sound card {spec.device or 'default'}: no calibration given (calibrate the chain first)")
    return SoundDeviceAudio(spec.device, spec.calibration, spec.sample_rate or 48000,
                            spec.channel_map or ChannelMap(), **spec.options)


class SoundDeviceAudio(CoreBackedDevice):
    """AudioInterface on a PortAudio device. Constructor shape shared with SimulatedAudio."""

    def __init__(self, device: AudioDeviceChoice | None, calibration: Calibration, sample_rate: int = 48000,
                 channel_map: ChannelMap = ChannelMap(), *, blocksize: int = 0, queue_blocks: int = 256):
        self.device = device
        self.calibration = calibration
        self.sample_rate = int(sample_rate)
        self.channel_map = channel_map
        self.blocksize = int(blocksize)     # 0: whatever the host API prefers (JACK: its period)
        self.queue_blocks = int(queue_blocks)
        self._core: DuplexCore | None = None
        self._stream = None
        self._device_info: AudioDeviceInfo | None = None
        self._finished = threading.Event()   # set by PortAudio's finished callback
        self._callback_frames = 0            # frames per callback as PortAudio delivers them

    def start(self, excitation: LoopedExcitation) -> None:
        if self._stream is not None:
            raise AudioError("the stream is already running: stop() it first")
        sd = portaudio.sounddevice_module()
        if portaudio.abandoned_reason() is not None:
            raise AudioError(f"PortAudio cannot be used again in this process: {portaudio.abandoned_reason()}")
        info = find_device(self.device)
        cm = self.channel_map
        if cm.n_inputs > info.max_input_channels or cm.n_outputs > info.max_output_channels:
            raise AudioError(f"sound card {info.choice} has {info.max_input_channels} inputs and "
                             f"{info.max_output_channels} outputs; the channel map needs {cm.n_inputs} and "
                             f"{cm.n_outputs}")
        core = DuplexCore(excitation, cm.n_inputs, cm.n_outputs, cm.output, self.queue_blocks)
        self._finished.clear()

        def callback(indata, outdata, frames, time_info, status):
            self._callback_frames = frames
            core.process(indata, outdata, status._flags)

        try:
            stream = sd.Stream(samplerate=self.sample_rate, blocksize=self.blocksize,
                               device=(info.index, info.index), channels=(cm.n_inputs, cm.n_outputs),
                               dtype="float32", callback=callback, finished_callback=self._finished.set)
            stream.start()
        except sd.PortAudioError as exc:
            raise AudioError(f"cannot open {info.choice} at {self.sample_rate} Hz with "
                             f"{cm.n_inputs} in / {cm.n_outputs} out: {exc}") from None
        self._core, self._stream, self._device_info = core, stream, info

    @property
    def running(self) -> bool:
        stream = self._stream
        # NB: PortAudio's JACK host API clears "active" when the server shuts down.
        return stream is not None and not self._finished.is_set() and bool(stream.active)

    def stop(self) -> None:
        """Stop and close; a PortAudio call that does not return in time (STOP_TIMEOUT_*) is abandoned."""
        stream, self._stream = self._stream, None
        if stream is None:
            return
        if not stream.active and portaudio.jack_server_alive() is False and self._uses_jack():
            # The server is gone: stop/close would never return (portaudio.py, fact 2).
            portaudio.mark_abandoned(f"the JACK server '{portaudio.jack_server_name()}' went away mid-stream")
            return

        def close():
            stream.stop()
            stream.close()

        closer = threading.Thread(target=close, name="audio-stream-close", daemon=True)
        closer.start()
        closer.join(STOP_TIMEOUT_S + STOP_TIMEOUT_BLOCKS * self._callback_frames / self.sample_rate)
        if closer.is_alive():
            portaudio.mark_abandoned(f"closing the stream on {self._device_info.choice} hung")

    def describe(self) -> str:
        device = self._device_info.choice if self._device_info else self.device
        return f"SoundDeviceAudio({device or 'default device'}, {self.sample_rate} Hz)"

    def _uses_jack(self) -> bool:
        return self._device_info is not None and self._device_info.hostapi.startswith("JACK")

    def __enter__(self) -> SoundDeviceAudio:
        return self

    def __exit__(self, *exc) -> None:
        self.stop()
