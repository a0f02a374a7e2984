"""Whether a result is physically possible for a loudspeaker, judged like validity: red, with its likely cause.

Validity (analysis.validity) asks whether the signals can be trusted; this
asks whether the numbers they gave can belong to a driver at all. A wrong
scale in the sidecar (a laser in mm declared as m, a current probe's ratio
left out), a mistyped Sd or a rewritten WAV header gives a clean fit of
impossible numbers: a 12 µg cone, an efficiency of 625,000 %. Each check
gives a red Finding (analysis.validity_findings) that names the likely cause
and the remedy; the ranges and their reasons are in docs/bounds.md.

- efficiency eta0 above ETA0_RED (yellow above ETA0_YELLOW), or below 0;
- moving mass per area Mms/Sd outside MASS_PER_AREA_RED;
- a peak excursion above EXCURSION_FACTOR x the small-signal limit of the
  level check (analysis.excursion.DEFAULT_X_LIMIT_M);
- RE far from the nominal impedance the user entered (the sidecar's
  driver.nominal_impedance_ohm) outside RE_OVER_NOMINAL_RED;
- the WAV header's rate against the rate the sidecar says the capture ran at;
- Bl seen line by line from Z and Hx pointing negative: the laser's sign.

The likely cause is chosen by what each mistake moves: a displacement scale
wrong by 1000 moves Bl by 1000 and Mms by 10^6 but leaves Qes, fs and RE;
a wrong Sd moves only what needs Sd; a current probe's ratio moves RE.
"""
from __future__ import annotations

import math
import re
from typing import Mapping

import numpy as np

from analysis.excursion import DEFAULT_X_LIMIT_M
from analysis.validity.findings import Finding, Severity

EFFICIENCY = "implausible-efficiency"
MASS_PER_AREA = "implausible-mass-per-area"
EXCURSION = "implausible-excursion"
RE_NOMINAL = "implausible-re"
SAMPLE_RATE = "sample-rate-mismatch"
LASER_SIGN = "laser-sign-inverted"

ETA0_YELLOW, ETA0_RED = 0.05, 0.10          # reference efficiency: direct radiators stay below ~5 %
MASS_PER_AREA_REAL = (0.1, 10.0)            # kg/m^2 of real drivers, micro speakers to heavy subwoofers
MASS_PER_AREA_RED = (0.01, 100.0)           # a factor 10 beyond them
MMS_LIGHTEST = 1e-6                         # kg: no loudspeaker's moving mass is below a milligram
EXCURSION_FACTOR = 100.0
RE_OVER_NOMINAL_RED = (0.3, 2.0)            # RE is 0.6-0.95 of the nominal impedance in real drivers
RATE_TOLERANCE = 0.005                      # relative: two sample rates that differ by more are two rates
MOTIONAL_OVER_RE = 2.0                      # lines where |Z| > 2 RE: the motion dominates the impedance
SIGN_INVERTED_BELOW = -0.5                  # median cos(angle of Bl per line): +1 right, -1 inverted
SIGN_MIN_LINES = 3
PEAK_MARGIN = 1.02                           # a resonance's |Z| peak stands 2 % above both ends of its run

_X_SCALE = "the displacement scale looks like mm, not m: set the displacement channel's scale in the sidecar " \
           "(mm -> m is x 0.001) and analyse again"
_SD_SCALE = "Sd looks wrong for this cone (cm^2 typed as m^2, or another driver's): enter the cone's effective " \
            "area in m^2 (cm^2 / 10,000)"
_AUDIO_RATE = re.compile(r"(\d+(?:\.\d+)?) Hz")


def _value(parameters: Mapping, name: str) -> float | None:
    p = parameters.get(name)
    v = None if p is None else p.value
    return float(v) if v is not None and math.isfinite(v) else None


def _red(channel: str, code: str, message: str, remedy: str, value: float) -> Finding:
    return Finding(channel, code, Severity.RED, message, remedy, value)


def _mass_cause(mms: float | None, per_area: float | None, x_scale: str = _X_SCALE) -> str:
    """The likely cause of an impossible mass or efficiency: the displacement's scale (`x_scale` says how to mend
    it), else Sd."""
    if mms is not None and mms < MMS_LIGHTEST:
        return x_scale
    if per_area is not None and per_area < MASS_PER_AREA_RED[0] * 1e-2:
        return x_scale
    return _SD_SCALE


def mechanical_findings(parameters: Mapping, sd_m2: float | None, peak_m: float | None,
                        x_scale: str = _X_SCALE) -> list[Finding]:
    """Efficiency, mass per area and excursion (module doc), on the displacement channel; `x_scale`: the remedy
    when the displacement's scale is the likely cause (a recording's sidecar; an imported Hx curve's unit)."""
    found: list[Finding] = []
    mms, eta0 = _value(parameters, "Mms"), _value(parameters, "eta0")
    per_area = mms / sd_m2 if mms is not None and sd_m2 else None
    if peak_m is not None and math.isfinite(peak_m) and peak_m > EXCURSION_FACTOR * DEFAULT_X_LIMIT_M:
        found.append(_red("displacement", EXCURSION,
                          f"peak excursion {peak_m * 1e3:.4g} mm: {peak_m / DEFAULT_X_LIMIT_M:.3g} times the "
                          f"small-signal limit {DEFAULT_X_LIMIT_M * 1e3:g} mm; no driver moves so far at a "
                          "measuring level", x_scale, peak_m))
    if per_area is not None and not MASS_PER_AREA_RED[0] <= per_area <= MASS_PER_AREA_RED[1]:
        found.append(_red("displacement", MASS_PER_AREA,
                          f"moving mass per area Mms/Sd {per_area:.3g} kg/m^2 (Mms {mms * 1e3:.3g} g, Sd "
                          f"{sd_m2:.4g} m^2); real drivers have {MASS_PER_AREA_REAL[0]:g} to "
                          f"{MASS_PER_AREA_REAL[1]:g} kg/m^2", _mass_cause(mms, per_area, x_scale), per_area))
    elif mms is not None and mms < MMS_LIGHTEST:
        found.append(_red("displacement", MASS_PER_AREA, f"moving mass Mms {mms * 1e6:.3g} mg: below any "
                          f"loudspeaker's ({MMS_LIGHTEST * 1e6:g} mg)", x_scale, mms))
    if eta0 is not None and (eta0 < 0 or eta0 > ETA0_YELLOW):
        severity = Severity.RED if eta0 < 0 or eta0 > ETA0_RED else Severity.YELLOW
        why = ("no driver's efficiency is negative" if eta0 < 0 else
               f"direct-radiating drivers stay below {ETA0_YELLOW * 100:g} %" + (
                   "; only a few professional woofers come near it" if severity is Severity.YELLOW else ""))
        found.append(Finding("displacement", EFFICIENCY, severity, f"reference efficiency eta0 {eta0 * 100:.4g} %: "
                             f"{why}", _mass_cause(mms, per_area, x_scale), eta0))
    return found


def re_findings(parameters: Mapping, driver: Mapping | None) -> list[Finding]:
    """RE against the nominal impedance the user entered (the sidecar's driver.nominal_impedance_ohm)."""
    nominal = (driver or {}).get("nominal_impedance_ohm")
    re_ohm = _value(parameters, "RE")
    if re_ohm is None or isinstance(nominal, bool) or not isinstance(nominal, (int, float)) or not nominal > 0:
        return []
    ratio = re_ohm / float(nominal)
    if RE_OVER_NOMINAL_RED[0] <= ratio <= RE_OVER_NOMINAL_RED[1]:
        return []
    cause = (f"the current probe's ratio is not in the sidecar (the current reads {ratio:.3g} times low): "
             "set the current channel's scale to the probe's ratio" if ratio > 1 else
             f"the current's scale looks {1 / ratio:.3g} times too large (a shunt's value, a probe's ratio): "
             "check the current channel's scale in the sidecar")
    return [_red("current", RE_NOMINAL, f"RE {re_ohm:.4g} Ω is {ratio:.3g} times the nominal impedance "
                 f"{float(nominal):g} Ω entered; real drivers have RE 0.6 to 0.95 times it", cause, ratio)]


def captured_rate(extra: Mapping | None) -> float | None:
    """The rate the sidecar says the sound card captured at (the laser's alignment, or the audio device's
    description), or None when it does not say."""
    extra = extra or {}
    alignment = extra.get("laser_alignment")
    if isinstance(alignment, Mapping):
        rate, ratio = alignment.get("laser_rate_hz"), alignment.get("ratio")
        if all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v > 0
               for v in (rate, ratio)):
            return float(rate) * float(ratio)
    measurement = extra.get("measurement")
    audio = measurement.get("audio") if isinstance(measurement, Mapping) else None
    match = _AUDIO_RATE.search(audio) if isinstance(audio, str) else None
    return float(match.group(1)) if match else None


def rate_findings(sample_rate: float, extra: Mapping | None) -> list[Finding]:
    rate = captured_rate(extra)
    if rate is None or abs(sample_rate / rate - 1) <= RATE_TOLERANCE:
        return []
    return [_red("voltage", SAMPLE_RATE, f"the WAV file says {sample_rate:g} Hz but the sidecar says the capture "
                 f"ran at {rate:g} Hz: every frequency (fs too) is {sample_rate / rate:.4g} times what it was",
                 "the WAV header was rewritten (resampled, or saved at another rate): analyse the recording as "
                 "it was written, or measure again", sample_rate / rate)]


def _resonance_lines(z_abs: np.ndarray, freqs: np.ndarray, re_ohm: float) -> np.ndarray:
    """The lines of the first run where |Z| > 2 RE (the resonance), within two octaves of its start: above
    it the voice coil's inductance lifts |Z| too, and there Ze is no longer ~ RE.

    The run must hold a peak of |Z| (it rises, then falls by PEAK_MARGIN): a driver whose resonance stays
    below 2 RE (Qms < Qes) has its first such run in the inductive rise, where Z - RE is the coil's j w Le,
    not the motion, and Bl line by line comes out negative (-w^2 Le Mms / Bl) on a right laser. No lines
    then: the sign is not judged, rather than judged wrong."""
    high = np.isfinite(z_abs) & (z_abs > MOTIONAL_OVER_RE * re_ohm)
    keep = np.zeros_like(high)
    if not high.any():
        return keep
    first = int(np.argmax(high))
    end = first
    while end < high.size and high[end] and freqs[end] <= 4 * freqs[first]:
        end += 1
    run = z_abs[first:end]
    peak = int(np.argmax(run))
    if not (0 < peak < run.size - 1 and run[peak] > PEAK_MARGIN * max(run[0], run[-1])):
        return keep
    keep[first:end] = True
    return keep


def sign_findings(spectra, re_ohm: float | None, laser_delay_s: float | None = None) -> list[Finding]:
    """The laser's sign from Z and Hx alone, whatever the model: U = Ze*I + Bl*s*X gives, line by line,

        Bl = (Z - Ze) / (s * Hx * Z)

    (docs/physics.md section 1: Hx = Bl / (s*Zm*Z), Z - Ze = Bl^2 / Zm), real and positive for a cone that moves outward
    with a positive current. Taken where the motion dominates Z (|Z| > 2 RE, around fs, Ze ~ RE there);
    pointing the other way on most of those lines: the displacement's sign is inverted. An inverted sign
    drags a fit's fs and Bl anywhere, so the fit's values are not used, only its RE and the laser's delay
    (a laser 15 ms late turns Hx by 2 pi f 15 ms, a whole turn and more around fs: that is no inverted sign)."""
    hx = spectra.displacement
    if hx is None or not hx.has_phase or re_ohm is None or not re_ohm > 0:
        return []
    z = spectra.impedance
    common, z_at, x_at = np.intersect1d(z.bins, hx.bins, return_indices=True)
    zv, xv = z.value[z_at], hx.value[x_at]
    s = 2j * np.pi * z.freqs[z_at]
    if laser_delay_s is not None and np.isfinite(laser_delay_s):
        xv = xv * np.exp(s * laser_delay_s)         # the displacement as it was, before the link delayed it
    motional = _resonance_lines(np.abs(zv), z.freqs[z_at], re_ohm) & np.isfinite(xv) & (np.abs(xv) > 0)
    if np.count_nonzero(motional) < SIGN_MIN_LINES:
        return []
    bl = (zv[motional] - re_ohm) / (s[motional] * xv[motional] * zv[motional])
    pointing = float(np.median(np.cos(np.angle(bl))))
    if pointing > SIGN_INVERTED_BELOW:
        return []
    phase = math.degrees(float(np.median(np.abs(np.angle(bl)))))
    return [_red("displacement", LASER_SIGN,
                 f"the force factor Bl seen line by line from Z and Hx points {phase:.0f}° from positive on "
                 f"{np.count_nonzero(motional)} lines around fs; a cone moves outward with a positive current",
                 "the laser's sign is inverted: flip the displacement channel's scale (or the laser's sign in the "
                 "plan) and analyse again; no effect of the model explains it", phase)]


def plausibility_findings(recording, spectra, parameters: Mapping, sd_m2: float | None,
                          peak_m: float | None) -> dict[str, list[Finding]]:
    """Every plausibility finding of a fitted result, by channel (for Validity.with_findings)."""
    found: dict[str, list[Finding]] = {}
    for finding in (*rate_findings(spectra.sample_rate, recording.extra),
                    *re_findings(parameters, recording.driver),
                    *sign_findings(spectra, _value(parameters, "RE"), _value(parameters, "tau_x")),
                    *mechanical_findings(parameters, sd_m2, peak_m)):
        found.setdefault(finding.channel, []).append(finding)
    return found
