"""Lossy voice-coil inductance: the blocked impedance beyond RE + s*LE.

Eddy currents in the pole piece make the coil's inductance fall and its
resistance rise with frequency. Each model here adds a term to Ze; they are
alternatives (one category), so they may share parameter names.

The start values lean on the one number the data give about the top band:
LE_high = Im(Z)/w at the top lines, the whole inductance seen there.
"""
from __future__ import annotations

import numpy as np

from analysis.effects.base import Effect, ParamSpec, Site

CATEGORY = "inductance"

L2 = ParamSpec("L2", "H", "mH", 1e3, 0.0, 1.0, 2e-4, "para-inductance", typical=(1e-5, 1e-2))
R2 = ParamSpec("R2", "ohm", "ohm", 1.0, 0.0, 1e4, 4.0, "eddy-current loss resistance", typical=(0.1, 100.0))


def _top_angular_frequency(ctx) -> float:
    return 2.0 * np.pi * ctx.f_max


def _shunted(s, inductance: float, resistance: float):
    """s*L*R / (s*L + R), an inductance shunted by a resistance: 0 when either is 0 (no inductance, or a short),
    the limit the fraction tends to. Both bounds admit 0, and a fit at both read 0/0: NaN, and a RuntimeWarning on
    the user's terminal."""
    if inductance == 0.0 or resistance == 0.0:
        return np.zeros_like(s)
    return s * inductance * resistance / (s * inductance + resistance)


class LR2(Effect):
    """ZP(s) = s*L2*R2 / (s*L2 + R2): an inductance L2 shunted by R2 in series with LE."""

    def response(self, s, p):
        return _shunted(s, p["L2"], p["R2"])

    def guess(self, ctx):
        return {"L2": max(ctx.LE_high, 1e-6), "R2": max(ctx.RE, 0.1)}


lr2 = LR2(
    id="lr2",
    category=CATEGORY,
    title="LR-2 (L2 shunted by R2)",
    site=Site.BLOCKED,
    params=(L2, R2),
    physics=("Eddy currents in the pole piece and the magnet's iron act like a shorted secondary winding: "
             "above a few hundred hertz part of the coil's inductance is shunted by a resistance, so the "
             "inductance seems to fall and the resistance to rise with frequency."),
    signature=("Impedance residual growing with frequency above about 1 kHz: measured |Z| below a pure "
               "inductance's and the real part of Z rising; phase lower than 90 degrees at the top."),
    typical="L2 0.1 to 2 mH, R2 1 to 20 ohm (paper: L2 0.264 mH, R2 3.52 ohm)",
    reference="W. Klippel, 'Loudspeaker nonlinearities', and the LR-2 model of Klippel LPM; paper Table I",
    notes=("The reference paper's model. One corner frequency R2/(2*pi*L2): when the fall of the inductance "
           "is spread over more than a decade, try lr3 (two corners) or the power laws leach and wright."),
)


class LR3(Effect):
    """ZP(s) = s*L2*R2 / (s*L2 + R2) + s*L3*R3 / (s*L3 + R3): two shunted inductances in series with LE.

    LR-2 is the special case L3 = 0. The two stages are interchangeable in
    the formula; the start values put stage 3's corner R3/(2*pi*L3) below
    stage 2's, and the fit keeps that order in practice.
    """

    def response(self, s, p):
        return _shunted(s, p["L2"], p["R2"]) + _shunted(s, p["L3"], p["R3"])

    def guess(self, ctx):
        L = max(ctx.LE_high, 1e-6)
        R = max(ctx.RE, 0.1)
        # Stage 3 starts with a corner 4x lower than stage 2: it breaks the
        # symmetry of the two stages so the fit does not sit on the saddle between them.
        return {"L2": L, "R2": R, "L3": L, "R3": R / 4.0}


lr3 = LR3(
    id="lr3",
    category=CATEGORY,
    title="LR-3 (two LR stages: L2||R2 and L3||R3)",
    site=Site.BLOCKED,
    params=(L2, R2,
            ParamSpec("L3", "H", "mH", 1e3, 0.0, 1.0, 2e-4, "second para-inductance", typical=(1e-5, 1e-2)),
            ParamSpec("R3", "ohm", "ohm", 1.0, 0.0, 1e4, 1.0, "second eddy-current loss resistance",
                      typical=(0.05, 100.0))),
    physics=("Like LR-2, but the eddy currents are modelled by two shorted secondary windings with different "
             "corner frequencies (pole piece and front plate, or the skin depth changing with frequency): "
             "the inductance falls in two steps, which follows the slow, spread-out fall of real motors better."),
    signature=("After LR-2 is fitted, a wavy impedance residual above a few hundred hertz: the real and "
               "imaginary parts of Z alternate above and below the model around the LR-2 corner frequency."),
    typical="L2, L3 0.05 to 2 mH; R2, R3 0.5 to 30 ohm; the two corners R/(2*pi*L) a decade or so apart",
    reference="Klippel GmbH, LPM Linear Parameter Measurement, inductance models LR-2 and LR-3 (KLIPPEL R&D System manual)",
    notes=("Contains lr2 (L3 = 0). Adds two parameters: prefer it only when BIC drops. If both corners fall "
           "outside the measured band the stages cannot be told apart and the standard errors say so."),
)


class Leach(Effect):
    """ZL(s) = K * s^n, with s = jw: K*w^n*[cos(n*pi/2) + j*sin(n*pi/2)], added to RE + s*LE.

    A 'semi-inductance': for 0 < n < 1 its resistance and reactance both grow
    as w^n, in the fixed ratio cot(n*pi/2). n = 1 is an inductance, n = 0 a
    resistance. K is in ohm*s^n.
    """

    def response(self, s, p):
        return p["K"] * s ** p["n"]

    def guess(self, ctx):
        n = 0.6
        w = _top_angular_frequency(ctx)
        # Half of the reactance seen at the top lines goes to the semi-inductance.
        K = 0.5 * max(ctx.LE_high, 1e-7) * w / (w**n * np.sin(n * np.pi / 2))
        return {"K": K, "n": n}


leach = Leach(
    id="leach",
    category=CATEGORY,
    title="Leach semi-inductance K*(jw)^n",
    site=Site.BLOCKED,
    params=(ParamSpec("K", "ohm*s^n", "ohm*s^n", 1.0, 0.0, 10.0, 5e-3, "semi-inductance coefficient",
                      typical=(1e-4, 0.2)),
            ParamSpec("n", "1", "-", 1.0, 0.01, 0.99, 0.6, "exponent of the semi-inductance", typical=(0.3, 0.95))),
    physics=("Eddy currents diffuse into the iron: the deeper they reach at low frequencies, the more iron "
             "they see. The result behaves like something between a resistance and an inductance whose "
             "impedance grows as a power of frequency, with a fixed phase angle n*90 degrees."),
    signature=("Impedance residual above about 500 Hz: |Z| rises more slowly than a pure inductance's "
               "(as f^n), with a phase that stays near n*90 degrees instead of approaching 90 degrees."),
    typical="n 0.6 to 0.8; K 1e-3 to 5e-2 ohm*s^n (|K*(jw)^n| of 1 to 20 ohm at 1 kHz)",
    reference=("W. M. Leach, 'Loudspeaker voice-coil inductance losses: circuit models, parameter estimation, "
               "and effect on frequency response', JAES 50(6), 2002"),
    notes=("Here the term is added to RE + s*LE (Leach used it with or without a separate LE). n near 1 "
           "trades against LE, n near 0 against RE: a fit ending at a bound of n means the data do not "
           "support the semi-inductance. Not realisable as a finite circuit."),
)


class Wright(Effect):
    """ZL(jw) = Rw*(w/w_ref)^Er + j*Xw*(w/w_ref)^Ei, added to RE + s*LE; w_ref = 2*pi*1 kHz.

    Wright's separate power laws for the resistance and the reactance,
    written at a reference frequency: Rw and Xw are the resistance and
    reactance the term adds at 1 kHz, in ohm. Wright's own coefficients
    follow as Kr = Rw / w_ref^Er and Ki = Xw / w_ref^Ei (ohm*s^E). Written
    with Kr, Ki the fit would have to move a coefficient by decades whenever
    an exponent moves a little; at 1 kHz the four numbers are nearly
    independent. Unlike Leach's K*(jw)^n the phase is not fixed, and in
    general the model is not causal (its real and imaginary parts are not a
    Hilbert pair unless Er = Ei).
    """

    def response(self, s, p):
        w = np.abs(s) / WRIGHT_REFERENCE_RAD_S
        return p["Rw"] * w ** p["Er"] + 1j * p["Xw"] * w ** p["Ei"]

    def guess(self, ctx):
        # Half the reactance seen at 1 kHz by the one-number estimate LE_high.
        half_reactance = 0.5 * max(ctx.LE_high, 1e-7) * WRIGHT_REFERENCE_RAD_S
        return {"Rw": half_reactance, "Er": 0.7, "Xw": half_reactance, "Ei": 0.7}


WRIGHT_REFERENCE_RAD_S = 2.0 * np.pi * 1000.0

wright = Wright(
    id="wright",
    category=CATEGORY,
    title="Wright empirical model Rw*(w/w_ref)^Er + j*Xw*(w/w_ref)^Ei",
    site=Site.BLOCKED,
    params=(ParamSpec("Rw", "ohm", "ohm", 1.0, 0.0, 1e3, 1.0, "resistance the term adds at 1 kHz", typical=(0.01, 100.0)),
            ParamSpec("Er", "1", "-", 1.0, 0.01, 2.0, 0.7, "exponent of the resistance", typical=(0.2, 1.5)),
            ParamSpec("Xw", "ohm", "ohm", 1.0, 0.0, 1e3, 2.0, "reactance the term adds at 1 kHz", typical=(0.01, 100.0)),
            ParamSpec("Ei", "1", "-", 1.0, 0.01, 0.99, 0.7, "exponent of the reactance", typical=(0.2, 0.95))),
    physics=("An empirical description of the lossy coil: the resistance and the reactance added by eddy "
             "currents each grow as their own power of frequency. It fits most motors well with four "
             "numbers, but it is a curve fit, not a circuit."),
    signature=("Impedance residual above about 500 Hz where Leach's fixed phase angle does not fit: the real "
               "part of Z and the imaginary part deviate with different slopes on a log-log plot."),
    typical=("Er 0.6 to 0.9, Ei 0.6 to 0.8; Rw 0.3 to 3 ohm, Xw 1 to 10 ohm at 1 kHz "
             "(Wright's Kr 1e-3 to 1e-2, Ki 2e-3 to 2e-2 ohm*s^E)"),
    reference="J. R. Wright, 'An empirical model for loudspeaker motor impedance', JAES 38(10), 1990",
    notes=("Wright's coefficients: Kr = Rw / w_ref^Er, Ki = Xw / w_ref^Ei with w_ref = 2*pi*1000 rad/s. "
           "Here the term is added to RE + s*LE, so the reactance term is what lies beyond a constant LE; Ei near 1 "
           "trades against LE and Er near 0 against RE. Not causal in general: good for describing Z, "
           "not for a time-domain simulation."),
)
