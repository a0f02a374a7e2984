"""Recordings of measurements that went wrong, each in one known way, for the validity checks.

Every function returns a Recording of the paper's driver (resources/drivers/
paper.json) measured on a `Bench` (48 kHz, periods of 16,384 samples, 8
averaged, 0.3 V RMS: ~0.15 mm peak, small signal) with one thing wrong. What
the capture saw is put where the measurement runner puts it: the sidecar's
"capture" object (analysis.validity.capture). The linear ones come from
analysis.synthesis' exact steady state; those that need the driver's own
nonlinearity from NonlinearBlockDriver.

How a fault shows in the signals, and which check must catch it:

    fault                  in the recording                                         channel       code
    current_disconnected   current input open: its own noise only                   current       no-signal
    laser_disconnected     laser output open: its noise only                        displacement  no-signal
    amplifier_clipping     voltage clipped at a fraction of its peak; the           voltage       distortion-high
                           (linear) driver answers the clipped voltage
    low_snr                0.3 mV RMS: far too low for the sensors' noise          current       snr-low
    nonlinear_range        the nonlinear driver at 10 V RMS (5.6 mm peak)           current       distortion-high
    laser_bandwidth_low    displacement low-passed (100 Hz, 6th order) before the   displacement  x-band-low
                           laser's noise: the sensor's filter or a too low rate
    laser_out_of_range     the cone beyond the measuring range: those samples       displacement  laser-out-of-range
                           hold the last valid distance, counted as codes 262078
    laser_errors           "no peak" codes (262076) on a share of the samples,      displacement  laser-errors
                           held and counted the same way
    adc_clipping           the current input's gain too high: clipped at full scale current       clipping
    dropouts               a lost block in the sound card's stream (xrun)           voltage       dropouts
    heating_drift          RE rising by 10 % during the measurement (voice coil     current       drift
                           warming); the displacement per volt drifts with it
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Mapping

import numpy as np

from analysis.drivers import load_driver
from analysis.multitone import Multitone, design_multitone
from analysis.recording.format import Recording, make_recording
from analysis.synthesis import ChannelNoise, steady_state_period
from analysis.validity.capture import OUT_OF_RANGE_CODES, CaptureInfo
from instruments.simulation.nonlinear_driver import NonlinearBlockDriver

PAPER = load_driver("paper")
# A bench with real sensors: a sound card at about -100 dB of a few volts of full scale, and a
# triangulation laser (ILD1420-10 class) with 0.2 um of noise.
BENCH_NOISE = ChannelNoise(voltage=1e-4, current=1e-4, displacement=2e-7)
NO_PEAK = 262076


@dataclass(frozen=True)
class Bench:
    """The measurement every fault starts from."""

    sample_rate: int = 48000
    period_samples: int = 16384
    f_min: float = 5.0
    f_max: float = 10000.0
    level_rms: float = 0.3
    n_periods: int = 8
    settle_periods: int = 2
    noise: ChannelNoise = BENCH_NOISE
    seed: int = 0
    values: Mapping[str, float] = field(default_factory=lambda: dict(PAPER.parameters))

    def multitone(self) -> Multitone:
        # design_multitone remembers the design: the crest-factor descent runs once for every fault.
        return design_multitone(self.sample_rate, self.period_samples, self.f_min, self.f_max, rms=self.level_rms)

    @property
    def total_periods(self) -> int:
        return self.n_periods + self.settle_periods


DEFAULT_BENCH = Bench()


# --- the faults ---------------------------------------------------------------------------------

def clean(bench: Bench = DEFAULT_BENCH) -> Recording:
    """Nothing wrong: the linear driver, small signal, the bench's noise."""
    return _record(bench, _linear_period(bench, bench.multitone().waveform))


def clean_nonlinear(bench: Bench = DEFAULT_BENCH) -> Recording:
    """Nothing wrong either, but from the nonlinear driver (at the bench's small level)."""
    return _record(bench, _nonlinear_periods(bench, bench.multitone().waveform))


def current_disconnected(bench: Bench = DEFAULT_BENCH) -> Recording:
    period = _linear_period(bench, bench.multitone().waveform)
    period["current"] = np.zeros_like(period["current"])
    return _record(bench, period)


def laser_disconnected(bench: Bench = DEFAULT_BENCH) -> Recording:
    period = _linear_period(bench, bench.multitone().waveform)
    period["displacement"] = np.zeros_like(period["displacement"])
    return _record(bench, period)


def amplifier_clipping(bench: Bench = DEFAULT_BENCH, clip_fraction: float = 0.6) -> Recording:
    """The amplifier's output limited to clip_fraction of the waveform's peak."""
    waveform = bench.multitone().waveform
    limit = clip_fraction * np.max(np.abs(waveform))
    return _record(bench, _linear_period(bench, np.clip(waveform, -limit, limit), every_bin=True))


def low_snr(bench: Bench = DEFAULT_BENCH, level_rms: float = 3e-4) -> Recording:
    return clean(replace(bench, level_rms=level_rms))


def nonlinear_range(bench: Bench = DEFAULT_BENCH, level_rms: float = 10.0) -> Recording:
    return clean_nonlinear(replace(bench, level_rms=level_rms))


def laser_bandwidth_low(bench: Bench = DEFAULT_BENCH, cutoff_hz: float = 100.0, order: int = 6) -> Recording:
    """The displacement through an order-`order` Butterworth low-pass before the laser's noise is added."""
    period = _linear_period(bench, bench.multitone().waveform)
    n = bench.period_samples
    f = np.fft.rfftfreq(n, 1.0 / bench.sample_rate)
    s = 1j * f / cutoff_hz
    poles = np.exp(1j * np.pi * (2 * np.arange(1, order + 1) + order - 1) / (2 * order))
    lowpass = np.prod([1.0 / (s - p) for p in poles], axis=0) * np.prod(-poles).real
    period["displacement"] = np.fft.irfft(np.fft.rfft(period["displacement"]) * lowpass, n)
    return _record(bench, period)


def laser_out_of_range(bench: Bench = DEFAULT_BENCH, limit_fraction: float = 0.7) -> Recording:
    """The measuring range ends at limit_fraction of the outward peak; beyond it the last distance is held."""
    def beyond(x: np.ndarray) -> np.ndarray:
        return x > limit_fraction * np.max(x)
    return _laser_fault(bench, beyond, OUT_OF_RANGE_CODES[1], out_of_range=True)


def laser_errors(bench: Bench = DEFAULT_BENCH, share: float = 0.02) -> Recording:
    """A random share of the laser's measurements are "no peak" codes, held like the runner holds them."""
    rng = np.random.default_rng(bench.seed + 7)
    return _laser_fault(bench, lambda x: rng.random(x.size) < share, NO_PEAK, out_of_range=False)


def adc_clipping(bench: Bench = DEFAULT_BENCH, full_scale_a: float | None = None) -> Recording:
    """The current input's full scale below the current's peak (default: at 70 % of it)."""
    rec = clean(bench)
    current = rec.signal("current")
    fs = 0.7 * np.max(np.abs(current)) if full_scale_a is None else full_scale_a
    clipped = int(np.sum(np.abs(current) >= fs))
    signals = {c.signal: rec.signal(c.signal) for c in rec.channels}
    signals["current"] = np.clip(current, -fs, fs)
    capture = CaptureInfo(full_scale_fraction={"current": 1.0}, clipped_samples={"current": clipped})
    return _recording(bench, signals, capture)


def dropouts(bench: Bench = DEFAULT_BENCH, lost_samples: int = 480) -> Recording:
    """The sound card lost a block (an xrun) in the middle: every channel jumps ahead by lost_samples."""
    rec = clean(bench)
    at = rec.n_samples // 2
    signals = {}
    for c in rec.channels:
        x = rec.signal(c.signal)
        signals[c.signal] = np.concatenate([x[:at], x[at + lost_samples:], x[-lost_samples:]])
    return _recording(bench, signals, CaptureInfo(xruns=1))


def heating_drift(bench: Bench = DEFAULT_BENCH, rise: float = 0.1) -> Recording:
    """RE rising linearly by `rise` (relative) from the first to the last period."""
    waveform = bench.multitone().waveform
    periods = []
    for p in range(bench.total_periods):
        values = dict(bench.values, RE=bench.values["RE"] * (1.0 + rise * p / max(bench.total_periods - 1, 1)))
        periods.append(_linear_period(replace(bench, values=values), waveform))
    signals = {name: np.concatenate([p[name] for p in periods]) for name in periods[0]}
    return _recording(bench, _noisy(bench, signals))


# --- helpers ------------------------------------------------------------------------------------------

def _linear_period(bench: Bench, waveform: np.ndarray, every_bin: bool = False) -> dict[str, np.ndarray]:
    """One steady-state period; every_bin: the voltage has lines on every bin (a distorted voltage)."""
    bins = np.arange(1, bench.period_samples // 2) if every_bin else bench.multitone().excited_bins
    model = PAPER.model(with_displacement=True)
    return steady_state_period(model, bench.values, waveform, bins, bench.sample_rate)


def _nonlinear_periods(bench: Bench, waveform: np.ndarray) -> dict[str, np.ndarray]:
    """All periods (settle included) from the nonlinear driver; its FIR spans one period, so it settles in two."""
    driver = NonlinearBlockDriver(bench.values, bench.sample_rate, fir_length=bench.period_samples)
    block = driver.process(np.tile(waveform, bench.total_periods))
    return {"voltage": block.voltage, "current": block.current, "displacement": block.displacement}


def _record(bench: Bench, signals: dict[str, np.ndarray]) -> Recording:
    """One period (tiled) or all periods of noise-free signals -> a recording with the bench's noise."""
    n_all = bench.total_periods * bench.period_samples
    whole = {name: (x if x.size == n_all else np.tile(x, bench.total_periods)) for name, x in signals.items()}
    return _recording(bench, _noisy(bench, whole))


def _noisy(bench: Bench, signals: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(bench.seed)
    return {name: x + rng.normal(0.0, getattr(bench.noise, name), x.size) for name, x in signals.items()}


def _recording(bench: Bench, signals: dict[str, np.ndarray], capture: CaptureInfo | None = None) -> Recording:
    extra = {"capture": capture.as_json()} if capture is not None else None
    bins = tuple(int(b) for b in bench.multitone().excited_bins)
    return make_recording(bench.sample_rate, signals, bench.period_samples, bench.settle_periods, bins,
                          driver={"name": PAPER.name, "sd_m2": PAPER.sd_m2}, extra=extra)


def _laser_fault(bench: Bench, bad, code: int, out_of_range: bool) -> Recording:
    """Laser samples where bad(x) are not distances: held at the last valid one and counted."""
    rec = clean(bench)
    x = rec.signal("displacement")
    invalid = bad(x)
    index = np.where(invalid, 0, np.arange(x.size))
    np.maximum.accumulate(index, out=index)
    signals = {c.signal: rec.signal(c.signal) for c in rec.channels}
    signals["displacement"] = x[index]
    count = int(invalid.sum())
    capture = CaptureInfo(laser_samples=x.size, laser_error_counts={code: count},
                          laser_out_of_range_share=count / x.size if out_of_range else 0.0)
    return _recording(bench, signals, capture)
