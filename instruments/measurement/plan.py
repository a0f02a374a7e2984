"""What a measurement plays and keeps: templates per driver class, and the plan made from one.

A template is a sensible start for a class of drivers (band, period, level,
periods); a MeasurementPlan is a template with the user's changes, frozen,
so a measurement thread can hold it. Levels are RMS volts at the terminals.

Periods are powers of two. The bin spacing is sample_rate / period: 65,536
samples at 48 kHz (0.73 Hz, 1.37 s) resolve a woofer's resonance and creep
below it; 16,384 (2.9 Hz, 0.34 s) suit drivers resonating above ~100 Hz.
The virtual rig's driver is a 65,536-tap FIR, whose steady state is exact
only for periods that divide 65,536 (every power of two up to it).

Settling: capture() discards ``settle_periods`` whole periods after the
fade-in and the first sound. They must outlast the driver's memory: a real
driver's decays in well under a second, the rig's FIR lasts exactly 65,536
samples, so the default asks for SETTLE_SAMPLES (the FIR plus a margin for
the audio round trip) rounded up to whole periods.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, is_dataclass, replace
from typing import Any, Mapping

from analysis.bounds import FREQUENCY, LEVEL_V_RMS, PERIODS
from analysis.errors import LinparError

SETTLE_SAMPLES = 65536 + 8192
ON_XRUN = ("end", "restart")


class PlanError(LinparError, ValueError):
    """A plan the measurement cannot follow (a level, a period, a template the user chose); one line."""


@dataclass(frozen=True, slots=True)
class MeasurementTemplate:
    name: str
    description: str
    f_min_hz: float
    f_max_hz: float
    period_samples: int
    level_v_rms: float
    n_periods: int
    lines_per_octave: float = 12.0
    settle_periods: int | None = None       # None: SETTLE_SAMPLES in whole periods


# A line's woofer in under 3 s (the end-of-line target): 4 periods of 16,384 samples (2.9 Hz between
# bins, 0.34 s each) after 4 settling ones (65,536 samples: the virtual rig's FIR; a real woofer's decay is far
# shorter), 2.7 s of sound, at a level given once (`--level`, the first unit's level check) instead of a
# level check per unit. Repeatability (tools/line_repeatability.py, 10 repeats on the in-process rig):
# docs/production.md.
LINE_WOOFER = ("woofer-line", "woofers on a production line, fs 25 - 100 Hz: 2.7 s of sound a unit at a level given "
               "once (no level check). 10 repeats on the in-process rig with a line's noise: 1 σ of Re 0.001 %, fs "
               "0.001 %, Qts 0.004 %, Bl 0.003 %, Mms 0.005 % (the full woofer template, 13.7 s: 0.000-0.002 %); "
               "that is the noise alone: a line's fixture, temperature and creep add theirs (docs/production.md)")

TEMPLATES: Mapping[str, MeasurementTemplate] = {t.name: t for t in (
    MeasurementTemplate("woofer", "bass and bass-midrange drivers, fs 15 - 100 Hz", 2.0, 10000.0, 65536, 1.0, 8),
    MeasurementTemplate("midrange", "midrange drivers, fs 100 - 500 Hz", 10.0, 20000.0, 16384, 1.0, 16),
    MeasurementTemplate("tweeter", "tweeters, fs above 500 Hz: nothing below 200 Hz", 200.0, 20000.0, 16384,
                        0.5, 16),
    MeasurementTemplate("microspeaker", "micro speakers and receivers, fs 300 Hz - 1.5 kHz", 50.0, 20000.0,
                        16384, 0.3, 16),
    # The large-signal plan's steps (large_signal_plan.py): short periods, few of them, from a small-signal level.
    MeasurementTemplate("large-signal", "large-signal steps of woofers and midranges, fs 20 - 200 Hz", 5.0, 10000.0,
                        16384, 0.5, 4),
    MeasurementTemplate(*LINE_WOOFER, 5.0, 10000.0, 16384, 1.0, 4, settle_periods=4),
)}


@dataclass(frozen=True, slots=True)
class MeasurementPlan:
    """Everything run_measurement needs to know besides the devices. SI units."""

    template: str = "woofer"
    f_min_hz: float = 2.0
    f_max_hz: float = 10000.0
    period_samples: int = 65536
    level_v_rms: float = 1.0
    n_periods: int = 8
    settle_periods: int | None = None     # None: SETTLE_SAMPLES in whole periods
    lines_per_octave: float = 12.0
    laser_rate_hz: float = 4000.0
    laser_sign: float = -1.0              # -1: the laser looks at the cone's front (outward = closer)
    laser_latency_s: float = 0.0          # a known latency of the serial laser's link, subtracted
    on_xrun: str | None = None            # "end" | "restart" (while periods are kept; see runner.py);
                                          # None: end with a serial laser, else restart
    driver: Mapping[str, Any] = field(default_factory=dict)     # {"name": ..., "sd_m2": ...}
    # What the caller knows of the chain's calibration (e.g. the wizard's reference-resistor corrections);
    # written into the recording's sidecar as "calibration", with the sound card's constants added.
    calibration: Mapping[str, Any] = field(default_factory=dict)
    # Who measures and where (analysis.session): the sidecar's "session", with the template, date and software.
    session: Mapping[str, Any] = field(default_factory=dict)
    seed: int = 0

    def __post_init__(self) -> None:
        p = self.period_samples
        if not (isinstance(p, int) and p >= 1024 and p & (p - 1) == 0):
            raise PlanError(f"period_samples must be a power of two >= 1024, got {p!r}")
        if not self.level_v_rms > 0:
            raise PlanError(f"the level must be > 0 V RMS, got {self.level_v_rms!r}")
        LEVEL_V_RMS.check(self.level_v_rms, "the level", PlanError)       # inf, 1e6 V: refused here too
        if not (isinstance(self.n_periods, int) and self.n_periods >= 2):
            raise PlanError(f"at least 2 periods are needed to estimate the noise, got {self.n_periods!r}")
        PERIODS.check(self.n_periods, "the periods averaged", PlanError)
        for name in ("f_min_hz", "f_max_hz"):
            FREQUENCY.check(getattr(self, name), name, PlanError)
        if self.settle_periods is not None and self.settle_periods < 0:
            raise PlanError(f"settle_periods must be >= 0, got {self.settle_periods!r}")
        if not 0 < self.f_min_hz < self.f_max_hz:
            raise PlanError(f"the band must be 0 < f_min < f_max, got {self.f_min_hz} - {self.f_max_hz} Hz")
        if self.on_xrun not in (None, *ON_XRUN):
            raise PlanError(f"on_xrun must be one of {ON_XRUN}, got {self.on_xrun!r}")
        if self.laser_sign not in (-1.0, 1.0):
            raise PlanError(f"laser_sign must be +1 or -1, got {self.laser_sign!r}")

    @classmethod
    def from_template(cls, name: str = "woofer", **changes: Any) -> MeasurementPlan:
        try:
            t = TEMPLATES[name]
        except KeyError:
            raise PlanError(f"unknown template {name!r}; known: {', '.join(TEMPLATES)}") from None
        base = cls(template=t.name, f_min_hz=t.f_min_hz, f_max_hz=t.f_max_hz, period_samples=t.period_samples,
                   level_v_rms=t.level_v_rms, n_periods=t.n_periods, lines_per_octave=t.lines_per_octave,
                   settle_periods=t.settle_periods)
        return replace(base, **{k: v for k, v in changes.items() if v is not None})

    @property
    def settle(self) -> int:
        """Periods discarded after the fade-in."""
        if self.settle_periods is not None:
            return self.settle_periods
        return math.ceil(SETTLE_SAMPLES / self.period_samples)

    def end_on_xrun(self, serial_laser: bool) -> bool:
        """Whether an xrun while periods are kept ends the measurement ("end"), or capture() discards them and
        averages again ("restart"; with the serial laser the audio's time line is then taken from the blocks
        after the xrun, since an xrun moves the audio's sample counter against the host clock)."""
        return self.on_xrun == "end" or (self.on_xrun is None and serial_laser)

    def excitation(self, sample_rate: int):
        """The multitone (analysis.multitone.Multitone) at this plan's band, period and level."""
        from analysis.multitone import design_multitone
        f_max = min(self.f_max_hz, 0.45 * sample_rate)
        return design_multitone(sample_rate, self.period_samples, self.f_min_hz, f_max,
                                lines_per_octave=self.lines_per_octave, rms=self.level_v_rms, seed=self.seed)

    def duration_s(self, sample_rate: int) -> float:
        """Nominal time at the sound card: settle and averaged periods."""
        return (self.settle + self.n_periods) * self.period_samples / sample_rate

    def sidecar_calibration(self, sound_card_constants) -> dict[str, Any]:
        """The recording's "calibration": the caller's (corrections) and the sound card's constants."""
        out = dict(self.calibration)
        if is_dataclass(sound_card_constants):
            out["sound_card"] = asdict(sound_card_constants)
        return out

    def as_json(self) -> dict[str, Any]:
        d = asdict(self)
        d["driver"] = dict(self.driver)
        d["calibration"] = dict(self.calibration)
        d["session"] = dict(self.session)
        d["settle_periods"] = self.settle
        return d
