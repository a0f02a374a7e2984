"""The large-signal model (analysis.large_signal.model) that a NonlinearBlockDriver is: the truth of the tests."""
from __future__ import annotations

import numpy as np

from analysis.large_signal.curves import Curve
from analysis.large_signal.model import LargeSignalModel, Scalar


def truth_model(driver, x_range=(-4e-3, 4e-3)) -> LargeSignalModel:
    """The simulator's curves and constants as a LargeSignalModel (no creep: the simulator's creep acts on its
    small-signal part only, which no large-signal model matches)."""
    p = driver.values
    bl0, le0 = p["Bl"], p["LE"]
    k0, l20 = bl0**2 / p["LCES"], p.get("L2", 0.0)

    def curve(name, c0, relative):
        c = np.concatenate([[c0], c0 * np.asarray(relative, dtype=float)])
        return Curve(name, c, np.zeros((c.size, c.size)), x_range)
    curves = {"Bl": curve("Bl", bl0, driver.bl_poly), "Kms": curve("Kms", k0, driver.kms_poly),
              "Le": curve("Le", le0, driver.le_poly)}
    if l20:
        curves["L2"] = curve("L2", l20, driver.l2_poly)
    rms = bl0**2 / p["RES"]
    scalars = {"RE": Scalar(p["RE"], 0.0), "R2": Scalar(p.get("R2", 0.0), 0.0),
               "Mms": Scalar(p["CMES"] * bl0**2, 0.0), "Rms": Scalar(rms, 0.0)}
    tau2 = l20 / p["R2"] if l20 else 1e-4
    return LargeSignalModel(curves, scalars, tau2, 0.0, 1.0, (le0 * driver.le_i_poly[0], le0 * driver.le_i_poly[1]),
                            rms * driver.rms_v2, 0.0, x_range)


# --- the known polynomials -------------------------------------------------------------------------------

from analysis.drivers import load_driver                       # noqa: E402
from analysis.multitone import design_multitone                # noqa: E402
from analysis.recording.format import make_recording                  # noqa: E402
from analysis.synthesis import ChannelNoise                    # noqa: E402

FS = 48000
# The paper's driver without creep (see truth_model): Bl(x) = Bl (1 - 0.03 x - 0.01 x^2), Kms(x) = Kms (1 + 0.04 x
# + 0.05 x^2), x in mm (here in m), Le(x) the simulator's default, LR-2 as the paper's.
NO_CREEP = {k: v for k, v in load_driver("paper").parameters.items() if k != "lambda"}
KNOWN = dict(bl_poly=(-30.0, -1e4), kms_poly=(40.0, 5e4), x_range_m=0.008)
# What the truth says: Bl(x) largest at x = -1.5 mm; Bl / Bl(0) = 0.82 at +3.0 mm (and -6.0 mm).
KNOWN_OFFSET_M = -1.5e-3
KNOWN_X_BL_M = 3.0e-3
KNOWN_LEVEL_V = 10.5            # the project multitone's RMS giving about +-4 mm
BENCH_NOISE = ChannelNoise(voltage=1e-4, current=1e-4, displacement=2e-7)


def known_driver(period: int, substeps: int = 1, **changes):
    from instruments.simulation.nonlinear_driver import NonlinearBlockDriver
    return NonlinearBlockDriver(NO_CREEP, FS, fir_length=period, substeps=substeps, **{**KNOWN, **changes})


def multitone(period: int):
    return design_multitone(FS, period, 5.0, 10000.0, rms=1.0)


def clean_periods(driver, level_v: float, periods: int, settle: int = 2):
    """The driver's noise-free signals: settle + periods periods of the project multitone at level_v."""
    mt = multitone(driver.fir_length)
    driver.reset()
    return driver.process(mt.scaled(rms=level_v).tile(periods + settle)), mt


def noisy_recording(block, mt, settle: int = 2, seed: int = 0, noise: ChannelNoise = BENCH_NOISE,
                    driver_name: str = "known polynomials"):
    rng = np.random.default_rng(seed)
    n = block.voltage.size
    signals = {"voltage": block.voltage + rng.normal(0, noise.voltage, n),
               "current": block.current + rng.normal(0, noise.current, n),
               "displacement": block.displacement + rng.normal(0, noise.displacement, n)}
    return make_recording(FS, signals, mt.period_samples, settle, tuple(int(k) for k in mt.excited_bins),
                          driver={"name": driver_name})


def write_steps(folder, levels=(5.0, 9.0), period: int = 8192) -> list:
    """The known driver at each level, 4 periods each, written as recordings in folder: their WAV paths."""
    from analysis.recording.format import write_recording
    driver = known_driver(period)
    paths = []
    for level in levels:
        block, mt = clean_periods(driver, level, 4)
        paths.append(write_recording(folder / f"step-{level:g}V", noisy_recording(block, mt))[0])
    return paths


def inner(x_range, share: float = 0.8, points: int = 81) -> np.ndarray:
    """`points` values of x over the middle `share` of x_range (the issue's "80 % of the covered range")."""
    lo, hi = x_range
    margin = (1.0 - share) / 2.0 * (hi - lo)
    return np.linspace(lo + margin, hi - margin, points)


def relative_errors(model, driver, name: str) -> tuple[float, float]:
    """The curve's largest relative error against the driver's truth over the middle 80 % of the measured range,
    and its relative error at rest (x = 0)."""
    curve, truth = model.curves[name], getattr(driver, name.lower())
    x = inner(model.x_range)
    return float(np.max(np.abs(curve(x) / truth(x) - 1.0))), float(curve(0.0) / truth(0.0) - 1.0)
