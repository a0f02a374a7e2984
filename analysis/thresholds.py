"""Every limit the validity checks use, in one place (docs/physics.md section 5).

The defaults below are what the workstation ships with; a JSON file of
overrides ({"snr_red_db": 25, ...}, any subset of the field names) changes
them for a lab: `load_thresholds(path)`. Nothing else in the code holds a
validity limit.

Levels are power ratios in dB (10*log10): a line's SNR is |line|^2 over the
variance of the averaged line (the squared noise floor), so 20 dB means the
noise floor is a tenth of the line's amplitude.

Why these numbers
-----------------
snr_red_db = 20
    A transfer function is a ratio of averaged lines, Z = U/I. With noise on
    the denominator the ratio is biased by about 1/SNR (power ratio): 1 % at
    20 dB, more than the paper's repeatability of RE (0.3 %) or Bl (0.35 %)
    (docs/physics.md section 7). Below it the parameters are not just noisy but wrong.
snr_yellow_db = 30
    A line's own scatter is then below 3 %; the fit still reports honest
    uncertainties below 30 dB, but they grow quickly.
snr_quantile = 0.1
    The SNR a channel is judged on is the one that 90 % of its lines exceed:
    the current is weakest at the impedance peak, which is exactly where the
    fit learns fs and Qms, so the weakest lines count, but a single odd line
    does not condemn the channel.
no_signal_*
    A disconnected input leaves lines that are noise: SNR ~ 0 dB, above
    10 dB on e^-10 of them. Fewer than a quarter of the lines 10 dB above
    the noise is "nothing connected" (or a level so low it is the same).
distortion_yellow_db = 6, distortion_red_db = 10
    Noise + distortion on the unexcited lines over the noise floor, in the
    worst band. Distortion products also fall on the excited lines, where they
    are a bias the fit cannot see: at 6 dB the bias is already above the
    reported 1-sigma; at 10 dB it is three times it. Bands of at least
    distortion_min_bins = 32 lines keep the noise-only ratio within ~1 dB,
    so noise alone never reaches 6 dB even in the worst of thirty bands.
x_band_red_hz = 300
    docs/physics.md: a displacement that sinks into the noise below ~300 Hz does
    not carry the resonance region well enough to give Bl. Yellow below 500 Hz.
x_line_snr_db = 20, x_lines_red = 10, x_lines_yellow = 20
    A displacement line "stands above the noise" at 20 dB (the same bias
    argument as snr_red_db). Hx adds Bl and the creep to the fit; fewer than
    10 usable lines cannot pin them down (resonance close to the sensor's
    bandwidth).
full_scale_red = 0.999, full_scale_yellow = 0.9
    A sample at full scale is a clipped sample. Above 90 % of full scale
    (< 1 dB headroom) the next level step will clip.
laser_error_red_share = 0.01, out_of_range_red_share = 0.001
    Error codes are not distances (docs/laser-protocol.md). When the recording
    says what leaving them out cost (capture.laser_gaps), that decides (the
    laser_gap_* below); otherwise any is yellow, 1 % is red. Out of range
    means the cone left the measuring range at its peaks, which clips the
    displacement: any is yellow, 0.1 % red.
laser_gap_growth_yellow = 0.10, laser_gap_growth_red = 0.5, laser_gap_unseen_red_s = 0.0005
    Missing laser samples are left out of the average; the result stays
    unbiased and its uncertainty grows with what is missing. Yellow when the
    displacement's standard uncertainty grew by 10 % (about a fifth of its
    data lost), red at 50 % (more than half): the laser's setup is failing.
    Red too when a stretch of the period longer than 0.5 ms (two samples at
    4 kHz) was measured in no period: the spot was lost at the same point of
    every period, and there the motion is only bridged, a guess.
copy_residual_red = 1e-4
    A channel whose excited lines are those of another times one complex
    gain, to 1 % in amplitude (1e-4 in power), is a copy of it: two inputs on
    one sense (analysis.validity.wiring). The motional branch alone moves |Z|
    by a factor of 2 or more, so no driver comes near; a resistor does.
misfit_yellow_chi2_red = 100
    A reduced chi^2 of 100 on a fitted channel is a misfit ten times the
    noise on every line: the model does not describe the measurement, and
    the parameters carry an error their (Birge-scaled) uncertainties only
    guess at (analysis.validity.fit). Yellow, and QA does not judge it.
drift_*
    Line spectra of the first and the last drift_periods periods compared.
    A drift of 0.5 % is above the paper's repeatability (yellow), 2 % is a
    driver that changed during the measurement (red). It must also be
    drift_significance times what the noise alone would give.
"""
from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path
from typing import Any, Mapping

from analysis.errors import LinparError
from analysis.files import read_text


class ThresholdsError(LinparError, ValueError):
    """An override file that cannot be used; the message names the file and the key."""


@dataclass(frozen=True, slots=True)
class ValidityThresholds:
    """Every limit of the validity checks (module doc): the defaults, or a lab's overrides (load_thresholds)."""

    # Signal-to-noise on the excited lines (dB).
    snr_quantile: float = 0.1
    snr_yellow_db: float = 30.0
    snr_red_db: float = 20.0
    noise_pool_lines: int = 5           # excited lines whose noise is pooled for each line's SNR
    # Nothing connected.
    no_signal_line_snr_db: float = 10.0
    no_signal_share: float = 0.25
    # Noise + distortion on the unexcited lines over the noise floor (dB, worst band).
    distortion_yellow_db: float = 6.0
    distortion_red_db: float = 10.0
    distortion_band_octaves: float = 1.0 / 3.0
    distortion_min_bins: int = 32
    # The displacement's usable band.
    x_line_snr_db: float = 20.0
    x_band_red_hz: float = 300.0
    x_band_yellow_hz: float = 500.0
    x_lines_red: int = 10
    x_lines_yellow: int = 20
    # Capture (CaptureInfo): fractions of full scale, shares of laser measurements.
    full_scale_red: float = 0.999
    full_scale_yellow: float = 0.9
    laser_error_red_share: float = 0.01
    out_of_range_red_share: float = 0.001
    # Laser samples left out as missing data (capture.laser_gaps): what it cost the result.
    laser_gap_growth_yellow: float = 0.10
    laser_gap_growth_red: float = 0.5
    laser_gap_unseen_red_s: float = 0.0005
    # A channel that copies another (residual power of the best complex gain, fraction).
    copy_residual_red: float = 1e-4
    # The fit's misfit (reduced chi^2 of a fitted channel).
    misfit_yellow_chi2_red: float = 100.0
    # Drift between the first and the last periods (relative change, fraction).
    drift_periods: int = 4
    drift_yellow: float = 0.005
    drift_red: float = 0.02
    drift_significance: float = 4.0

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ThresholdsError(f"{f.name}: found {value!r}, expected a finite number")
            if f.type == "int":
                if value != int(value):
                    raise ThresholdsError(f"{f.name}: found {value!r}, expected a whole number")
                object.__setattr__(self, f.name, int(value))       # 10.0 from JSON reads as 10
        pairs = (("snr_red_db", "snr_yellow_db"), ("distortion_yellow_db", "distortion_red_db"),
                 ("x_band_red_hz", "x_band_yellow_hz"), ("x_lines_red", "x_lines_yellow"),
                 ("full_scale_yellow", "full_scale_red"), ("drift_yellow", "drift_red"))
        for low, high in pairs:
            if getattr(self, low) > getattr(self, high):
                raise ThresholdsError(f"{low} ({getattr(self, low)}) must not exceed {high} ({getattr(self, high)})")
        if not 0.0 <= self.snr_quantile <= 1.0 or not 0.0 <= self.no_signal_share <= 1.0:
            raise ThresholdsError("snr_quantile and no_signal_share are fractions in 0..1")
        if self.noise_pool_lines < 1 or self.distortion_min_bins < 1 or self.drift_periods < 1:
            raise ThresholdsError("noise_pool_lines, distortion_min_bins and drift_periods must be at least 1")
        if self.distortion_band_octaves <= 0:
            raise ThresholdsError("distortion_band_octaves must be positive")
        if not 0.0 <= self.copy_residual_red < 1.0:
            raise ThresholdsError("copy_residual_red is a fraction of the channel's power in 0..1")
        if self.misfit_yellow_chi2_red < 1.0:
            raise ThresholdsError("misfit_yellow_chi2_red must be at least 1 (a model that fits gives 1)")

    def as_json(self) -> dict[str, float]:
        return asdict(self)

    def with_overrides(self, overrides: Mapping[str, Any], label: str = "<overrides>") -> "ValidityThresholds":
        known = {f.name for f in fields(self)}
        for key in overrides:
            if key not in known:
                raise ThresholdsError(f"{label}: unknown threshold {key!r}; known: {', '.join(sorted(known))}")
        try:
            return replace(self, **dict(overrides))
        except ThresholdsError as err:
            raise ThresholdsError(f"{label}: {err}") from None


DEFAULT_THRESHOLDS = ValidityThresholds()


def _not_a_number(name: str):
    raise ValueError(f"{name} is not a number")


def load_thresholds(path: str | Path, base: ValidityThresholds = DEFAULT_THRESHOLDS) -> ValidityThresholds:
    """The defaults with the overrides of a JSON object file ({field: number}) applied."""
    path = Path(path)
    text = read_text(path, "config", "a JSON file of threshold overrides", ThresholdsError)
    try:
        doc = json.loads(text, parse_constant=_not_a_number)
    except (json.JSONDecodeError, RecursionError, ValueError) as err:      # ValueError: NaN, a 5000-digit int
        raise ThresholdsError(f"{path}: not a readable JSON file ({err})") from None
    if not isinstance(doc, dict):
        raise ThresholdsError(f"{path}: expected a JSON object of threshold overrides")
    return base.with_overrides(doc, str(path))
