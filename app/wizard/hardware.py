"""The hardware the wizard measures with, and the Test of each device. Qt-free.

A HardwareConfig is what the Hardware page chose: the in-process simulator,
the JACK virtual rig, or a sound card with its channel map and calibration;
and the laser (none, the analog input of the channel map, or the serial
ILD1420). `open_audio` builds the AudioInterface for one job: each job opens
and closes its own, so no stream outlives the job that needed it.
"""
from __future__ import annotations

import sys
import threading
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from analysis.errors import LinparError
from instruments.audio.config import AudioDeviceChoice, Calibration, ChannelMap
from instruments.laser.factory import DEFAULT_MODEL, LaserSpec
from instruments.rig.engine import RIG_CALIBRATION, RIG_CHANNEL_MAP
from instruments.rig.state import DEFAULT_NAME
from instruments.serial_ports import port_example

SIMULATOR, RIG, SOUNDCARD = "simulator", "rig", "soundcard"
NO_LASER, ANALOG_LASER, SERIAL_LASER = "none", "analog", "serial"
TEST_PERIOD = 8192
TEST_PERIODS = 2
TEST_SETTLE = 9           # 9 x 8192 > the virtual rig's 65,536-tap FIR plus a block of latency
TEST_LEVEL_V = 0.1        # V rms: quiet, and well inside any driver's small-signal range


@dataclass(frozen=True, slots=True)
class HardwareConfig:
    kind: str = SIMULATOR
    realtime: bool = True                          # simulator: paced at the sample rate, like a sound card
    rig_name: str = DEFAULT_NAME
    rig_runtime_dir: str | None = None
    device: AudioDeviceChoice | None = None
    sample_rate: int = 48000
    channel_map: ChannelMap = RIG_CHANNEL_MAP
    calibration: Calibration = RIG_CALIBRATION
    laser: str = ANALOG_LASER
    laser_model: str = DEFAULT_MODEL
    laser_port: str = ""
    laser_rate_hz: float = 4000.0
    # Simulator only: a driver to simulate instead of the paper's (a resistor for the calibration).
    simulated_driver: object = field(default=None, compare=False)

    @property
    def has_displacement(self) -> bool:
        return self.laser == ANALOG_LASER and self.channel_map.laser_analog is not None

    def laser_spec(self) -> LaserSpec:
        """The serial laser chosen, for instruments.laser.open_laser."""
        return LaserSpec(self.laser_model, self.laser_port)

    def key(self) -> str:
        """Who the calibration corrections belong to: the chain, not the driver on it."""
        if self.kind == SIMULATOR:
            return "simulator"
        if self.kind == RIG:
            return f"rig:{self.rig_name}"
        device = self.device.name if self.device else "default"
        hostapi = self.device.hostapi if self.device else ""
        cm = self.channel_map
        return f"soundcard:{device}|{hostapi}|out{cm.output}|u{cm.voltage}|i{cm.current}"

    def describe(self) -> str:
        laser = {NO_LASER: "no laser", ANALOG_LASER: f"laser on input {self.channel_map.laser_analog}",
                 SERIAL_LASER: f"ILD1420 on {self.laser_port or '?'} at {self.laser_rate_hz:g} Hz"}[self.laser]
        if self.kind == SIMULATOR:
            pace = "real time" if self.realtime else "as fast as possible"
            return f"in-process simulator ({pace}), {laser}"
        if self.kind == RIG:
            return f"JACK virtual rig '{self.rig_name}', {laser}"
        return f"sound card {self.device or 'default'} at {self.sample_rate / 1000:g} kHz, {laser}"

    def measured_channel_map(self) -> ChannelMap:
        """The channel map with the laser input dropped when the laser is not used."""
        if self.laser == ANALOG_LASER:
            return self.channel_map
        return replace(self.channel_map, laser_analog=None)


def virtual_rig_unavailable(platform: str | None = None) -> str | None:
    """Why the JACK virtual rig cannot run on this system (``sys.platform`` unless given), or None where it can."""
    if (platform or sys.platform).startswith("linux"):
        return None
    return ("the virtual rig runs on Linux only: it needs a JACK server of its own and pseudo-terminals for its "
            "laser. The in-process simulator stands in for it here, with the same simulated driver and laser")


def find_virtual_rig(name: str = DEFAULT_NAME, runtime_dir: str | None = None):
    """The running rig of that name, or None (always None where the rig cannot run). Reads a few small files:
    fine on the GUI thread."""
    if virtual_rig_unavailable() is not None:
        return None         # and no look for a rig's process: os.kill(pid, 0) would end it on Windows
    from instruments.rig.manager import find_rig
    try:
        return find_rig(name, Path(runtime_dir) if runtime_dir else None)
    except (OSError, LinparError):      # a bad name, a state file of another version: no usable rig
        return None


def open_audio(config: HardwareConfig, calibration: Calibration | None = None):
    """The AudioInterface of `config`; `calibration` (the corrected one) is what the workstation believes.

    The simulated hardware keeps the true calibration: a correction changes
    only how the workstation reads the samples, as on a real bench.
    """
    from instruments.audio.factory import AudioSpec
    from instruments.audio.factory import open_audio as open_spec

    calibration = calibration or config.calibration
    if config.kind == SIMULATOR:
        spec = AudioSpec("simulated", calibration=RIG_CALIBRATION, sample_rate=config.sample_rate,
                         options={"driver": config.simulated_driver, "realtime": config.realtime})
    elif config.kind == RIG:
        from instruments.rig.manager import RigError
        handle = find_virtual_rig(config.rig_name, config.rig_runtime_dir)
        if handle is None:
            raise RigError(f"the virtual rig {config.rig_name!r} is not running (start it with 'linpar rig "
                           f"start', or choose the in-process simulator)")
        spec = AudioSpec("rig", options={"rig": handle})
    else:
        spec = AudioSpec("sounddevice", config.device, calibration, config.sample_rate)
    audio = open_spec(spec)
    audio.channel_map = config.measured_channel_map()
    audio.calibration = calibration
    return audio


def list_sound_cards() -> list:
    """Every device PortAudio lists (AudioUnavailable when PortAudio is missing). Those that only play or only
    record are listed too, with why they cannot be used: Windows lists a card under WASAPI, MME and DirectSound
    as an input and an output apart, and its user should see the card and be told to take its ASIO driver."""
    from instruments.audio.sounddevice_audio import list_devices
    return [d for d in list_devices(refresh=True) if d.max_input_channels or d.max_output_channels]


def test_audio(config: HardwareConfig, cancel: threading.Event | None = None, progress=None) -> str:
    """A short, quiet capture: what the inputs carry, in words (AudioError when the card does not work)."""
    from analysis.multitone import design_multitone
    from instruments.audio import capture

    mt = design_multitone(config.sample_rate, TEST_PERIOD, 50.0, 5000.0, rms=TEST_LEVEL_V, crest_iterations=0)
    audio = open_audio(config)
    captured = capture(audio, mt.waveform, TEST_PERIODS, TEST_SETTLE, cancel=cancel, progress=progress)
    levels = []
    for name, values in captured.signals().items():
        rms = float(np.sqrt(np.mean(np.square(values)))) if values.size else 0.0
        levels.append(_level_text(name, rms))
    stats = captured.stats
    problems = stats.problems()
    found = f"{config.describe()}: {', '.join(levels)} at {TEST_LEVEL_V:g} V rms out"
    if not config.has_displacement:
        found += "; no displacement input"
    return found + (". Problems: " + "; ".join(problems) if problems else "; no dropouts, nothing clipped.")


def test_laser(config: HardwareConfig) -> str:
    """Open the serial laser, set its rate, read a little: what it is and what it reads."""
    from instruments.laser import LaserError, open_laser

    if config.laser != SERIAL_LASER:
        return "no serial laser chosen"
    if not config.laser_port:
        raise LaserError(f"give the laser's serial port (a device such as {port_example()})")
    laser = open_laser(config.laser_spec())
    try:
        info = laser.open()
        laser.configure(config.laser_rate_hz)
        laser.start()
        block = laser.read_block(1.0)
        laser.stop()
    finally:
        laser.close()
    if block is None or len(block) == 0:
        return f"{info.name} (serial {info.serial}) answered but sent no measurements in 1 s"
    valid = block.distance_m[np.isfinite(block.distance_m)]
    where = f"distance {np.mean(valid) * 1e3:.3f} mm" if valid.size else "no valid distance (target out of range?)"
    return (f"{info.name}, serial {info.serial}, range {info.measuring_range_m * 1e3:g} mm, firmware "
            f"{info.firmware}: {len(block)} measurements at {config.laser_rate_hz:g} Hz, {where}")


def _level_text(signal: str, rms: float) -> str:
    if signal == "voltage":
        return f"voltage {rms * 1e3:.3g} mV rms"
    if signal == "current":
        return f"current {rms * 1e3:.3g} mA rms"
    return f"displacement {rms * 1e6:.3g} µm rms"
