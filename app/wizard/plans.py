"""What the wizard measures with: the driver's data and a template per driver class. Qt-free.

The excitation of each class (band, period, periods averaged) is
instruments.measurement's template, so the wizard measures exactly what
`linpar measure` would; the level check's limits (where to start, the maximum
voltage, the excursion limit) are the wizard's own, since the runner measures
at one given level.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from analysis.multitone import Multitone, design_multitone
from instruments.measurement import TEMPLATES as RUNNER_TEMPLATES, MeasurementPlan

SAMPLE_RATE = 48000
LARGE_SIGNAL = "large-signal"       # the template whose measurement is the large-signal plan, not one recording
PROBE_SECONDS = 1.0         # averaged per level-check probe: enough for the SNR statistics, not more


@dataclass(frozen=True, slots=True)
class DriverInfo:
    name: str
    serial: str = ""
    sd_m2: float | None = None
    nominal_impedance_ohm: float | None = None
    template: str = "woofer"
    # Who measured, and where: for the archive's record, not part of the recording's driver object.
    operator: str = ""
    station: str = ""

    def as_json(self) -> dict:
        """The recording's "driver" object (analysis.pipeline.resolve_sd reads sd_m2 from it)."""
        out = {"name": self.name, "serial": self.serial, "template": self.template}
        if self.sd_m2:
            out["sd_m2"] = self.sd_m2
        if self.nominal_impedance_ohm:
            out["nominal_impedance_ohm"] = self.nominal_impedance_ohm
        return out


@dataclass(frozen=True, slots=True)
class Template:
    key: str
    title: str
    f_min_hz: float
    f_max_hz: float
    period_samples: int
    n_periods: int            # averaged in the measurement
    settle_periods: int       # discarded first: the driver's decay and the rig's FIR length
    probe_periods: int        # averaged per level-check probe
    v_min: float              # V rms, where the level check starts
    v_max: float              # V rms, never exceeded
    x_limit_m: float          # peak excursion the level check stays under
    sample_rate: int = SAMPLE_RATE
    lines_per_octave: float = 12.0

    @property
    def band_hz(self) -> tuple[float, float]:
        return self.f_min_hz, min(self.f_max_hz, 0.45 * self.sample_rate)     # as the runner designs it

    def describe(self) -> str:
        seconds = (self.n_periods + self.settle_periods) * self.period_samples / self.sample_rate
        return (f"{self.f_min_hz:g} Hz – {self.f_max_hz / 1000:g} kHz, {self.n_periods} periods of "
                f"{self.period_samples} samples at {self.sample_rate / 1000:g} kHz (~{seconds:.0f} s); level "
                f"check {self.v_min:g}–{self.v_max:g} V rms, excursion ≤ {self.x_limit_m * 1e3:g} mm")

    def as_json(self) -> dict:
        return asdict(self)


# key: (title, v_min, v_max, x_limit_m) - the level check's limits, inside each class's small-signal range.
LEVEL_LIMITS = {
    "woofer": ("Woofer (fs 15–100 Hz)", 0.05, 5.0, 0.5e-3),
    "midrange": ("Midrange (fs 100–500 Hz)", 0.05, 4.0, 0.3e-3),
    "tweeter": ("Tweeter (fs above 500 Hz)", 0.02, 2.0, 0.05e-3),
    "microspeaker": ("Microspeaker (fs 300 Hz – 1.5 kHz)", 0.01, 1.0, 0.1e-3),
    # The level check finds the small-signal level the large-signal plan starts from (app/wizard/tasks.py).
    LARGE_SIGNAL: ("Large signal: Bl(x), Kms(x), Le(x) (woofers, midranges)", 0.05, 5.0, 0.5e-3),
}
def _probe_periods(period: int) -> int:
    return max(3, math.ceil(PROBE_SECONDS * SAMPLE_RATE / period))


def _templates() -> dict[str, Template]:
    out = {}
    for key, (title, v_min, v_max, x_limit) in LEVEL_LIMITS.items():
        t = RUNNER_TEMPLATES[key]
        settle = MeasurementPlan.from_template(key).settle
        out[key] = Template(key, title, t.f_min_hz, t.f_max_hz, t.period_samples, t.n_periods, settle,
                            _probe_periods(t.period_samples), v_min, v_max, x_limit,
                            lines_per_octave=t.lines_per_octave)
    return out


TEMPLATES: dict[str, Template] = _templates()

def multitone_for(template: Template) -> Multitone:
    """The template's multitone at 1 V rms, as the runner designs it (design_multitone remembers the design)."""
    f_min, f_max = template.band_hz
    return design_multitone(template.sample_rate, template.period_samples, f_min, f_max,
                            lines_per_octave=template.lines_per_octave, rms=1.0, seed=0)


def sd_from_diameter(diameter_m: float) -> float:
    """Sd of a piston of that effective diameter (the surround's half width included, by convention)."""
    return math.pi * diameter_m**2 / 4.0
