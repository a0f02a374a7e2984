"""Lossy voice-coil inductance: the blocked impedance beyond RE + s*LE.

Eddy currents in the pole piece make the coil's inductance fall and its
resistance rise with frequency. Each model here adds a term to Ze.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.effects.base import Effect, ParamSpec, Site

CATEGORY = "inductance"


@dataclass(frozen=True)
class LR2(Effect):
    """ZP(s) = s*L2*R2 / (s*L2 + R2): an inductance L2 shunted by R2 in series with LE."""

    def response(self, s, p):
        return s * p["L2"] * p["R2"] / (s * p["L2"] + p["R2"])

    def guess(self, ctx):
        return {"L2": max(ctx.LE_high, 1e-6), "R2": max(ctx.RE, 0.1)}


lr2 = LR2(
    id="lr2",
    category=CATEGORY,
    title="LR-2 (L2 shunted by R2)",
    site=Site.BLOCKED,
    params=(
        ParamSpec("L2", "H", "mH", 1e3, 0.0, 1.0, 2e-4, "para-inductance"),
        ParamSpec("R2", "ohm", "ohm", 1.0, 0.0, 1e4, 4.0, "eddy-current loss resistance"),
    ),
    physics=("Eddy currents in the pole piece and the magnet's iron act like a shorted secondary winding: "
             "above a few hundred hertz part of the coil's inductance is shunted by a resistance, so the "
             "inductance seems to fall and the resistance to rise with frequency."),
    signature=("Impedance residual growing with frequency above about 1 kHz: measured |Z| below a pure "
               "inductance's and the real part of Z rising; phase lower than 90 degrees at the top."),
    typical="L2 0.1 to 2 mH, R2 1 to 20 ohm (paper: L2 0.264 mH, R2 3.52 ohm)",
    reference="W. Klippel, 'Loudspeaker nonlinearities', and the LR-2 model of Klippel LPM; paper Table I",
)
