"""Choosing the measurement level: enough signal, no distortion, excursion within the user's limit.

`level_check` measures at a safe minimum and raises the level in steps of
`step` (x1.6 by default, 4 dB) until the SNR reaches its target. It stops
early, and keeps the last level that was still right, when

- a channel's noise + distortion stands `distortion_limit_db` above its noise
  floor (the driver leaves its linear range, or the amplifier limits),
- the peak excursion passes `x_limit_m` (0.5 mm by default: the small-signal
  range, docs/physics.md section 6),
- the next step would pass `v_max`, the user's maximum voltage (it then
  measures at v_max once).

Each step is also shortened so as not to overshoot a limit that the last probe
predicts: the excursion grows in proportion to the level, and the distortion
power over the (fixed) noise as level^6 for third-order products, the ones a
symmetric Kms(x) or Bl(x) makes (second-order ones grow as level^4, more
slowly, so they stay under the prediction):

    level_next <= level * x_limit / x_peak * 0.95
    level_next <= level * (excess_limit / excess)^(1/6),   excess = 10^(D/10) - 1

Near the distortion limit the steps thus shrink; when the next one would be
less than 1 % the check stops at the present level (the limit, predicted).

The levels are whatever `measure_at` takes (V RMS at the terminals, by the
project's convention).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

from analysis.excursion import DEFAULT_X_LIMIT_M
from analysis.recording.format import Recording
from analysis.thresholds import DEFAULT_THRESHOLDS, ValidityThresholds
from analysis.validity.assessment import Validity, assess

DEFAULT_STEP = 1.6
SNR_MARGIN_DB = 10.0           # default target: this far above the green SNR limit
_EXCURSION_MARGIN = 0.95
_DISTORTION_GROWTH = 6.0       # power exponent of third-order products over a fixed noise
MAX_PROBES = 30


@dataclass(frozen=True, slots=True)
class LevelProbe:
    """What one measurement at one level says about that level."""

    level: float
    snr_db: float                       # the weakest channel's SNR (validity's quantile statistic)
    snr_channel: str
    distortion_db: float                # the worst channel's noise + distortion over its noise floor
    distortion_channel: str
    peak_displacement_m: float | None
    validity: Validity | None = None

    @classmethod
    def from_validity(cls, level: float, validity: Validity) -> "LevelProbe":
        snr = {name: ch.measures.get("snr_db", -math.inf) for name, ch in validity.channels.items()
               if ch.status != "absent"}
        dist = {name: ch.measures.get("distortion_db", 0.0) for name, ch in validity.channels.items()
                if ch.status != "absent"}
        weakest = min(snr, key=snr.get)
        worst = max(dist, key=dist.get)
        return cls(float(level), float(snr[weakest]), weakest, float(dist[worst]), worst,
                   validity.peak_displacement_m, validity)

    @classmethod
    def from_recording(cls, level: float, recording: Recording,
                       thresholds: ValidityThresholds = DEFAULT_THRESHOLDS) -> "LevelProbe":
        return cls.from_validity(level, assess(recording, thresholds=thresholds))

    def describe(self) -> str:
        peak = "no displacement" if self.peak_displacement_m is None else \
            f"peak {self.peak_displacement_m * 1e3:.3f} mm"
        return (f"{self.level:.4g} V: SNR {self.snr_db:.1f} dB ({self.snr_channel}), noise + distortion "
                f"{self.distortion_db:.1f} dB over the floor ({self.distortion_channel}), {peak}")


@dataclass(frozen=True, slots=True)
class LevelDecision:
    level: float | None                 # None: not even v_min is usable
    # "snr-reached" | "distortion" | "excursion" | "max-voltage" | "too-loud-at-min" | "max-probes"
    reason_code: str
    reason: str
    probes: tuple[LevelProbe, ...]

    @property
    def chosen(self) -> LevelProbe | None:
        return next((p for p in reversed(self.probes) if p.level == self.level), None)


def level_check(measure_at: Callable[[float], LevelProbe], v_min: float, v_max: float,
                x_limit_m: float = DEFAULT_X_LIMIT_M, step: float = DEFAULT_STEP,
                snr_target_db: float | None = None, distortion_limit_db: float | None = None,
                thresholds: ValidityThresholds = DEFAULT_THRESHOLDS, max_probes: int = MAX_PROBES) -> LevelDecision:
    """Raise the level from v_min until the SNR is enough, within the limits (see the module doc)."""
    if not 0 < v_min <= v_max:
        raise ValueError(f"expected 0 < v_min <= v_max, got v_min={v_min}, v_max={v_max}")
    if step <= 1.0:
        raise ValueError(f"step must be above 1, got {step}")
    target = thresholds.snr_yellow_db + SNR_MARGIN_DB if snr_target_db is None else snr_target_db
    d_limit = thresholds.distortion_yellow_db if distortion_limit_db is None else distortion_limit_db
    probes: list[LevelProbe] = []
    good: LevelProbe | None = None
    level = float(v_min)

    def decide(chosen: LevelProbe | None, code: str, why: str) -> LevelDecision:
        if chosen is None:
            return LevelDecision(None, "too-loud-at-min", f"{why}; even the minimum level {v_min:.4g} V is too "
                                 f"loud: lower v_min", tuple(probes))
        return LevelDecision(chosen.level, code, f"{why}; chosen {chosen.describe()}", tuple(probes))

    for _ in range(max_probes):
        probe = measure_at(level)
        probes.append(probe)
        peak = probe.peak_displacement_m
        if peak is not None and peak > x_limit_m:
            return decide(good, "excursion", f"at {level:.4g} V the peak excursion {peak * 1e3:.3f} mm passed "
                                             f"the limit {x_limit_m * 1e3:.3f} mm")
        if probe.distortion_db >= d_limit:
            return decide(good, "distortion", f"at {level:.4g} V the {probe.distortion_channel}'s noise + "
                                              f"distortion stood {probe.distortion_db:.1f} dB over its noise "
                                              f"floor (limit {d_limit:g} dB)")
        good = probe
        if probe.snr_db >= target:
            return decide(probe, "snr-reached", f"the SNR reached {probe.snr_db:.1f} dB "
                                                f"({probe.snr_channel}; target {target:g} dB)")
        if level >= v_max:
            return decide(probe, "max-voltage", f"the maximum voltage {v_max:.4g} V leaves the SNR at "
                                                f"{probe.snr_db:.1f} dB ({probe.snr_channel}; target {target:g} dB)")
        nxt = min(level * step, v_max, _predicted_limit(probe, x_limit_m, d_limit))
        if nxt <= level * 1.01:
            return decide(probe, "excursion" if _excursion_bound(probe, x_limit_m) <= nxt * 1.0001 else
                          "distortion", "the next step would pass a limit (predicted from this level)")
        level = nxt
    return decide(good, "max-probes", f"no decision after {max_probes} probes")


def _excursion_bound(probe: LevelProbe, x_limit_m: float) -> float:
    peak = probe.peak_displacement_m
    if not peak:
        return math.inf
    return probe.level * x_limit_m / peak * _EXCURSION_MARGIN


def _predicted_limit(probe: LevelProbe, x_limit_m: float, d_limit_db: float) -> float:
    """The highest level the next step may take without passing a limit, predicted from this probe."""
    bound = _excursion_bound(probe, x_limit_m)
    excess = 10.0 ** (min(probe.distortion_db, 300.0) / 10.0) - 1.0
    if excess > 0.0 and d_limit_db < 300.0:
        allowed = 10.0 ** (d_limit_db / 10.0) - 1.0
        bound = min(bound, probe.level * (allowed / excess) ** (1.0 / _DISTORTION_GROWTH))
    return bound
