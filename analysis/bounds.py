"""Every plausible range of a number from outside, and every file size limit, in one place.

Numbers enter from files (a recording's WAV header and sidecar, imported
curves, driver files, archive records), from options, and from devices (the
laser's replies). Each is checked where it enters, once, before any physics
sees it: it must be a finite number inside its Bound, else the one message
of that check names where it came from, what was found and what is expected.

The ranges are wide: they refuse what no real measurement gives (a header
field overwritten with garbage, a typo of ten orders of magnitude, NaN), not
what is merely unusual. docs/bounds.md shows them as a table; it is generated
from this module (`markdown_table`) and a test keeps the two equal.

File sizes: every file linpar reads whole has a SizeLimit. The defaults fit
any real measurement with room to spare; `linpar --size-limit KIND=SIZE ...`
raises one for a command (`size_limits_set`), e.g. for a recording longer
than 2 GB of samples.
"""
from __future__ import annotations

import contextlib
import contextvars
import math
import numbers
import re
from dataclasses import dataclass, replace
from typing import Iterator

from analysis.errors import LinparError


class BoundsError(LinparError, ValueError):
    """A number outside its plausible range, or not a number; one line."""


@dataclass(frozen=True)
class Bound:
    """The range [low, high] of one kind of number, inclusive, in `unit`."""

    what: str           # "a sample rate"
    unit: str
    low: float
    high: float
    why: str            # where the limits come from, for the table
    integer: bool = False

    def expected(self) -> str:
        kind = "a whole number" if self.integer else "a number"
        unit = f" {self.unit}" if self.unit else ""
        return f"{self.what}: {kind} from {self.low:g} to {self.high:g}{unit}"

    def check(self, value, where: str, error: type[LinparError] = BoundsError):
        """`value` as a float (an int for an integer bound); `error`(one line naming `where`) otherwise."""
        ok = isinstance(value, numbers.Real) and not isinstance(value, bool)
        if ok:
            try:
                ok = math.isfinite(value) and self.low <= value <= self.high
            except OverflowError:       # an integer beyond the float range
                ok = False
        if ok and self.integer:
            ok = float(value).is_integer()
        if not ok:
            raise error(f"{where + ': ' if where else ''}found {_shown(value)}, expected {self.expected()}")
        return int(value) if self.integer else float(value)

    def parse(self, text: str, where: str, error: type[LinparError] = BoundsError):
        """A number typed by a user (an option, an entry): as `check`, with one message for text that is none."""
        try:
            value = int(text) if self.integer else float(text)
        except (TypeError, ValueError, OverflowError):
            if self.integer and _is_float_text(text):
                value = float(text)          # "8.0", "1e3": checked as a number, refused if not whole
            else:
                raise error(f"{where + ': ' if where else ''}found {_shown(text)}, expected {self.expected()}") \
                    from None
        return self.check(value, where, error)


def _is_float_text(text) -> bool:
    try:
        float(text)
    except (TypeError, ValueError):
        return False
    return True


def _shown(value) -> str:
    text = repr(value) if not isinstance(value, float) else f"{value:g}"
    return text if len(text) <= 40 else text[:37] + "..."


# --- the bounds ------------------------------------------------------------------------------------------------

SAMPLE_RATE = Bound("a sample rate", "Hz", 1e3, 1e6,
                    "sound cards run at 8 - 384 kHz; a rate outside is a damaged WAV header", integer=True)
PERIOD_SAMPLES = Bound("a period length", "samples", 2, 2**24,
                       "the multitone's period: 1024 - 65536 samples in the templates; 2**24 is 6 min at 48 kHz",
                       integer=True)
SD = Bound("an effective radiating area Sd", "m^2", 1e-4, 1.0,
           "1 cm^2 (a micro speaker) to 1 m^2 (an 18-inch woofer has 0.12 m^2)")
FREQUENCY = Bound("a frequency", "Hz", 0.01, 1e6,
                  "imported curves, fit ranges and the laser's band: infrasound to ultrasound")
IMPEDANCE = Bound("an impedance magnitude", "ohm", 1e-6, 1e9,
                  "a curve's |Z|: a shorted coil to an open circuit, never 0, inf or NaN")
HX = Bound("a displacement transfer magnitude", "m/V", 1e-15, 1.0,
           "an imported |X/U|: a tweeter at 20 kHz to a subwoofer's 1 m/V at DC")
PHASE_DEG = Bound("a phase", "degrees", -1e6, 1e6,
                  "a curve's phase, unwrapped or not (radians are converted first)")
CHANNEL_SCALE = Bound("a channel scale (its magnitude)", "unit per sample", 1e-30, 1e30,
                      "physical value = sample x scale; 5e-324 or 1e300 is a damaged sidecar")
LEVEL_V_RMS = Bound("a drive level", "V RMS", 1e-3, 100.0,
                    "a level at the driver's terminals: 1 mV to a PA amplifier's 100 V")
PERIODS = Bound("a number of periods", "", 2, 10_000,
                "periods averaged: 2 give a noise estimate; 10,000 of 65,536 samples are 4 hours", integer=True)
ADDED_MASS_G = Bound("an added mass", "g", 0.01, 10_000.0,
                     "added-mass curves: a few grams on a tweeter to kilograms on a woofer")
XRUN_S = Bound("an overrun", "s", 0.0, 10.0, "the rig's injected xrun: one cycle late by up to 10 s")
LIST_LIMIT = Bound("a number of measurements", "", 1, 10**9, "`archive list --limit`", integer=True)
YEAR = Bound("a year", "", 1900, 9998, "dates of measurements: a year the calendar arithmetic can take",
             integer=True)
PARAMETER = Bound("a parameter value", "SI", -1e30, 1e30,
                  "fitted and derived values as stored in an archive record: finite, not astronomical")
COVERAGE_K = Bound("a coverage factor k", "", 0.5, 10.0,
                   "`qa limits --k`: limits at mean +- k sigma of golden units; 3 is usual, 10 is no limit at all")
BASELINE = Bound("a control-chart baseline", "units", 10, 10**6,
                 "`qa stats --baseline`: the first units set the chart's limits; fewer than 10 set nothing",
                 integer=True)
LIMITS_VERSION = Bound("a limits version", "", 1, 2**31 - 1,
                       "`qa stats --limits-version`, `qa limits --show`: versions are numbered from 1", integer=True)
LASER_RANGE_M = Bound("a laser measuring range", "m", 1e-4, 10.0,
                      "the sensor's reply: 10 mm (ILD1420-10) to 500 mm; garbage otherwise")
# The large-signal identification and plan (analysis/large_signal/, docs/large-signal.md).
EXCURSION_MM = Bound("a peak excursion", "mm", 0.01, 50.0,
                     "the large-signal plan's limit: a micro speaker's tenth of a mm to a subwoofer's 50 mm")
TEMPERATURE_RISE_K = Bound("a temperature rise", "K", 0.1, 200.0,
                           "the voice coil's warming the plan allows; coils are rated to 150 - 250 C")
DISTORTION_DB = Bound("a distortion level", "dB", -80.0, 0.0,
                      "the current's distortion re the signal at which the plan stops: inaudible to all distortion")
LEVEL_STEP = Bound("a level factor", "", 1.05, 4.0, "the plan's steps: +0.4 dB to +12 dB each")
LIMIT_PERCENT = Bound("a limit's threshold", "%", 1.0, 99.0,
                      "X_Bl, X_C, X_L: the published 82 %, 75 %, 10 % and any threshold that is a fraction")
POLYNOMIAL_ORDER = Bound("a polynomial order", "", 0, 8,
                         "Bl(x), Kms(x), Le(x): beyond 8 the powers of x are too alike to tell apart", integer=True)
AUDIO_FREQUENCY = Bound("an audio frequency", "Hz", 1.0, 20000.0,
                        "a distortion prediction's sine or tones: within the band a multitone measures")

BOUNDS = (SAMPLE_RATE, PERIOD_SAMPLES, SD, FREQUENCY, IMPEDANCE, HX, PHASE_DEG, CHANNEL_SCALE, LEVEL_V_RMS,
          PERIODS, ADDED_MASS_G, XRUN_S, LIST_LIMIT, YEAR, PARAMETER, LASER_RANGE_M, EXCURSION_MM,
          TEMPERATURE_RISE_K, DISTORTION_DB, LEVEL_STEP, LIMIT_PERCENT, POLYNOMIAL_ORDER, AUDIO_FREQUENCY, COVERAGE_K,
          BASELINE, LIMITS_VERSION)


# --- file sizes ------------------------------------------------------------------------------------------------

KiB, MiB, GiB = 1024, 1024**2, 1024**3
MAX_SIZE_LIMIT = 1024 * GiB         # no file linpar reads is a terabyte; beyond, reads overflow their counts


@dataclass(frozen=True)
class SizeLimits:
    """The largest file of each kind that is read (bytes)."""

    wav: int = 2 * GiB              # a recording's samples: ~3 hours of 3 channels of float32 at 48 kHz
    sidecar: int = 10 * MiB         # a recording's NAME.json: a few kB, with the capture's counts
    # An imported curve export (text): 20 times a 1 Hz-spaced U/I/V export to 10 kHz (1 MB). An 87 MB file of
    # 3 million lines took 30 s and 2.9 GB of memory to read and fit; at the 200 MB allowed before, 6-7 GB.
    curve: int = 20 * MiB
    archive: int = 50 * MiB         # an archive's JSON files (results.json holds every fitted line)
    laser_stream: int = 2 * GiB     # a raw laser stream kept with a measurement
    config: int = 10 * MiB          # limits, thresholds, driver and calibration files

    def of(self, kind: str) -> int:
        return getattr(self, kind.replace("-", "_"))


SIZE_KINDS = ("wav", "sidecar", "curve", "archive", "laser-stream", "config")
_LIMITS: contextvars.ContextVar[SizeLimits] = contextvars.ContextVar("size_limits", default=SizeLimits())


def size_limit(kind: str) -> int:
    """The limit of a kind of file (SIZE_KINDS) in force."""
    return _LIMITS.get().of(kind)


@contextlib.contextmanager
def size_limits_set(**changes: int) -> Iterator[SizeLimits]:
    """Raise (or lower) limits for the code run inside: size_limits_set(wav=4 * GiB)."""
    token = _LIMITS.set(replace(_LIMITS.get(), **changes))
    try:
        yield _LIMITS.get()
    finally:
        _LIMITS.reset(token)


_SIZE = re.compile(r"^\s*([0-9]+(?:\.[0-9]+)?)\s*([kmgt]?)i?b?\s*$", re.IGNORECASE)
_FACTOR = {"": 1, "k": KiB, "m": MiB, "g": GiB, "t": 1024 * GiB}


def parse_size_limit(text: str) -> tuple[str, int]:
    """'wav=4G' -> ('wav', 4 GiB); BoundsError for anything else."""
    kind, _, size = str(text).partition("=")
    kind = kind.strip().lower()
    match = _SIZE.match(size)
    if kind not in SIZE_KINDS or match is None:
        raise BoundsError(f"--size-limit: found {text!r}, expected KIND=SIZE with KIND one of "
                          f"{', '.join(SIZE_KINDS)} and SIZE like 500M or 4G")
    value = int(float(match.group(1)) * _FACTOR[match.group(2).lower()])
    if not 1 <= value <= MAX_SIZE_LIMIT:
        raise BoundsError(f"--size-limit: {text!r}: expected a size from 1 byte to {describe_size(MAX_SIZE_LIMIT)}")
    return kind.replace("-", "_"), value


def describe_size(n: int) -> str:
    for unit, factor in (("GB", GiB), ("MB", MiB), ("kB", KiB)):
        if n >= factor:
            return f"{n / factor:.3g} {unit}"
    return f"{n} bytes"


def markdown_table() -> str:
    """docs/bounds.md's tables, from BOUNDS and SizeLimits."""
    rows = ["| number | from | to | unit | why |", "|---|---|---|---|---|"]
    for b in BOUNDS:
        whole = " (whole)" if b.integer else ""
        rows.append(f"| {b.what[0].upper() + b.what[1:]}{whole} | {b.low:g} | {b.high:g} | {b.unit or '-'} | "
                    f"{b.why} |")
    rows += ["", "| file | largest read by default | --size-limit KIND |", "|---|---|---|"]
    defaults = SizeLimits()
    for kind in SIZE_KINDS:
        rows.append(f"| {kind} | {describe_size(defaults.of(kind))} | {kind} |")
    return "\n".join(rows) + "\n"
