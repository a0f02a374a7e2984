"""Klippel LPM-like exports of realistic drivers: magnitude-only |Z| and |Hx|, noisy, log-spaced, truth known.

What a Klippel dB-Lab LPM export of a real driver looks like (issue 29, item 4; the format in tests/lpm_files.py):
|Z| in ohm and |Hx| in mm/V, each a "Measured" curve beside LPM's "Fitted" one, on log-spaced lines from a
few hertz to 20 kHz, magnitudes only. The drivers are tests/realistic_drivers.py's (several physics at once,
none in any catalogue form: an eddy-current ladder, a causal creep of six stages, damping rising with
frequency, the air load, a cone mode seen partly at the laser's spot, Bl lost to eddy currents), plus a 6.5"
mid-woofer like the SEAS L16RNX (fs about 45 Hz, Mms 15 g, Bl 7 T*m, RE 5.7 ohm).

The noise is a real stand's, added to the complex curve before its magnitude is taken:
- |Z|: 0.15 % of the value per line, rising below 10 Hz (less current signal, more hum) to 1.5 % at 2 Hz;
- Hx: 0.3 % of the value, and the laser's floor, 2 nm/V per line: Hx falls 40 dB a decade above fs, so
  at several kHz the curve is the floor's (a magnitude, so biased upwards there, as a real export is).

The "Fitted" column is LPM's model family (an L2R2 blocked impedance and the log creep law) fitted to the
driver's noise-free complex curves below 2 kHz: a tool's fit of this driver, an overlay, not the truth.
"""
from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np

from tests.lpm_files import lpm_text
from tests.realistic_drivers import REALISTIC, RealisticDriver, _ladder

# A 6.5" mid-woofer like the SEAS L16RNX (its datasheet and Speakerbench's fit of its free-air curve).
MIDWOOFER = RealisticDriver("midwoofer", RE=5.7, LE=0.1e-3, ladder=_ladder(1.6e-3), Bl=7.0, Mmd=11.2e-3,
                            Kms=1.19e3, Rms=1.9, radius=0.0575, creep=0.11, ring_mass=2.4e-3, mode_hz=1700.0,
                            mode_q=4.0, spot=0.3, bl_loss=0.05, bl_corner_hz=500.0)
DRIVERS: dict[str, RealisticDriver] = {**REALISTIC, "midwoofer": MIDWOOFER}
EIGHT = ("RE", "fs", "Qts", "Qes", "Qms", "Bl", "Mms", "Cms")

Z_RELATIVE, HX_RELATIVE, HX_FLOOR = 1.5e-3, 3e-3, 2e-9      # HX_FLOOR in m/V


def lpm_frequencies(f_min: float = 2.0, f_max: float = 20e3, per_decade: int = 96) -> np.ndarray:
    return np.logspace(np.log10(f_min), np.log10(f_max), int(round(per_decade * np.log10(f_max / f_min))) + 1)


def truth(driver: RealisticDriver) -> dict[str, float]:
    """The eight parameters a user means: Rms is every mechanical loss at fs (the real part of Zm there)."""
    s = np.array([2j * np.pi * driver.fs])
    _, zm, _, _ = driver._parts(s)
    ws = 2 * np.pi * driver.fs
    qms = ws * driver.Mms / float(zm.real[0])
    qes = ws * driver.Mms * driver.RE / driver.Bl**2
    return {"RE": driver.RE, "fs": driver.fs, "Qts": qms * qes / (qms + qes), "Qes": qes, "Qms": qms,
            "Bl": driver.Bl, "Mms": driver.Mms, "Cms": 1.0 / driver.Kms, "Kms": driver.Kms}


def measured(driver: RealisticDriver, freqs: np.ndarray, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """|Z| (ohm) and |Hx| (m/V) with the module doc's noise."""
    rng = np.random.default_rng(seed)
    s = 2j * np.pi * freqs

    def noisy(value, sigma):
        return np.abs(value + sigma / np.sqrt(2) * (rng.standard_normal(len(freqs))
                                                    + 1j * rng.standard_normal(len(freqs))))

    z, hx = driver.impedance(s), driver.displacement(s)
    z_sigma = Z_RELATIVE * np.abs(z) * (1.0 + 9.0 * np.clip((10.0 / freqs - 1.0) / 4.0, 0.0, 1.0))
    hx_sigma = np.hypot(HX_RELATIVE * np.abs(hx), HX_FLOOR)
    return noisy(z, z_sigma), noisy(hx, hx_sigma)


@lru_cache(maxsize=None)
def lpm_fitted(name: str, per_decade: int = 96) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(freqs, |Z|, |Hx|) of LPM's model family (lr2 + creep-log) fitted to the noise-free complex curves below 2 kHz."""
    from analysis.effects import parse_effects
    from analysis.fit.least_squares import FitData, fit_model
    from analysis.model.composed import Model
    from analysis.spectra import TransferFunction
    driver = DRIVERS[name]
    freqs = lpm_frequencies(per_decade=per_decade)
    band = freqs[(freqs >= 5.0) & (freqs <= 2e3)]
    s = 2j * np.pi * band
    z, hx = driver.impedance(s), driver.displacement(s)
    curves = [TransferFunction(kind, unit, band, np.arange(len(band)), v, 1e-3 * np.abs(v), True, True)
              for kind, unit, v in (("impedance", "ohm", z), ("displacement", "m/V", hx))]
    model = Model(parse_effects("lr2,creep-log"))
    fit = fit_model(FitData(*curves), model)
    s_all = 2j * np.pi * freqs
    return freqs, np.abs(model.impedance(s_all, fit.values)), np.abs(model.displacement(s_all, fit.values))


def write_exports(folder: Path, name: str, seed: int = 0, per_decade: int = 96, fitted: bool = True
                  ) -> tuple[Path, Path]:
    """Z.txt and HX.txt of DRIVERS[name] in `folder` (LPM's format), the Fitted columns when `fitted`."""
    driver = DRIVERS[name]
    freqs = lpm_frequencies(per_decade=per_decade)
    z, hx = measured(driver, freqs, seed)
    z_fit, hx_fit = lpm_fitted(name, per_decade)[1:] if fitted else (None, None)
    folder.mkdir(parents=True, exist_ok=True)
    z_path, hx_path = folder / f"{name}_Z.txt", folder / f"{name}_HX.txt"
    z_path.write_text(lpm_text("impedance", z, z_fit, freqs), encoding="latin-1")
    hx_path.write_text(lpm_text("displacement", hx, hx_fit, freqs), encoding="latin-1")
    return z_path, hx_path
