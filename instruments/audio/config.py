"""What the caller chooses and remembers about the sound card: device, wiring, calibration.

All three are frozen, compared by value, and round-trip through plain JSON
objects (``to_dict`` / ``from_dict``) so the settings can keep them.
"""
from __future__ import annotations

import math
from dataclasses import MISSING, asdict, dataclass, fields
from typing import Any, Mapping

import numpy as np

from analysis.errors import LinparError

# JACK's PortAudio host API, under the name PortAudio gives it.
JACK_HOSTAPI = "JACK Audio Connection Kit"


class AudioConfigError(LinparError, ValueError):
    """A device choice, channel map or calibration that cannot be used (a settings or calibration file, an entry)."""


def _from_mapping(cls, data: Mapping[str, Any], what: str):
    if not isinstance(data, Mapping):
        raise AudioConfigError(f"{what}: expected an object, got {type(data).__name__}")
    known = {f.name for f in fields(cls)}
    unknown = sorted(set(data) - known)
    if unknown:
        raise AudioConfigError(f"{what}: unknown key(s) {', '.join(unknown)}; known: {', '.join(sorted(known))}")
    missing = [f.name for f in fields(cls)
               if f.name not in data and f.default is MISSING and f.default_factory is MISSING]
    if missing:
        raise AudioConfigError(f"{what}: missing key(s) {', '.join(missing)}")
    return cls(**dict(data))


@dataclass(frozen=True, slots=True)
class AudioDeviceChoice:
    """A sound card as the user picked it: its name and its host API (ALSA, JACK, ...).

    Names, not PortAudio indices: indices change when a device is plugged in
    or a JACK client appears, names do not.
    """

    name: str
    hostapi: str

    def to_dict(self) -> dict[str, str]:
        return {"name": self.name, "hostapi": self.hostapi}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> AudioDeviceChoice:
        choice = _from_mapping(cls, data, "audio device")
        if not isinstance(choice.name, str) or not isinstance(choice.hostapi, str):
            raise AudioConfigError("audio device: 'name' and 'hostapi' must be strings")
        return choice

    def __str__(self) -> str:
        return f"{self.name!r} ({self.hostapi})"


@dataclass(frozen=True, slots=True)
class ChannelMap:
    """Which sound-card channel carries what (0-based).

    ``output``: the output that feeds the power amplifier. ``voltage``: the
    input wired to the voltage sense at the driver's terminals. ``current``:
    the input wired to the current-sense amplifier. ``laser_analog``: the
    input wired to the laser's analog output, or None when the displacement
    comes another way (the serial laser) or not at all.
    """

    output: int = 0
    voltage: int = 0
    current: int = 1
    laser_analog: int | None = None

    def __post_init__(self) -> None:
        for name in ("output", "voltage", "current", "laser_analog"):
            value = getattr(self, name)
            if value is None and name == "laser_analog":
                continue
            if not isinstance(value, int) or isinstance(value, bool) or value < 0:
                raise AudioConfigError(f"channel map: {name} must be a channel number >= 0, got {value!r}")
        inputs = self.input_channels()
        if len(set(inputs.values())) != len(inputs):
            raise AudioConfigError(f"channel map: two signals on one input: {inputs}")

    def input_channels(self) -> dict[str, int]:
        """Signal name -> input channel, for the signals that are wired."""
        wired = {"voltage": self.voltage, "current": self.current}
        if self.laser_analog is not None:
            wired["displacement"] = self.laser_analog
        return wired

    @property
    def n_inputs(self) -> int:
        """Input channels the stream must open (the highest wired one + 1)."""
        return max(self.input_channels().values()) + 1

    @property
    def n_outputs(self) -> int:
        return self.output + 1

    def to_dict(self) -> dict[str, int | None]:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ChannelMap:
        return _from_mapping(cls, data, "channel map")


@dataclass(frozen=True, slots=True)
class Calibration:
    """How one full-scale (FS) sample becomes volts, amperes and metres.

    A sample is a float in [-1, 1] (1.0 = the converter's full scale).

    Output:  u_terminals [V] = x_out * volts_per_fs_out
             (the DAC's full-scale voltage times the power amplifier's gain)
    Voltage: u [V] = x * volts_per_fs_voltage_sense
             (the ADC's full-scale voltage times the voltage-sense divider ratio)
    Current: i [A] = x * volts_per_fs_current_sense / (shunt_ohm * current_amp_gain)
             (the shunt turns current into a voltage, the amplifier scales it,
             the ADC reads it)
    Laser:   x [m] = x_sample * volts_per_fs_laser * laser_m_per_volt
             (the laser's analog output, read by an ADC input; only with
             ChannelMap.laser_analog)

    Calibrate the chain as a whole (a known voltage, a known resistor, a gauge
    block), not from datasheets: converter full scales are +-5 % apart.
    """

    volts_per_fs_out: float
    volts_per_fs_voltage_sense: float
    volts_per_fs_current_sense: float
    shunt_ohm: float
    current_amp_gain: float
    volts_per_fs_laser: float = 1.0
    laser_m_per_volt: float = 1e-3

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if (not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value)
                    or value <= 0):
                raise AudioConfigError(f"calibration: {f.name} must be a positive number, got {value!r}")

    @property
    def amperes_per_fs(self) -> float:
        return self.volts_per_fs_current_sense / (self.shunt_ohm * self.current_amp_gain)

    @property
    def metres_per_fs(self) -> float:
        return self.volts_per_fs_laser * self.laser_m_per_volt

    def scale(self, signal: str) -> float:
        """SI units per FS for an input signal: 'voltage', 'current' or 'displacement'."""
        if signal == "voltage":
            return self.volts_per_fs_voltage_sense
        if signal == "current":
            return self.amperes_per_fs
        if signal == "displacement":
            return self.metres_per_fs
        raise KeyError(f"no calibration for signal {signal!r}")

    def to_si(self, signal: str, samples: np.ndarray) -> np.ndarray:
        """Samples (FS) of one input signal in V, A or m, float64."""
        return np.asarray(samples, dtype=np.float64) * self.scale(signal)

    def volts_to_output(self, volts: np.ndarray) -> np.ndarray:
        """Terminal voltage wanted (V) -> output samples (FS), not clipped."""
        return np.asarray(volts, dtype=np.float64) / self.volts_per_fs_out

    def to_dict(self) -> dict[str, float]:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Calibration:
        return _from_mapping(cls, data, "calibration")
