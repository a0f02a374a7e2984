"""The causal log creep written so that RES holds every mechanical loss at fs: how imported curves are fitted.

creep-log-causal (Knudsen and Jensen's law with its loss) puts part of the suspension's loss at fs into the
creep term, so RES, Qms and Qts then leave it out, and Kms is the modulus of a complex stiffness. What a user
means by Qms, and what a tool fitting the lossless creep-log reports, is every loss at fs; by Kms, the real
part of the stiffness there. This form is the same law (the same curves, the same fits) with the creep's
loss at fs moved into RES and its stiffness at fs made real: with k(s) = 1/c(s) the causal law's relative
stiffness and k(j ws) = a + j b,

    k'(s) = (k(s) - s b / ws) / a            CMS(s) = CMS / k'(s)

k'(j ws) = 1: at fs the suspension is CMS, with no loss; the loss the law has at fs, b / ws in units of
KMS, is a constant resistance, which RES takes (s b / ws is a constant term of Zm = KMS k'(s) / s).
Below fs the loss still grows as the causal law's does (as 1/w); only its value at fs moved. The
realistic drivers' magnitude-only exports need this (docs/identification.md): lr2 with creep-log lets
the causal creep's loss at low frequencies pass into RE (+2 to +3 %, Qes +4 to +5 %); with this law RE
and the Qs come within 1-2 %.
"""
from __future__ import annotations


import numpy as np

from analysis.effects.base import Effect, Site
from analysis.effects.creep import CATEGORY, LAMBDA, _LOG_LAW_REFERENCE, _ws

_LOG10_J = 1j * np.pi / (2.0 * np.log(10.0))


class CreepLogCausalAtFs(Effect):
    """CMS(s) = CMS / k'(s), k'(s) = (k(s) - s*b/ws) / a, k(s) = 1 / [1 - lambda*log10(s/ws)], a + j*b = k(j*ws)."""

    def response(self, s, p):
        ws = _ws(p)
        k = 1.0 / (1.0 - p["lambda"] * np.log10(s / ws))
        at_fs = 1.0 / (1.0 - p["lambda"] * _LOG10_J)
        return at_fs.real / (k - s * at_fs.imag / ws)


creep_log_causal_at_fs = CreepLogCausalAtFs(
    id="creep-log-causal-fs",
    category=CATEGORY,
    title="Logarithmic creep, causal, every loss at fs in RES",
    site=Site.COMPLIANCE,
    params=(LAMBDA,),
    physics=("The causal logarithmic creep (creep-log-causal), with the part of its loss that acts at fs counted "
             "in the mechanical resistance: Qms and Qts then say every loss at the resonance, and the compliance "
             "at fs is real, as a tool fitting the lossless log law reports them."),
    signature=("As creep-log-causal: |Hx| rising below fs, and a resistive part of Z below fs that creep-log "
               "cannot give (it then passes into RE)."),
    typical="lambda 0.05 to 0.3",
    reference=_LOG_LAW_REFERENCE,
    notes=("The same curves as creep-log-causal with RES, LCES and lambda re-expressed: not in the catalogue "
           "(the diagnosis would find the two equal), used by the fit of imported magnitude-only curves."),
)
