"""A force factor that falls with frequency: eddy currents in a shorted turn that moves with the coil.

Derivation. A conducting voice-coil former (or a shorting path that rides with the coil) is a shorted
secondary turn: resistance R_f, self-inductance L_f, mutual inductance M with the coil, and its own
force factor Bl_f in the gap's field. With the coil current i, the turn's current i_f and the velocity v:

    u = (RE + s*L)*i + s*M*i_f + Bl*v                 (the coil)
    0 = (R_f + s*L_f)*i_f + s*M*i + Bl_f*v           (the shorted turn)
    Zm*v = Bl*i + Bl_f*i_f                           (the moving assembly)

Eliminating i_f = -(s*M*i + Bl_f*v) / (R_f + s*L_f):

    u    = [RE + s*L - s^2*M^2/(R_f + s*L_f)]*i + [Bl - s*M*Bl_f/(R_f + s*L_f)]*v
    Zm'*v = [Bl - s*M*Bl_f/(R_f + s*L_f)]*i,   Zm' = Zm + Bl_f^2/(R_f + s*L_f)

The first bracket is the LR-2 model of the blocked impedance (L2 = M^2/L_f, R2 = M^2*R_f/L_f^2,
corner R_f/L_f), the last term a small damping (at most Bl_f^2/R_f, a part of Rms below the corner).
The middle bracket multiplies Bl in the back-EMF and, by reciprocity, in the force alike: the
force-factor site of docs/physics.md section 8, with

    g(s) = 1 - dBl * s*tau / (1 + s*tau),   tau = 1 / (2*pi*f_Bl),   dBl = M*Bl_f / (Bl*L_f)

Bl at low frequencies, Bl*(1 - dBl) far above f_Bl; halfway (in the log) at f_Bl/sqrt(1 - dBl).
"""
from __future__ import annotations


import numpy as np

from analysis.effects.base import Effect, ParamSpec, Site

CATEGORY = "force-factor"


class EddyForceFactor(Effect):
    """g(s) = 1 - dBl * s*tau / (1 + s*tau), tau = 1 / (2*pi*f_Bl): the factor on Bl in the force and the
    back-EMF (Z = Ze + g^2*Bl^2/Zm, Hx = g*Bl / (s*Zm*Z)); see the module docstring for the derivation."""

    def response(self, s, p):
        x = s / (2.0 * np.pi * p["f_Bl"])
        return 1.0 - p["dBl"] * x / (1.0 + x)

    def guess(self, ctx):
        # The corner of the eddy currents lies in the upper band, like LR-2's (a kHz or so): start in the
        # middle (log) between fs and the top line.
        return {"dBl": 0.05, "f_Bl": float(np.sqrt(ctx.fs * ctx.f_max))}


bl_eddy = EddyForceFactor(
    id="bl-eddy",
    category=CATEGORY,
    title="Force factor falling with frequency (eddy currents in a shorted turn)",
    site=Site.FORCE_FACTOR,
    params=(ParamSpec("dBl", "1", "%", 100.0, -0.5, 0.95, 0.05,
                      "fraction of Bl lost far above the corner", typical=(0.002, 0.4)),
            ParamSpec("f_Bl", "Hz", "Hz", 1.0, 5.0, 1e5, 1000.0, "corner frequency of the force factor's fall",
                      typical=(50.0, 3e4))),
    physics=("A conducting coil former (aluminium) or another closed path that moves with the coil is a "
             "shorted turn in the gap: the coil's current and the motion induce eddy currents in it, whose "
             "own force and flux oppose the coil's. Above the turn's corner frequency part of Bl is lost, in the "
             "force and in the back-EMF alike, while the blocked impedance shows the same turn as LR-2."),
    signature=("Displacement residual growing above about a kHz: the measured |Hx| falls below the model by a "
               "step of dBl with a phase dip around f_Bl, which no sensor low-pass explains (it levels off); the "
               "motional part of Z changes by twice the share, too small to see at those frequencies."),
    typical="dBl 1 to 20 % (aluminium formers), f_Bl 0.3 to 5 kHz, often near LR-2's corner R2/(2*pi*L2)",
    reference=("J. Vanderkooy, 'A model of loudspeaker driver impedance incorporating eddy currents in the pole "
               "structure', JAES 37(3), 1989; L. Risbo, F. T. Agerkvist, C. Tinggaard, M. Halvorsen, B. Putzeys, "
               "'Force factor modulation in electro dynamic loudspeakers', AES 141st Convention, 2016 (the L2R2 "
               "model alone does not give the force)"),
    notes=("Bl stays the low-frequency force factor, so Mms = CMES*Bl^2 and Kms keep their meaning. For a single "
           "shorted turn f_Bl equals LR-2's corner R2/(2*pi*L2); it is fitted freely because real motors have "
           "several eddy paths. The turn's own damping, at most Bl_f^2/R_f, is left to Rms. Only the laser sees "
           "this effect well: without Hx the factor g^2 on a small motional impedance above fs is hidden in Ze."),
)
