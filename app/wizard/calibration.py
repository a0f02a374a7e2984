"""Calibration against a reference resistor: the gain and delay of the current channel. Qt-free.

With a resistor R in place of the driver, Z = U / I must equal R at every
line with zero phase. What the chain makes of it instead:

    Z_meas(f) = R * g * exp(j 2 pi f tau)

g is the error of the current channel's scale relative to the voltage's (a
shunt off its nominal value, an amplifier gain), tau the time by which the
current channel lags the voltage channel (anti-alias filters, a current-sense
amplifier's bandwidth). g is the median of |Z_meas| / R (robust to a few noisy
lines), tau the least-squares slope of the unwrapped phase against 2 pi f
through the origin (a delay has no phase at DC). The corrections put the
current back: I = I_read * g (Corrections.apply, in the calibration), then
advanced by tau in the stream (app.wizard.corrected_audio).

Only the ratio U / I is calibrated here: the voltage channel itself is
calibrated against a voltmeter (its constant is on the Hardware page).
"""
from __future__ import annotations

import math
import threading
import time
from dataclasses import asdict, dataclass, replace
from typing import Mapping

import numpy as np

from analysis.errors import LinparError
from analysis.model.composed import Model
from analysis.spectra import Spectra, estimate_spectra
from instruments.audio.config import Calibration

# Beyond these the "resistor" is not one, or not the value given: the corrections are refused.
GAIN_LIMIT = 0.2            # |Z| more than 20 % off R: wrong resistor, or the driver still connected
SPREAD_LIMIT = 0.02         # |Z| varying more than 2 % across the band: not a pure resistance
PHASE_RESIDUAL_LIMIT_DEG = 2.0   # phase left after the delay: a filter, not a delay
CAL_PERIOD = 16384
CAL_PERIODS = 4
CAL_SETTLE = 5


class CorrectionsError(LinparError, ValueError):
    """Stored corrections that cannot be used (settings written by another version, or edited by hand)."""


@dataclass(frozen=True, slots=True)
class Corrections:
    current_gain: float = 1.0           # amperes as read x this = amperes
    current_delay_s: float = 0.0        # the current channel lags the voltage channel by this
    source: str = "none"                # "resistor" | "none" | "exact"
    resistor_ohm: float | None = None
    measured_at: str = ""
    hardware: str = ""

    @property
    def is_identity(self) -> bool:
        return self.current_gain == 1.0 and self.current_delay_s == 0.0

    def apply(self, calibration: Calibration) -> Calibration:
        """The calibration with the current's gain corrected (the delay: app.wizard.corrected_audio)."""
        return replace(calibration, volts_per_fs_current_sense=calibration.volts_per_fs_current_sense
                       * self.current_gain)

    def describe(self) -> str:
        if self.source == "exact":
            return "none needed: the virtual rig's chain is exact by construction"
        if self.source == "none":
            return "none (the calibration constants are used as they are)"
        delay_us = round(self.current_delay_s * 1e6, 2) + 0.0          # + 0.0: no "-0.00"
        return (f"current gain ×{self.current_gain:.5f}, current delay {delay_us:.2f} µs "
                f"(from {self.resistor_ohm:g} Ω, {self.measured_at})")

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, data) -> Corrections:
        """The corrections of a settings object; CorrectionsError for one that cannot be used."""
        if not isinstance(data, Mapping):
            raise CorrectionsError(f"corrections: expected an object, found {type(data).__name__}")
        known = {k: data[k] for k in cls.__dataclass_fields__ if k in data}
        gain, delay = known.get("current_gain", 1.0), known.get("current_delay_s", 0.0)
        for name, value in (("current_gain", gain), ("current_delay_s", delay)):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise CorrectionsError(f"corrections: {name}: found {value!r}, expected a finite number")
        if not 1 - GAIN_LIMIT <= gain <= 1 + GAIN_LIMIT or abs(delay) > 1.0:
            raise CorrectionsError(f"corrections: gain {gain!r} or delay {delay!r} s beyond what a calibration "
                                   f"against a resistor accepts")
        for name in ("source", "measured_at", "hardware"):
            if name in known and not isinstance(known[name], str):
                raise CorrectionsError(f"corrections: {name}: expected text")
        resistor = known.get("resistor_ohm")
        if resistor is not None and (isinstance(resistor, bool) or not isinstance(resistor, (int, float))
                                     or not math.isfinite(resistor) or resistor <= 0):
            raise CorrectionsError(f"corrections: resistor_ohm: found {resistor!r}, expected a positive number")
        return cls(**known)


@dataclass(frozen=True, slots=True, eq=False)
class ResistorCheck:
    resistor_ohm: float
    freqs: np.ndarray               # Hz, the excited lines
    impedance: np.ndarray           # complex, as measured (before the corrections)
    corrections: Corrections
    spread: float                   # max/min of |Z| - 1 across the band
    phase_max_deg: float            # largest |phase| as measured
    phase_residual_deg: float       # largest |phase| left after removing the delay
    problems: tuple[str, ...]       # empty: the corrections may be stored

    @property
    def ok(self) -> bool:
        return not self.problems

    def summary(self) -> str:
        z = np.abs(self.impedance)
        return (f"|Z| = {np.median(z):.4g} Ω (R = {self.resistor_ohm:g} Ω; spread {self.spread * 100:.2f} % across "
                f"{self.freqs[0]:.3g} Hz – {self.freqs[-1] / 1000:.3g} kHz), phase up to {self.phase_max_deg:.2f}° "
                f"({self.phase_residual_deg:.2f}° after the delay)")


def resistor_model(r_ohm: float) -> tuple[Model, dict[str, float]]:
    """The lumped model reduced to a resistance: no inductance, a motional branch shorted (RES ~ 0).

    Z = RE + 1 / (s CMES + 1/RES + 1/(s LCES)) = R + ~1e-9 ohm; the cone does not move (Hx ~ 1e-10 m/V).
    """
    return Model((), with_displacement=True), {"RE": float(r_ohm), "LE": 0.0, "CMES": 1e-6, "LCES": 1e-3,
                                                "RES": 1e-9, "Bl": 1.0}


def resistor_driver(r_ohm: float, sample_rate: int):
    """A simulated reference resistor for SimulatedAudio (the LinearBlockDriver of resistor_model)."""
    from instruments.simulation.linear_driver import LinearBlockDriver
    model, values = resistor_model(r_ohm)
    return LinearBlockDriver(model, values, sample_rate)


def check_resistor(spectra: Spectra, r_ohm: float, hardware: str = "") -> ResistorCheck:
    """The corrections that make the measured impedance R, and whether R was really what was measured."""
    z = spectra.impedance.value
    f = spectra.impedance.freqs
    magnitude = np.abs(z)
    gain = float(np.median(magnitude) / r_ohm)
    phase = np.unwrap(np.angle(z))
    w = 2 * np.pi * f
    delay = float(np.sum(w * phase) / np.sum(w * w))
    residual = np.degrees(np.abs(phase - w * delay))
    spread = float(magnitude.max() / magnitude.min() - 1.0)
    problems = []
    if abs(gain - 1.0) > GAIN_LIMIT:
        problems.append(f"|Z| is {np.median(magnitude):.3g} Ω, not the {r_ohm:g} Ω given: check the resistor's "
                        f"value, that it (and not the driver) is connected, and the current-sense constants")
    if spread > SPREAD_LIMIT:
        problems.append(f"|Z| varies by {spread * 100:.1f} % across the band (limit {SPREAD_LIMIT * 100:g} %): "
                        f"not a pure resistance (a wire-wound resistor is inductive) or the current sense "
                        f"is not flat")
    if residual.max() > PHASE_RESIDUAL_LIMIT_DEG:
        problems.append(f"the phase departs from a pure delay by {residual.max():.1f}° (limit "
                        f"{PHASE_RESIDUAL_LIMIT_DEG:g}°): a filter in one channel, or a reactive load")
    when = time.strftime("%Y-%m-%d %H:%M")
    corrections = Corrections(gain, delay, "resistor", float(r_ohm), when, hardware)
    return ResistorCheck(float(r_ohm), f, z, corrections, spread, float(np.degrees(np.abs(phase)).max()),
                         float(residual.max()), tuple(problems))


def measure_resistor(config, r_ohm: float, level_v: float, cancel: threading.Event | None = None,
                     progress=None) -> ResistorCheck:
    """Measure the reference resistor on `config` (on the simulator: a simulated one) and check it."""
    from analysis.multitone import design_multitone
    from app.wizard.hardware import SIMULATOR, open_audio
    from instruments.audio import capture

    if config.kind == SIMULATOR:
        config = replace(config, simulated_driver=resistor_driver(r_ohm, config.sample_rate))
    mt = design_multitone(config.sample_rate, CAL_PERIOD, 10.0, 20000.0, rms=level_v)
    audio = open_audio(config)
    captured = capture(audio, mt.waveform, CAL_PERIODS, CAL_SETTLE, cancel=cancel, progress=progress)
    signals = {k: v for k, v in captured.signals().items() if k != "displacement"}
    from analysis.recording.format import make_recording
    recording = make_recording(captured.sample_rate, signals, captured.period_samples,
                               excited_bins=tuple(int(b) for b in mt.excited_bins))
    return check_resistor(estimate_spectra(recording), r_ohm, config.key())
