"""Suspension creep: a compliance that grows towards low frequencies."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.effects.base import Effect, ParamSpec, Site
from analysis.model import resonance_frequency

CATEGORY = "creep"
LAMBDA = ParamSpec("lambda", "1", "-", 1.0, -0.5, 2.0, 0.05,
                   "relative change of the compliance per decade away from fs")


@dataclass(frozen=True)
class CreepLog(Effect):
    """CMS(jw) = CMS * [1 - lambda*log10(w/ws)], ws = 2*pi*fs (Knudsen and Jensen; real-valued)."""

    def response(self, s, p):
        ws = 2.0 * np.pi * resonance_frequency(p)
        return 1.0 - p["lambda"] * np.log10(np.abs(s) / ws)


creep_log = CreepLog(
    id="creep-log",
    category=CATEGORY,
    title="Logarithmic creep (Knudsen and Jensen)",
    site=Site.COMPLIANCE,
    params=(LAMBDA,),
    physics=("The surround and spider are viscoelastic: under a sustained force they keep yielding. "
             "The suspension is softer at low frequencies than at the resonance, by lambda*100 % per decade."),
    signature=("Displacement residual below fs: the measured |Hx| rises above the model towards low "
               "frequencies instead of flattening; the impedance hardly changes."),
    typical="lambda 0.05 to 0.4 (paper: 0.376)",
    reference="M. H. Knudsen, J. G. Jensen, 'Low-frequency loudspeaker models that include suspension creep', JAES 41(1/2), 1993",
)
