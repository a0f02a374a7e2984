"""Whether an imported impedance curve can be a loudspeaker's at all: passive, and with a resonance.

A recording is judged by validity (analysis.validity) before its numbers are trusted; imported curves carry
none of its signals, but two things no driver can do are read off the curve itself:

- give out energy: a passive two-terminal's Re(Z) >= 0 at every frequency, its phase within +-90 degrees
  (a driver's stays within about +-60). Lines below -PASSIVE_MARGIN x |Z| in Re(Z) (phase beyond
  ~93 degrees) are no measurement of a driver. The likely cause follows from where they lie: on nearly every
  line, an impedance measured with the current the wrong way round (Z -> -Z, phases near +-180); rising
  with frequency, a delay between the voltage and the current channels not taken out (the phase falls by
  360 f tau degrees); elsewhere, a phase column in another unit than it was read in.
- have no resonance: the moving cone adds Bl^2/Zm to the coil's impedance, a peak of |Z| at fs
  (RE + RES over RE on both sides: RES/RE = Qms/Qes, above 0.2 for any driver). A curve with no peak
  standing RESONANCE_RATIO above the lower of the lowest |Z| on its left and on its right is a resistor (or
  a coil, whose |Z| only rises): fitting a driver's model to it reports an fs, a Qms that no cone gave.
  When |Z| only falls from the curve's first line, the resonance lies below it.

Each gives a red finding (analysis.validity.findings) on the impedance, with its cause and remedy; the
parameters of such a curve are withheld with the finding's words (analysis.curves.fitting).
"""
from __future__ import annotations

import dataclasses
from typing import Mapping

import numpy as np

from analysis.derived import ParameterValue
from analysis.spectra import TransferFunction
from analysis.validity.assessment import ChannelValidity
from analysis.validity.findings import Finding, Severity
from analysis.validity.result import ResultValidity

NOT_PASSIVE = "not-passive"
NO_RESONANCE = "no-resonance"
PASSIVE_MARGIN = 0.05           # Re(Z) below -5 % of |Z| (phase beyond ~93 deg): beyond a curve's rounding
MOST_LINES = 0.9                # the share of lines that says "every line" (an inverted current)
RESONANCE_RATIO = 1.2           # a driver's |Z| peak stands at least 20 % above its minimum (RES/RE > 0.2)


def _phase_falls(value: np.ndarray, bad: np.ndarray) -> bool:
    """Whether the phase falls steadily over the curve's top, from the first non-passive line: a delay's mark."""
    top = np.unwrap(np.angle(value[int(np.argmax(bad)) - 1:]))
    return top.size > 2 and top[-1] < top[0] - np.pi / 2


def _not_passive(z: TransferFunction) -> Finding | None:
    if not z.has_phase:
        return None
    value = z.value
    bad = np.isfinite(value) & (value.real < -PASSIVE_MARGIN * np.abs(value))
    n = int(np.count_nonzero(bad))
    if n == 0:
        return None
    phase = np.degrees(np.angle(value[bad]))
    worst = float(phase[np.argmax(np.abs(phase))])
    where = f"{z.freqs[bad][0]:.4g}-{z.freqs[bad][-1]:.4g} Hz"
    share = n / value.size
    if share >= MOST_LINES:
        cause = ("the current was measured the wrong way round (Z reads -Z, every phase near ±180°): swap the "
                 "current probe or the sign of the current's column, and import again")
    elif z.freqs[bad][0] > z.freqs[value.size // 2] and _phase_falls(value, bad):
        cause = ("a delay between the voltage and the current channels was not taken out (the phase falls with "
                 "frequency): remove the measuring system's latency in the tool that exported the curve")
    else:
        cause = ("the phase column may be in another unit than it was read in (--phase deg or --phase rad), or "
                 "belong to another curve: check the file's columns")
    return Finding("impedance", NOT_PASSIVE, Severity.RED,
                   f"Re(Z) < 0 on {n} of {value.size} lines ({where}; phase up to {worst:.0f}°): a loudspeaker "
                   "is passive, its phase stays within ±90°: this curve is no driver's impedance", cause, worst)


def _no_resonance(z: TransferFunction) -> Finding | None:
    magnitude = np.abs(z.value)
    ok = np.isfinite(magnitude) & (magnitude > 0)
    if np.count_nonzero(ok) < 5:
        return None
    magnitude, freqs = magnitude[ok], z.freqs[ok]
    # Each line's rise above the lower of the lowest |Z| on its left and on its right: a peak's prominence.
    left = np.minimum.accumulate(magnitude)
    right = np.minimum.accumulate(magnitude[::-1])[::-1]
    prominence = magnitude / np.maximum(left, right)
    ratio = float(np.max(prominence))
    if ratio >= RESONANCE_RATIO:
        return None
    lowest = int(np.argmin(magnitude))
    falling = float(magnitude[0] / magnitude[lowest])
    if falling >= RESONANCE_RATIO and lowest > 0:        # only falling from the first line: a peak below it
        return Finding("impedance", NO_RESONANCE, Severity.RED,
                       f"no resonance in the curve: |Z| falls from its first line ({freqs[0]:.4g} Hz, "
                       f"{magnitude[0]:.4g} Ω) to {magnitude[lowest]:.4g} Ω at {freqs[lowest]:.4g} Hz with no "
                       "peak: the resonance lies below the curve",
                       f"measure (or export) the impedance from well below fs, e.g. from {freqs[0] / 4:.2g} Hz",
                       falling)
    return Finding("impedance", NO_RESONANCE, Severity.RED,
                   f"no resonance: no peak of |Z| stands more than {(ratio - 1) * 100:.0f} % above the curve "
                   f"around it (|Z| {magnitude[lowest]:.4g} to {np.max(magnitude):.4g} Ω); a moving cone adds a "
                   f"peak of at least {(RESONANCE_RATIO - 1) * 100:.0f} %",
                   "this is a resistor (or a coil), not a driver: check that the driver, not the jig's dummy load "
                   "or a reference resistor, was measured", ratio)


def passivity_findings(impedance: TransferFunction) -> list[Finding]:
    """The red findings of an imported impedance curve that cannot be a loudspeaker's (module doc)."""
    return [f for f in (_not_passive(impedance), _no_resonance(impedance)) if f is not None]


def judged_not_a_driver(validity: ResultValidity, parameters: Mapping[str, ParameterValue], found: list[Finding]
                        ) -> tuple[ResultValidity, dict[str, ParameterValue]]:
    """The curves' validity red with `found` on the impedance, and every parameter withheld with their words:
    a resistor's fs or a non-passive curve's Qms is no driver's, and is not reported as one."""
    why = "the curve is no driver's: " + "; ".join(f.message.split(":")[0] for f in found) + " (see validity)"
    # The impedance channel has findings but no light of its own (nothing else of the curves was checked).
    validity = validity.replace(overall=Severity.RED,
                                channels={"impedance": ChannelValidity("impedance", None, tuple(found))})
    return validity, {name: dataclasses.replace(p, value=None, std=None, std_noise=None, std_model=None, reason=why)
                      for name, p in parameters.items()}
