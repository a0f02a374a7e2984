"""Physics a real driver has and the user's model may lack: how far each moves the parameters when the data ask for it.

The forms the model part exchanges (analysis.fit.model_uncertainty's ALTERNATIVES: other inductance and creep
laws) cover what the model holds in another form. They do not cover physics the model has no term for. On the
tests' real-like woofer (tests/real_like.py: a baffled piston's air load, a cone mode seen at the laser's spot,
damping rising with frequency, a diffusion law of eddy currents and a Cole-Cole creep, all at once) every
inductance and creep form agrees on Bl within 0.3 %, and Bl is 0.8 % low, Mms and Kms 1.8 %: the truth stood 3-4
reported std away. Added alone, the air load lowers the misfit 2.5 times and moves Bl, Mms and Kms most of the
way to the truth.

So each effect of EXTENSIONS the user's model lacks is added to it alone and fitted from the reported values.
It counts (`asked_for`) when it lowers the chi^2 and its own parameters end within the range a driver's usually
lie in (ParamSpec.typical) and on no bound: an effect whose corner runs off below fs, or a damping that turns
negative, imitates something else, and its parameters are not a reading of the physics it names. The shift an
effect that counts makes in each parameter is the reported value's bias in that direction; the model part
takes their rms in quadrature with the forms' spread (ModelPart.spread).

Measured (three seeds of the real-like woofer; the realistic woofer, midrange and subwoofer, two seeds each):
the truth of fs, RE, Bl, Mms and Kms within 1.5 reported std on all nine (the real-like woofer's Bl 4.3 std
before); no std above 3.7 % of its value.
"""
from __future__ import annotations

import math

from analysis.effects import Site, get_effect
from analysis.fit.least_squares import FitResult
from analysis.model.composed import Model, ModelError

# What a real driver has beside the lumped piston: the air it moves, a cone that stops being a piston, a force
# factor eddy currents take part of, damping that rises with frequency, and the laser spot's own mode.
EXTENSIONS = ("air-load", "breakup", "bl-eddy", "damping-power", "breakup-spot")


def extended_models(model: Model) -> list[Model]:
    """`model` with each effect of EXTENSIONS it lacks added alone (one that cannot join it is left out)."""
    models = []
    for effect_id in EXTENSIONS:
        effect = get_effect(effect_id)
        if effect_id in model.effect_ids or (effect.site is Site.DISPLACEMENT and not model.with_displacement):
            continue        # there already, or the laser's own effect without a laser
        try:
            models.append(Model(model.effects + (effect,), with_displacement=model.with_displacement))
        except ModelError:
            continue        # one the model cannot hold: a parameter name twice, a mass without Bl (no laser)
    return models


def asked_for(extended: FitResult, reported: FitResult) -> bool:
    """True when the added effect lowers the misfit with its own parameters where a driver's lie (module doc)."""
    if not (math.isfinite(extended.chi2) and extended.chi2 < reported.chi2):
        return False
    own = [spec for spec in extended.model.param_specs if spec.name not in reported.values]
    return all(not spec.on_bound(extended.values[spec.name]) and spec.within_typical(extended.values[spec.name])
               for spec in own)
