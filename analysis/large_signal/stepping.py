"""The large-signal plan's decisions: what one step measured, whether to stop, and the next level. No devices.

Each step is one multitone recording at a level (V RMS at the terminals).
What it says about the driver, from its periods:

    peak excursion       the coherent mean period's largest |x - mean| (analysis.excursion), trusted only
                         when the displacement repeated from period to period as the voltage did
                         (displacement_repeat.py): a laser stream misplaced in time averages to a low peak
    current distortion   the power at the lines not excited, within the excitation's band, less the
                         noise, over the power at the excited lines, in dB (analysis.large_signal.distortion's
                         measure; -20 dB: the distortion is a tenth of the signal in amplitude)
    coil temperature     RE per period: the mean of Re(U / I) over the lines where |Z| is within 10 % of
                         its minimum above the resonance (there Z is RE plus little else); the rise over
                         the first step's first period, through copper's 0.393 %/K

    voltage              its RMS (the coherent mean period's) and its own distortion, as the current's: a
                         distorted voltage, or one below the level asked for, is the amplifier or the sound
                         card limiting

The plan stops as soon as a step's displacement did not repeat (its peak
cannot be trusted, and the next level is predicted from it: a "fault"), or a
step reaches any limit (the user's peak excursion, the voltage, the current distortion, the coil's temperature
rise), or the chain cannot deliver the level (the voltage distorted above
VOLTAGE_DISTORTION_DB, more than 10 % below the level, or an input at its
converter's full scale: the sidecar's capture counts), keeping every step. Otherwise the next level is the present one
times ``step``, shortened so as not to overshoot a limit predicted from this
step: the excursion grows in proportion to the level, the third-order
distortion's power ratio as level^4 (40 dB per decade; the second order's
grows more slowly, so stays under the prediction):

    next <= level * x_limit / peak,   next <= level * 10^((D_limit - D) / 40),   next <= v_max

When the next step would be less than 2 % above this one, the plan stops
here: the limit is reached as predicted.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import asdict, dataclass

import numpy as np

from analysis.bounds import DISTORTION_DB, EXCURSION_MM, LEVEL_V_RMS, TEMPERATURE_RISE_K
from analysis.excursion import recording_peak_displacement
from analysis.large_signal.displacement_repeat import MAX_DISPLACEMENT_CHANGE, displacement_change
from analysis.large_signal.data import LargeSignalError
from analysis.recording.format import Recording

COPPER_ALPHA_PER_K = 0.00393
MIN_STEP_RATIO = 1.02
REACHED = 0.98            # a limit counts as reached at this share of it (a step never lands exactly)
VOLTAGE_DISTORTION_DB = -40.0     # the amplifier limits: a clean amplifier stays far below (validity: -60 dB)
LEVEL_SHORTFALL = 0.9     # the chain delivers less than this share of the level asked for
STOPS = ("excursion", "voltage", "distortion", "temperature", "clipping", "steps", "fault", "cancelled")


@dataclass(frozen=True, slots=True)
class StepLimits:
    max_excursion_m: float = 4e-3
    max_voltage_v: float = 10.0
    max_current_distortion_db: float = -20.0
    max_temperature_rise_k: float = 20.0

    def __post_init__(self) -> None:
        # The same bounds as the CLI's options (analysis.bounds), the excursion's in mm
        excursion = self.max_excursion_m
        EXCURSION_MM.check(excursion * 1e3 if isinstance(excursion, numbers.Real) else excursion,
                           "max_excursion_m (in mm)", LargeSignalError)
        LEVEL_V_RMS.check(self.max_voltage_v, "max_voltage_v", LargeSignalError)
        DISTORTION_DB.check(self.max_current_distortion_db, "max_current_distortion_db", LargeSignalError)
        TEMPERATURE_RISE_K.check(self.max_temperature_rise_k, "max_temperature_rise_k", LargeSignalError)

    def as_json(self) -> dict:
        return asdict(self)


@dataclass(frozen=True, slots=True)
class StepMeasures:
    level_v: float
    peak_m: float | None
    current_distortion_db: float
    re_per_period: tuple[float, ...]
    drive_rms_v: float = float("nan")
    voltage_distortion_db: float = -math.inf
    clipped: tuple[str, ...] = ()           # inputs that reached their converter's full scale
    displacement_change: float | None = None    # relative, period to period (displacement_repeat.py)

    @property
    def displacement_repeats(self) -> bool:
        """The displacement's periods agree (or there is no displacement): its peak can be trusted."""
        return self.displacement_change is None or self.displacement_change <= MAX_DISPLACEMENT_CHANGE

    @property
    def re_ohm(self) -> float:
        return float(np.mean(self.re_per_period)) if self.re_per_period else float("nan")

    def temperature_rise_k(self, re_reference: float) -> float:
        """From the last period's RE: the coil is warmest at the end of the step."""
        if not self.re_per_period or not re_reference > 0:
            return float("nan")
        return (self.re_per_period[-1] / re_reference - 1.0) / COPPER_ALPHA_PER_K

    def as_json(self, re_reference: float) -> dict:
        return {"level_v": self.level_v, "drive_rms_v": _finite(self.drive_rms_v),
                "peak_displacement_m": self.peak_m,
                "current_distortion_db": _finite(self.current_distortion_db),
                "voltage_distortion_db": _finite(self.voltage_distortion_db), "clipped": list(self.clipped),
                "displacement_change": self.displacement_change,
                "re_ohm_per_period": list(self.re_per_period),
                "temperature_rise_k": _finite(self.temperature_rise_k(re_reference))}


def step_measures(recording: Recording, level_v: float, re_lines: np.ndarray | None = None
                  ) -> tuple[StepMeasures, np.ndarray]:
    """What one step's recording says (module doc), and the lines RE is read at (chosen on the first step)."""
    u = np.fft.rfft(recording.periods("voltage"), axis=1)
    i = np.fft.rfft(recording.periods("current"), axis=1)
    excited = np.asarray(recording.excited_bins, dtype=np.int64)
    mean = i.mean(axis=0)
    if re_lines is None:
        re_lines = _resistive_lines(u.mean(axis=0)[excited] / mean[excited], excited)
    u_mean = recording.periods("voltage").mean(axis=0)
    drive = float(np.sqrt(np.mean((u_mean - u_mean.mean()) ** 2)))
    with np.errstate(divide="ignore", invalid="ignore"):
        re = np.real(u[:, re_lines] / i[:, re_lines]).mean(axis=1)
    peak = recording_peak_displacement(recording) if recording.signal("displacement") is not None else None
    return StepMeasures(float(level_v), peak, distortion_db(i, excited), tuple(float(r) for r in re), drive,
                        distortion_db(u, excited), clipped_inputs(recording),
                        displacement_change(recording)), re_lines


def clipped_inputs(recording: Recording) -> tuple[str, ...]:
    """The inputs the sidecar's "capture" says reached full scale (none when it does not say)."""
    from analysis.pipeline import checked_capture
    capture = checked_capture(recording)
    if capture is None:
        return ()
    return tuple(sorted(name for name, count in capture.clipped_samples.items() if count > 0))


def distortion_db(per_period: np.ndarray, excited: np.ndarray) -> float:
    """The power at the lines not excited (within the excitation's band, less their noise) over the power at
    the excited lines, dB, from per-period spectra (P, bins); -inf when nothing stands above the noise."""
    mean = per_period.mean(axis=0)
    p = per_period.shape[0]
    var = np.sum(np.abs(per_period - mean) ** 2, axis=0) / (p * (p - 1))
    other = np.setdiff1d(np.arange(excited[0], excited[-1] + 1), excited)
    distortion = float(np.sum(np.abs(mean[other]) ** 2 - var[other]))
    signal = float(np.sum(np.abs(mean[excited]) ** 2))
    return 10.0 * math.log10(distortion / signal) if distortion > 0 and signal > 0 else -math.inf


def displacement_not_repeating(step: StepMeasures) -> str:
    """What a step whose displacement did not repeat says about it: the change, and its likely cause."""
    peak = "" if step.peak_m is None else f" (its peak {step.peak_m * 1e3:.2f} mm may be too low)"
    return f"the displacement at {step.level_v:.3g} V changed by {step.displacement_change:.0%} from period to " \
           f"period while the voltage repeated{peak}: the laser's stream was not placed right in time (a busy machine?)"


def stop_reason(step: StepMeasures, limits: StepLimits, re_reference: float, measured_again: bool = False
                ) -> tuple[str, str] | None:
    """(code, words) when this step reached a limit or its displacement cannot be trusted, else None.
    `measured_again`: this level was measured a second time because the first did not repeat."""
    if not step.displacement_repeats:
        again = ", and so it did when measured again" if measured_again else ""
        return "fault", f"{displacement_not_repeating(step)}{again}; the plan stops rather than step on past the " \
                        f"excursion limit: measure again with the machine less busy"
    if step.clipped:
        return "clipping", f"the {' and '.join(step.clipped)} input reached its full scale at {step.level_v:.3g} V: " \
                           f"a larger input range (lower sense gain) would let the plan go on"
    if step.peak_m is not None and step.peak_m >= REACHED * limits.max_excursion_m:
        return "excursion", f"the peak excursion {step.peak_m * 1e3:.2f} mm reached the limit " \
                            f"{limits.max_excursion_m * 1e3:.2f} mm"
    if step.current_distortion_db >= limits.max_current_distortion_db:
        return "distortion", f"the current's distortion {step.current_distortion_db:.1f} dB reached the limit " \
                             f"{limits.max_current_distortion_db:g} dB"
    rise = step.temperature_rise_k(re_reference)
    if math.isfinite(rise) and rise >= limits.max_temperature_rise_k:
        return "temperature", f"the voice coil warmed by {rise:.1f} K (RE {step.re_per_period[-1]:.3f} ohm), " \
                              f"the limit is {limits.max_temperature_rise_k:g} K"
    if step.voltage_distortion_db >= VOLTAGE_DISTORTION_DB:
        return "voltage", f"the voltage itself is distorted ({step.voltage_distortion_db:.1f} dB) at " \
                          f"{step.level_v:.3g} V: the amplifier or the sound card limits there"
    if math.isfinite(step.drive_rms_v) and step.drive_rms_v < LEVEL_SHORTFALL * step.level_v:
        return "voltage", f"the chain delivered {step.drive_rms_v:.3g} V of the {step.level_v:.3g} V asked for: " \
                          f"check the amplifier's gain and the calibration"
    if step.level_v >= REACHED * limits.max_voltage_v:
        return "voltage", f"the level reached the maximum voltage {limits.max_voltage_v:g} V"
    return None


def next_level(step: StepMeasures, limits: StepLimits, factor: float) -> tuple[float | None, str]:
    """The next level, or (None, why) when it would not be meaningfully above this one."""
    candidates = [(step.level_v * factor, "step"), (limits.max_voltage_v, "voltage")]
    if step.peak_m:
        candidates.append((step.level_v * limits.max_excursion_m / step.peak_m, "excursion"))
    if math.isfinite(step.current_distortion_db):
        headroom = limits.max_current_distortion_db - step.current_distortion_db
        candidates.append((step.level_v * 10.0 ** (headroom / 40.0), "distortion"))
    level, why = min(candidates)
    if level < MIN_STEP_RATIO * step.level_v:
        return None, why
    return level, why


def _resistive_lines(z: np.ndarray, lines: np.ndarray) -> np.ndarray:
    """Lines above the resonance where |Z| is within 10 % of its minimum there (Z ~ RE)."""
    magnitude = np.abs(z)
    peak = int(np.argmax(magnitude))
    above = np.arange(peak, magnitude.size)
    low = above[np.argmin(magnitude[above])]
    chosen = above[magnitude[above] <= 1.1 * magnitude[low]]
    return lines[chosen] if chosen.size else lines[[low]]


def _finite(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None
