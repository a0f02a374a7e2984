"""Synthetic recordings from a model: the project's own linear simulator.

A periodic excitation drives a linear system into a periodic steady state, so
the responses are computed exactly in the frequency domain, line by line:

    I[k] = U[k] / Z(j w_k)        X[k] = Hx(j w_k) * U[k]

and repeated for every period (settle periods included: they are identical
here, as after a real transient). White Gaussian noise is then added to each
channel in the time domain, independently per sample.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np

from analysis.model.composed import Model
from analysis.recording.format import Recording, make_recording


@dataclass(frozen=True, slots=True)
class ChannelNoise:
    """RMS of the white noise added to each channel, in V, A and m."""

    voltage: float = 0.0
    current: float = 0.0
    displacement: float = 0.0


# A realistic measurement's noise: about 60-70 dB SNR on the lines of a 1 V RMS multitone.
TYPICAL_NOISE = ChannelNoise(voltage=1e-4, current=1e-4, displacement=1e-8)


def steady_state_period(model: Model, values: Mapping[str, float], waveform: np.ndarray,
                        excited_bins: np.ndarray, sample_rate: float) -> dict[str, np.ndarray]:
    """One period of voltage, current (and displacement) for the excitation `waveform` (V)."""
    n = len(waveform)
    U = np.fft.rfft(waveform)
    bins = np.asarray(excited_bins)
    s = 2j * np.pi * bins * sample_rate / n
    I = np.zeros_like(U)
    I[bins] = U[bins] / model.impedance(s, values)
    out = {"voltage": np.asarray(waveform, dtype=float), "current": np.fft.irfft(I, n)}
    if model.with_displacement:
        X = np.zeros_like(U)
        X[bins] = U[bins] * model.displacement(s, values)
        out["displacement"] = np.fft.irfft(X, n)
    return out


def synthesize_recording(model: Model, values: Mapping[str, float], waveform: np.ndarray,
                         excited_bins: np.ndarray, sample_rate: int, n_periods: int,
                         settle_periods: int = 1, noise: ChannelNoise = ChannelNoise(),
                         seed: int | None = 0, write_excited_bins: bool = True,
                         driver: Mapping | None = None,
                         drift: Callable[[int], Mapping[str, float]] | None = None) -> Recording:
    """A recording of `n_periods` analysed periods after `settle_periods`, with noise.

    drift(k): values that change from period k on (k = 0 the first settle period), e.g. the RE of a
    voice coil warming up; each period is then the steady state of its own values (a drift slow
    against a period, as heating is).
    """
    total = n_periods + settle_periods
    if drift is None:
        period = steady_state_period(model, values, waveform, excited_bins, sample_rate)
        tiled = {name: np.tile(one, total) for name, one in period.items()}
    else:
        periods = [steady_state_period(model, {**values, **drift(k)}, waveform, excited_bins, sample_rate)
                   for k in range(total)]
        tiled = {name: np.concatenate([p[name] for p in periods]) for name in periods[0]}
    rng = np.random.default_rng(seed)
    signals = {}
    for name, signal in tiled.items():
        sigma = getattr(noise, name)
        if sigma > 0:
            signal = signal + rng.normal(0.0, sigma, signal.shape)
        signals[name] = signal
    return make_recording(
        sample_rate, signals, period_samples=len(waveform), settle_periods=settle_periods,
        excited_bins=tuple(int(b) for b in excited_bins) if write_excited_bins else None,
        driver=dict(driver or {}),
    )
