"""What the measurement chain adds: the current channel and the displacement sensor.

These effects are not the driver: they describe how the measured Z = U/I and
Hx = X/U differ from the driver's own. A channel factor multiplies the
transfer function it distorts, so the driver's parameters stay clean.

Sign convention for delays: a positive tau means that channel lags the
voltage channel (its samples arrive tau later than they should).
"""
from __future__ import annotations


import numpy as np

from analysis.effects.base import Effect, ParamSpec, Site

CURRENT_CATEGORY = "electrical-channel"
DISPLACEMENT_CATEGORY = "displacement-sensor"

# Up to 1 GHz: a sensor the recording does not low-pass must be able to leave the model. At 1 MHz, the bound before,
# the low-pass still turned Hx's phase 0.6 degrees at 10 kHz, and a fit ended there with chi^2 40-100 times the noise.
FC_X = ParamSpec("fc_x", "Hz", "Hz", 1.0, 10.0, 1e9, 5e3, "corner frequency of the displacement sensor",
                 typical=(200.0, 1e5))

_CURRENT_GAIN_NOTE = (
    "A gain error g of the current sense (I_measured = g*I) is NOT identifiable and is deliberately not an "
    "effect: Z/g is exactly the model with RE, LE, the inductance parameters, LCES and RES divided by g and "
    "CMES multiplied by g, and Hx = X/U, which does not involve the current, is unchanged by that scaling "
    "(ZR/(ZR + Ze) only depends on ratios of impedances). Bl comes out right, but Mms = CMES*Bl^2, "
    "Cms = LCES/Bl^2 and Rms = Bl^2/RES come out wrong by the factor g. Calibrate the current sense instead "
    "(a known resistor in place of the driver).")


def _clipped(value: float, spec: ParamSpec) -> float:
    return float(min(max(value, spec.min), spec.max))


class CurrentDelay(Effect):
    """Z_measured(s) = Z(s) * exp(s*tau_i).

    The current channel lags the voltage channel by tau_i: I_measured(t) =
    I(t - tau_i), so I_measured(s) = I(s)*exp(-s*tau_i) and U/I_measured =
    Z*exp(+s*tau_i). |factor| = 1; the phase error is w*tau_i.
    """

    def response(self, s, p):
        return np.exp(s * p["tau_i"])

    def guess(self, ctx):
        # Z_measured / Z = exp(j*w*tau_i): the slope of the phase the current model leaves over.
        return {"tau_i": _clipped(ctx.z_phase_slope, self.params[0])}


delay_current = CurrentDelay(
    id="delay-current",
    category=CURRENT_CATEGORY,
    title="Delay of the current channel",
    site=Site.CURRENT,
    params=(ParamSpec("tau_i", "s", "us", 1e6, -1e-3, 1e-3, 0.0,
                      "delay of the current channel after the voltage channel", typical=(-2e-4, 2e-4)),),
    physics=("The voltage and current are sampled through different paths (sense amplifier, converter "
             "channels, their filters): when one path is slower, the measured current is a delayed copy of the "
             "true one. That rotates the phase of Z in proportion to frequency without changing |Z|."),
    signature=("Impedance residual mainly in the imaginary part, growing linearly with frequency (phase error "
               "w*tau_i, positive when the current lags), while |Z| fits; worst at the top of the band."),
    typical="|tau_i| 0 to 50 us (a sample at 48 kHz is 20.8 us)",
    reference=("R. Pintelon, J. Schoukens, 'System Identification: A Frequency Domain Approach', 2nd ed., "
               "Wiley-IEEE Press, 2012 (delays and calibration of the measurement channels)"),
    notes=("The fit starts from the slope of the phase that the current model leaves in Z over the top "
           "octave (analysis.fit.startvalues.phase_slope): a start of 0 can end in a local minimum when the "
           "model is far from the data (a hidden -50 us did, at -7 us, with a reduced chi^2 of 3e8 to "
           "start from), and far from the data the diagnosis also refits it from the data's own start values "
           "(the bent fit's other parameters can hold it in a local minimum even when it starts at the true "
           "delay). " + _CURRENT_GAIN_NOTE),
    cold_start=True,
)


class CurrentLowPass(Effect):
    """Z_measured(s) = Z(s) * (1 + s/wc),  wc = 2*pi*fc_i.

    The current sense (shunt amplifier, its anti-alias filter) rolls off
    before the voltage sense: I_measured = I / (1 + s/wc), so U/I_measured =
    Z*(1 + s/wc). Well below fc_i it looks like a delay of 1/wc; near fc_i
    |Z| rises too, which a delay cannot do.
    """

    def response(self, s, p):
        return 1.0 + s / (2.0 * np.pi * p["fc_i"])

    def guess(self, ctx):
        return {"fc_i": max(4.0 * ctx.f_max, 1e3)}


lowpass_current = CurrentLowPass(
    id="lowpass-current",
    category=CURRENT_CATEGORY,
    title="Bandwidth of the current sense (first-order low-pass)",
    site=Site.CURRENT,
    params=(ParamSpec("fc_i", "Hz", "kHz", 1e-3, 100.0, 1e7, 50e3,
                      "corner frequency of the current channel relative to the voltage channel",
                      typical=(1e3, 5e6)),),
    physics=("The current is sensed by a small shunt and an amplifier whose bandwidth, or an extra filter, "
             "is lower than the voltage path's: the measured current falls and lags at the top of the band, "
             "so the measured |Z| rises and its phase leads."),
    signature=("Impedance residual growing with frequency in the phase (like a delay) and, near the corner, "
               "in |Z| too: measured |Z| above the model at the top lines."),
    typical="fc_i 20 kHz to 1 MHz for a good sense amplifier; a few kHz for a slow one",
    reference="Any first-order amplifier response; AES2-2012 on measuring the impedance of drivers",
    notes=_CURRENT_GAIN_NOTE,
)


class DisplacementDelay(Effect):
    """Hx_measured(s) = Hx(s) * exp(-s*tau_x).

    The displacement lags the voltage by tau_x (sensor latency, or an
    alignment left over after the laser's stream was matched to the audio).
    """

    def response(self, s, p):
        return np.exp(-s * p["tau_x"])

    def guess(self, ctx):
        # Hx_measured / Hx = exp(-j*w*tau_x): minus the slope of the phase left over.
        return {"tau_x": _clipped(-ctx.x_phase_slope, self.params[0])}


delay_x = DisplacementDelay(
    id="delay-x",
    category=DISPLACEMENT_CATEGORY,
    title="Delay of the displacement channel",
    site=Site.DISPLACEMENT,
    # Bounds: a serial laser's USB link leaves up to tens of ms (analysis/laser_delay.py searches as far).
    params=(ParamSpec("tau_x", "s", "us", 1e6, -10e-3, 40e-3, 0.0,
                      "delay of the displacement channel after the voltage channel", typical=(0.0, 2e-3)),),
    physics=("A triangulation laser computes each distance from a camera exposure, so its output comes a "
             "little late; a laser on its own clock is also aligned to the audio only to within some residual. "
             "Either way the measured displacement is a delayed copy of the true one."),
    signature=("Displacement residual in the phase of Hx only, a phase lag growing linearly with frequency "
               "(w*tau_x), while |Hx| fits; the impedance is unaffected."),
    typical=("0 to 1 ms (sensor latency of a few measuring periods; ILD1420 at 4 kHz: 0.25 ms each); "
             "1 to 25 ms through a USB serial adapter (its packets and latency timer)"),
    reference="Micro-Epsilon optoNCDT 1420 manual (measuring rate and output latency); docs/laser-protocol.md",
    notes=("Below a low-pass's corner frequency a delay and a first-order low-pass look alike (a phase lag "
           "proportional to f): lowpass-x is the alternative when |Hx| also drops at the top. The fit "
           "starts from the slope of the phase that the current model leaves in Hx over the top octave "
           "(unwrapped from the lowest line up), so delays are found as long as the phase moves less than "
           "half a turn from one line to the next; far from the data the diagnosis also refits it from the "
           "data's own start values. A measurement with a serial laser starts it from a search over the "
           "whole range (analysis/laser_delay.py)."),
    cold_start=True,
)


class DisplacementLowPass(Effect):
    """Hx_measured(s) = Hx(s) / (1 + s/wc), wc = 2*pi*fc_x: a first-order low-pass.

    1 at DC, 1/sqrt(2) (-3 dB, -45 degrees) at fc_x.
    """

    def response(self, s, p):
        return 1.0 / (1.0 + s / (2.0 * np.pi * p["fc_x"]))

    def guess(self, ctx):
        # A corner at the top line: visible enough for the fit to move it either way.
        return {"fc_x": ctx.f_max}


lowpass_x = DisplacementLowPass(
    id="lowpass-x",
    category=DISPLACEMENT_CATEGORY,
    title="Displacement sensor bandwidth (first-order low-pass)",
    site=Site.DISPLACEMENT,
    params=(FC_X,),
    physics=("The displacement sensor averages over its exposure time and filters its output, so it cannot "
             "follow fast motion: its response falls above a corner frequency, like an RC filter."),
    signature=("Displacement residual at the top of the band: the measured |Hx| falls below the model and "
               "its phase lags, by 45 degrees at fc_x; the impedance is unaffected."),
    typical="fc_x 1 to 20 kHz (a 4 kHz measuring rate gives about 1 to 2 kHz)",
    reference="Micro-Epsilon optoNCDT 1420 manual (measuring rate, averaging); docs/laser-protocol.md",
    notes=("When fc_x lies far above the band the fit only sees the phase lag w/wc and fc_x trades against a "
           "delay (see delay-x); its standard error is then large, rightly."),
)


class DisplacementLowPass2(Effect):
    """Hx_measured(s) = Hx(s) / (1 + s/(Q_x*wc) + (s/wc)^2), wc = 2*pi*fc_x: a second-order low-pass.

    1 at DC; at fc_x the magnitude is Q_x and the phase -90 degrees
    (Q_x = 1/sqrt(2): Butterworth, -3 dB at fc_x).
    """

    def response(self, s, p):
        x = s / (2.0 * np.pi * p["fc_x"])
        return 1.0 / (1.0 + x / p["Q_x"] + x * x)

    def guess(self, ctx):
        return {"fc_x": ctx.f_max, "Q_x": 1.0 / np.sqrt(2.0)}


lowpass2_x = DisplacementLowPass2(
    id="lowpass2-x",
    category=DISPLACEMENT_CATEGORY,
    title="Displacement sensor bandwidth (second-order low-pass)",
    site=Site.DISPLACEMENT,
    params=(FC_X, ParamSpec("Q_x", "1", "-", 1.0, 0.1, 20.0, 1.0 / np.sqrt(2.0),
                            "quality factor of the sensor's low-pass", typical=(0.3, 3.0))),
    physics=("A sensor whose output filter (or a velocity probe's mechanics) is second order: flat, then "
             "falling twice as steeply as an RC filter, possibly with a small peak before the fall."),
    signature=("Like lowpass-x but the top-band |Hx| falls as 1/f^2 and the phase lag reaches 90 degrees at "
               "fc_x; a peak in |Hx| just below fc_x when Q_x > 0.7."),
    typical="fc_x 1 to 20 kHz, Q_x 0.5 to 1",
    reference="Any text on analogue filters; sensor manual for the output filter",
    notes="Two parameters: prefer it to lowpass-x only when BIC drops.",
)
