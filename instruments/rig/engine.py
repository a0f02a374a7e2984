"""The virtual rig's analog chain, one block at a time, without JACK.

    played sample (FS) -> power amplifier -> driver terminals -> BlockDriver
                                        |-> voltage sense  -> ADC input (FS)
                                        |-> shunt + amp    -> ADC input (FS)
                                        `-> laser analog   -> ADC input (FS)

The chain follows a Calibration (instruments.audio.config) read backwards:
a workstation that uses the same Calibration gets the driver's volts,
amperes and metres back. Faults act where a real rig would fail: a cable off
(an input reads exact zeros), an amplifier that clips, more noise. Used by
the JACK rig (instruments.rig.jack_rig) in its process callback and by
SimulatedAudio in its thread, so both simulate the same hardware.
"""
from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass, field, replace
from typing import Callable, Iterable

import numpy as np

from analysis.errors import LinparError
from instruments.audio.config import Calibration, ChannelMap
from instruments.laser.usb_link import MAX_LATENCY_S
from instruments.simulation.block_driver import BlockDriver

# The rig's fixed hardware: 1 FS out = 10 V at the terminals; the voltage
# sense reads 20 V at FS; 0.1 ohm shunt, x5 amplifier, 1 V ADC: 2 A at FS;
# the laser's analog output, 1 mm/V, on a 5 V input: 5 mm at FS.
RIG_CALIBRATION = Calibration(volts_per_fs_out=10.0, volts_per_fs_voltage_sense=20.0,
                              volts_per_fs_current_sense=1.0, shunt_ohm=0.1, current_amp_gain=5.0,
                              volts_per_fs_laser=5.0, laser_m_per_volt=1e-3)
# Where the rig's cables go on the sound card: its ports connect in this order.
RIG_CHANNEL_MAP = ChannelMap(output=0, voltage=0, current=1, laser_analog=2)
SIGNALS = ("voltage", "current", "displacement")

DisplacementSink = Callable[[np.ndarray, int], None]


class RigSpecError(LinparError, ValueError):
    """A --noise or --fault specification of the rig that cannot be used; one line."""


@dataclass(frozen=True, slots=True)
class RigNoise:
    """RMS of the white noise on each sensor, in V, A and m (about -105 dB of full scale by default)."""

    voltage: float = 1e-4
    current: float = 1e-5
    displacement: float = 1e-8

    def __post_init__(self) -> None:
        for name in SIGNALS:
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                raise RigSpecError(f"noise.{name} must be a number >= 0, got {value!r}")

    @classmethod
    def parse(cls, text: str) -> RigNoise:
        """'voltage=1e-4,current=1e-5,displacement=1e-8' (any subset; the rest keep their defaults)."""
        values = _key_values(text, "noise")
        unknown = sorted(set(values) - set(SIGNALS))
        if unknown:
            raise RigSpecError(f"noise: unknown channel(s) {', '.join(unknown)}; known: {', '.join(SIGNALS)}")
        return cls(**{k: _number(v, f"noise.{k}") for k, v in values.items()})


@dataclass(frozen=True, slots=True)
class RigFaults:
    """What is wrong with the rig now.

    ``disconnected``: signals whose input reads exact zeros (cable off).
    ``amp_clip_volts``: the amplifier's output limit (V peak), None for none.
    ``noise_factor``: the sensors' noise times this.
    ``laser_latency_s``, ``laser_jitter_s``: the serial laser's link, late like a USB serial adapter
    (instruments/laser/usb_link.py); applied by the rig's laser from its next switch-on.
    """

    disconnected: frozenset[str] = field(default_factory=frozenset)
    amp_clip_volts: float | None = None
    noise_factor: float = 1.0
    laser_latency_s: float = 0.0
    laser_jitter_s: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "disconnected", frozenset(self.disconnected))
        unknown = sorted(self.disconnected - set(SIGNALS))
        if unknown:
            raise RigSpecError(f"fault: cannot disconnect {', '.join(unknown)}; signals: {', '.join(SIGNALS)}")
        if self.amp_clip_volts is not None and not self.amp_clip_volts > 0:
            raise RigSpecError(f"fault: the clipping level must be > 0 V, got {self.amp_clip_volts}")
        if not self.noise_factor >= 0:
            raise RigSpecError(f"fault: the noise factor must be >= 0, got {self.noise_factor}")
        for key, value in (("latency", self.laser_latency_s), ("jitter", self.laser_jitter_s)):
            if not 0 <= value <= MAX_LATENCY_S:
                raise RigSpecError(f"fault: {key} must be seconds from 0 to {MAX_LATENCY_S:g} (e.g. "
                                   f"latency=0.008,jitter=0.002), got {value:g}")

    @classmethod
    def parse(cls, texts: Iterable[str]) -> RigFaults:
        """Faults from 'disconnect=current', 'clip=5' (V), 'noise=10' (factor); repeat or join with commas."""
        faults = cls()
        for text in texts:
            for key, value in _key_values(text, "fault").items():
                faults = faults.with_fault(key, value)
        return faults

    def with_fault(self, key: str, value: str) -> RigFaults:
        if key == "disconnect":
            names = {"voltage-sense": "voltage", "current-sense": "current", "laser": "displacement",
                     "laser-analog": "displacement"}
            return replace(self, disconnected=self.disconnected | {names.get(value, value)})
        if key == "clip":
            return replace(self, amp_clip_volts=_number(value, "clip"))
        if key == "noise":
            return replace(self, noise_factor=_number(value, "noise"))
        if key == "latency":
            return replace(self, laser_latency_s=_number(value, "fault: latency"))
        if key == "jitter":
            return replace(self, laser_jitter_s=_number(value, "fault: jitter"))
        raise RigSpecError(f"unknown fault {key!r}; known: disconnect=SIGNAL, clip=VOLTS, noise=FACTOR, "
                           f"latency=SECONDS[,jitter=SECONDS]")

    def describe(self) -> list[str]:
        out = [f"disconnect={name}" for name in sorted(self.disconnected)]
        if self.amp_clip_volts is not None:
            out.append(f"clip={self.amp_clip_volts:g}")
        if self.noise_factor != 1.0:
            out.append(f"noise={self.noise_factor:g}")
        if self.laser_latency_s:
            out.append(f"latency={self.laser_latency_s:g}")
        if self.laser_jitter_s:
            out.append(f"jitter={self.laser_jitter_s:g}")
        return out

    @property
    def laser_link(self) -> dict[str, float]:
        """The serial laser's link settings (RigLaser.configure's names)."""
        return {"link_latency_s": self.laser_latency_s, "link_jitter_s": self.laser_jitter_s}


@dataclass(frozen=True, slots=True, eq=False)
class RigOutputs:
    """One block at the sound card's inputs, FS units (clipped to +-1 like an ADC), float32."""

    voltage: np.ndarray
    current: np.ndarray
    displacement: np.ndarray


class RigEngine:
    """The analog chain around a BlockDriver (see the module doc).

    ``displacement_sinks`` receive each block of displacement (m, float64,
    read-only) with the frame counter of its first sample. They are called
    from the audio thread: they must only copy or enqueue, never block.
    """

    def __init__(self, driver: BlockDriver, calibration: Calibration = RIG_CALIBRATION,
                 noise: RigNoise = RigNoise(), faults: RigFaults = RigFaults(),
                 displacement_sinks: list[DisplacementSink] | None = None, seed: int | None = None):
        self.driver = driver
        self.calibration = calibration
        self.noise = noise
        # NB: replaced whole from control threads, read once per block by the audio thread.
        self.faults = faults
        self.displacement_sinks = list(displacement_sinks or [])
        self._rng = np.random.default_rng(seed)
        self._stall_s = 0.0
        self._lock = threading.Lock()
        self.sink_errors = 0
        self.blocks = 0
        self.peak_terminal_volts = 0.0

    @property
    def sample_rate(self) -> int:
        return self.driver.sample_rate

    def request_stall(self, seconds: float) -> None:
        """Make the next block take ``seconds`` longer (the xrun injector)."""
        with self._lock:
            self._stall_s = float(seconds)

    def process(self, played_fs: np.ndarray, frame_counter: int) -> RigOutputs:
        faults = self.faults
        cal = self.calibration
        u = np.asarray(played_fs, dtype=np.float64) * cal.volts_per_fs_out
        if faults.amp_clip_volts is not None:
            np.clip(u, -faults.amp_clip_volts, faults.amp_clip_volts, out=u)
        block = self.driver.process(u)
        for sink in self.displacement_sinks:
            try:
                sink(block.displacement, frame_counter)
            except Exception:   # a broken sink must not stop the rig's audio
                self.sink_errors += 1
        outputs = {}
        for name, si in (("voltage", block.voltage), ("current", block.current),
                         ("displacement", block.displacement)):
            if name in faults.disconnected:
                outputs[name] = np.zeros(si.size, dtype=np.float32)
                continue
            sigma = getattr(self.noise, name) * faults.noise_factor
            fs_units = si / cal.scale(name)
            if sigma > 0:
                fs_units = fs_units + self._rng.standard_normal(si.size) * (sigma / cal.scale(name))
            outputs[name] = np.clip(fs_units, -1.0, 1.0).astype(np.float32)
        self.blocks += 1
        if u.size:
            self.peak_terminal_volts = max(self.peak_terminal_volts, float(np.max(np.abs(u))))
        if self._stall_s:
            with self._lock:
                stall, self._stall_s = self._stall_s, 0.0
            time.sleep(stall)
        return RigOutputs(outputs["voltage"], outputs["current"], outputs["displacement"])


def default_driver(name_or_path: str = "paper", sample_rate: int = 48000, effects: str | None = None):
    """The LinearBlockDriver of a driver file; ``effects`` replaces the file's effect ids."""
    from analysis.drivers import load_driver
    from analysis.effects import parse_effects
    from analysis.model.composed import Model
    from instruments.simulation.linear_driver import LinearBlockDriver

    definition = load_driver(name_or_path)
    model = definition.model() if effects is None else Model(parse_effects(effects))
    values = dict(definition.parameters)
    missing = [p.name for p in model.param_specs if p.name not in values]
    if missing:
        raise RigSpecError(f"driver {definition.name!r} has no value for {', '.join(missing)} "
                         f"(needed by effects {effects!r})")
    return LinearBlockDriver(model, values, sample_rate), definition


def _key_values(text: str, what: str) -> dict[str, str]:
    out = {}
    for item in (t.strip() for t in str(text).split(",")):
        if not item:
            continue
        key, sep, value = item.partition("=")
        if not sep:
            raise RigSpecError(f"{what}: expected KEY=VALUE, got {item!r}")
        out[key.strip()] = value.strip()
    return out


def _number(text: str, what: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise RigSpecError(f"{what}: expected a number, got {text!r}") from None
    if not math.isfinite(value):
        raise RigSpecError(f"{what}: expected a finite number, got {text!r}")
    return value
