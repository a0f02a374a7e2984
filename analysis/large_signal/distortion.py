"""How well the identified model reproduces a measurement, and what it predicts at other levels.

Output error: the model (simulate.py) is driven by the measured voltage of
a recording's mean period, and its current and displacement are compared
with the measured ones:

    time domain     rms(measured - model) / rms(measured), in %
    excited lines   mean |Y - Y_model|^2 / var, the misfit in units of the noise (1: as good as the noise)
    other lines     the distortion: power at the lines not excited, within the excitation's band,
                    measured P_m = sum(|Y|^2 - var), predicted P_p = sum |Y_model|^2,
                    left P_r = sum(|Y - Y_model|^2 - var); each in dB re the excited lines' power,
                    and explained = 1 - P_r / P_m

For the voltage, which drives the model, the residual is the electrical
equation's (columns.py), in the same units. Predictions at a level the user
chooses are a multitone scaled from a recording's voltage, a sine (H2, H3)
or two tones (IEC 60268-5's f1 + f2 with 4:1 amplitudes: IMD2 from f2 +- f1,
IMD3 from f2 +- 2 f1), each for the current and the displacement.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from analysis.large_signal.data import LargeSignalError, RecordingData
from analysis.large_signal.model import LargeSignalModel
from analysis.large_signal.simulate import SimulationDiverged, steady_state

BANDS_PER_OCTAVE = 3
SINE_PERIOD = 16384
CHANNELS = ("current", "displacement")


@dataclass(frozen=True, slots=True, kw_only=True)
class ChannelFit:
    channel: str
    time_rms_percent: float
    excited_misfit: float          # mean |r|^2 / var at the excited lines
    measured_db: float             # distortion re signal, dB (nan when at the noise)
    predicted_db: float
    unexplained_db: float
    explained_percent: float       # nan when no distortion stands above the noise
    bands_hz: tuple[float, ...]
    bands_measured_db: tuple[float, ...]
    bands_predicted_db: tuple[float, ...]
    bands_noise_db: tuple[float, ...]

    def as_json(self) -> dict:
        out = {}
        for name in ("time_rms_percent", "excited_misfit", "measured_db", "predicted_db", "unexplained_db",
                     "explained_percent"):
            out[name] = _finite(getattr(self, name))
        out["bands"] = {"hz": list(self.bands_hz), "measured_db": [_finite(v) for v in self.bands_measured_db],
                        "predicted_db": [_finite(v) for v in self.bands_predicted_db],
                        "noise_db": [_finite(v) for v in self.bands_noise_db]}
        return out


@dataclass(frozen=True, slots=True)
class RecordingFit:
    label: str
    drive_rms_v: float
    channels: dict                 # "current", "displacement" -> ChannelFit
    voltage_equation_percent: float
    failed: str = ""               # why the model could not be driven at this level

    def as_json(self) -> dict:
        return {"source": self.label, "drive_rms_v": self.drive_rms_v, "failed": self.failed or None,
                "voltage_equation_rms_percent": _finite(self.voltage_equation_percent),
                "channels": {name: c.as_json() for name, c in self.channels.items()}}


def recording_fit(model: LargeSignalModel, data: RecordingData, offset_m: float, delay_s: float,
                  voltage_residual_percent: float = float("nan")) -> RecordingFit:
    """The model against one recording (module doc)."""
    u = data.mean("u")
    drive = float(np.sqrt(np.mean((u - u.mean()) ** 2)))
    try:
        sim = steady_state(model, u, data.sample_rate)
    except SimulationDiverged as exc:
        return RecordingFit(data.label, drive, {}, voltage_residual_percent, str(exc))
    n = data.period_samples
    s = 2j * np.pi * np.arange(n // 2 + 1) * data.bin_width
    measured = {"current": data.i, "displacement": _delayed(data.x, s, delay_s)}
    simulated = {"current": sim.current, "displacement": sim.displacement}
    tops = {"current": int(data.excited_bins[-1]), "displacement": int(data.mechanical_bins[-1])}
    channels = {}
    for name in CHANNELS:
        channels[name] = _channel_fit(name, measured[name], simulated[name], data.excited_bins, tops[name],
                                      data.bin_width)
    return RecordingFit(data.label, drive, channels, voltage_residual_percent)


def _channel_fit(name: str, periods: np.ndarray, simulated: np.ndarray, excited: np.ndarray, top: int,
                 bin_width: float) -> ChannelFit:
    spectra = np.fft.rfft(periods, axis=1)
    mean = spectra.mean(axis=0)
    p = periods.shape[0]
    var = np.sum(np.abs(spectra - mean) ** 2, axis=0) / (p * (p - 1))
    model = np.fft.rfft(simulated)
    lines = np.arange(1, top + 1)
    exc = excited[excited <= top]
    other = np.setdiff1d(lines[lines >= excited[0]], exc)
    ac = periods.mean(axis=0) - periods.mean()
    time_rms = 100.0 * _rms(ac - (simulated - simulated.mean())) / max(_rms(ac), 1e-300)
    residual = np.abs(mean - model) ** 2
    misfit = float(np.mean(residual[exc] / np.maximum(var[exc], 1e-300))) if exc.size else float("nan")
    signal = float(np.sum(np.abs(mean[exc]) ** 2))
    measured = float(np.sum(np.abs(mean[other]) ** 2 - var[other]))
    predicted = float(np.sum(np.abs(model[other]) ** 2))
    left = float(np.sum(residual[other] - var[other]))
    noise = float(np.sum(var[other]))
    # Above what the noise's own scatter could make (each line's |Y|^2 - var scatters by about var).
    significant = measured > 3.0 * noise / math.sqrt(max(other.size, 1))
    explained = 100.0 * (1.0 - max(left, 0.0) / measured) if significant else float("nan")
    bands = _bands(other, bin_width)
    band_hz, band_m, band_p, band_n = [], [], [], []
    for members in bands:
        density = _density(np.abs(mean[exc]) ** 2, exc, members)
        band_hz.append(float(np.exp(np.mean(np.log(members * bin_width)))))
        power, floor = np.mean(np.abs(mean[members]) ** 2), np.mean(var[members])
        # Shown only where it stands clear of the noise (3 dB): below, the "distortion" is the noise's.
        band_m.append(_db((power - floor) / density) if power > 2.0 * floor else float("nan"))
        band_p.append(_db(np.mean(np.abs(model[members]) ** 2) / density))
        band_n.append(_db(np.mean(var[members]) / density))
    return ChannelFit(channel=name, time_rms_percent=time_rms, excited_misfit=misfit,
                      measured_db=_db(measured / signal) if significant else float("nan"),
                      predicted_db=_db(predicted / signal),
                      unexplained_db=_db(max(left, 0.0) / signal) if significant else float("nan"),
                      explained_percent=explained, bands_hz=tuple(band_hz), bands_measured_db=tuple(band_m),
                      bands_predicted_db=tuple(band_p), bands_noise_db=tuple(band_n))


def multitone_prediction(model: LargeSignalModel, data: RecordingData, level_rms_v: float) -> dict:
    """The distortion predicted with a recording's mean voltage scaled to level_rms_v (V RMS), per channel:
    total and per band, in dB re the excited lines (no measurement to compare)."""
    u = data.mean("u")
    u = (u - u.mean()) * level_rms_v / max(float(np.sqrt(np.mean((u - u.mean()) ** 2))), 1e-300)
    sim = steady_state(model, u, data.sample_rate)
    out = {"level_rms_v": level_rms_v, "peak_displacement_m": float(np.max(np.abs(sim.displacement -
                                                                                   sim.displacement.mean())))}
    excited = data.excited_bins
    for name, y, top in (("current", sim.current, data.excited_bins[-1]),
                         ("displacement", sim.displacement, data.mechanical_bins[-1])):
        spectrum = np.abs(np.fft.rfft(y)) ** 2
        lines = np.arange(excited[0], top + 1)
        exc = excited[excited <= top]
        other = np.setdiff1d(lines, exc)
        signal = float(np.sum(spectrum[exc]))
        bands = _bands(other, data.bin_width)
        out[name] = {"predicted_db": _finite(_db(np.sum(spectrum[other]) / signal)),
                     "bands": {"hz": [float(np.exp(np.mean(np.log(b * data.bin_width)))) for b in bands],
                               "predicted_db": [_finite(_db(np.mean(spectrum[b]) /
                                                             _density(spectrum[exc], exc, b))) for b in bands]}}
    return out


def harmonics(model: LargeSignalModel, frequency_hz: float, level_rms_v: float, sample_rate: float = 48000.0,
              period: int = SINE_PERIOD) -> dict:
    """H2 and H3 (dB re the fundamental) of current and displacement for a sine of level_rms_v at frequency_hz
    (moved to the nearest line of the period: the returned "frequency_hz")."""
    k = max(1, int(round(frequency_hz * period / sample_rate)))
    if not 2 * k < period // 2:
        raise LargeSignalError(f"a sine at {frequency_hz:g} Hz: its second harmonic is beyond the "
                               f"{sample_rate / 2:g} Hz the model is sampled to")
    t = np.arange(period)
    u = level_rms_v * math.sqrt(2.0) * np.sin(2 * np.pi * k * t / period)
    sim = steady_state(model, u, sample_rate)
    out = {"frequency_hz": k * sample_rate / period, "level_rms_v": level_rms_v,
           "peak_displacement_m": float(np.max(np.abs(sim.displacement - sim.displacement.mean())))}
    for name, y in (("current", sim.current), ("displacement", sim.displacement)):
        spectrum = np.abs(np.fft.rfft(y))
        out[name] = {f"H{h}_db": _finite(_db(spectrum[h * k] ** 2 / spectrum[k] ** 2)) for h in (2, 3)
                     if h * k < spectrum.size}
    return out


def intermodulation(model: LargeSignalModel, f1_hz: float, f2_hz: float, level_rms_v: float,
                    sample_rate: float = 48000.0, period: int = SINE_PERIOD) -> dict:
    """IMD2 and IMD3 (dB re the f2 line) of current and displacement, two tones with amplitudes 4:1."""
    k1 = max(1, int(round(f1_hz * period / sample_rate)))
    k2 = max(3 * k1, int(round(f2_hz * period / sample_rate)))
    if not k2 + 2 * k1 < period // 2:
        raise LargeSignalError(f"two tones at {f1_hz:g} + {f2_hz:g} Hz: their products are beyond the "
                               f"{sample_rate / 2:g} Hz the model is sampled to")
    t = np.arange(period)
    tones = 4.0 * np.sin(2 * np.pi * k1 * t / period) + np.sin(2 * np.pi * k2 * t / period)
    u = tones * level_rms_v / float(np.sqrt(np.mean(tones**2)))
    sim = steady_state(model, u, sample_rate)
    out = {"f1_hz": k1 * sample_rate / period, "f2_hz": k2 * sample_rate / period, "level_rms_v": level_rms_v}
    for name, y in (("current", sim.current), ("displacement", sim.displacement)):
        a = np.abs(np.fft.rfft(y))
        out[name] = {"IMD2_db": _finite(_db(((a[k2 - k1] + a[k2 + k1]) / a[k2]) ** 2)),
                     "IMD3_db": _finite(_db(((a[k2 - 2 * k1] + a[k2 + 2 * k1]) / a[k2]) ** 2))}
    return out


def _bands(other: np.ndarray, bin_width: float) -> list[np.ndarray]:
    if other.size == 0:
        return []
    f = other * bin_width
    index = np.floor(BANDS_PER_OCTAVE * np.log2(f / f[0])).astype(int)
    return [other[index == b] for b in np.unique(index)]


def _density(excited_power: np.ndarray, excited: np.ndarray, members: np.ndarray) -> float:
    """The excited lines' mean power around a band (the nearest lines if none lies inside)."""
    inside = (excited >= members[0]) & (excited <= members[-1])
    if not inside.any():
        nearest = np.argsort(np.abs(excited - members.mean()))[:3]
        inside = np.zeros(excited.size, dtype=bool)
        inside[nearest] = True
    return float(np.mean(excited_power[inside]))


def _delayed(x: np.ndarray, s: np.ndarray, delay_s: float) -> np.ndarray:
    if not delay_s:
        return x
    return np.fft.irfft(np.fft.rfft(x, axis=-1) * np.exp(s * delay_s), x.shape[-1], axis=-1)


def _rms(y: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(y))))


def _db(ratio: float) -> float:
    return 10.0 * math.log10(ratio) if ratio > 0 and math.isfinite(ratio) else float("nan")


def _finite(value: float) -> float | None:
    return float(value) if value is not None and math.isfinite(value) else None
