"""An effect added to the default model that settles on a bound far from the data: it may fit worse than none.

A fit of a model with an effect of the user's choice can end in a minimum worse than the same model
without it: an effect file's `0.001 * log(r) * sqrt(f)` vanishes at r = 1, yet the fit of the paper
driver's recording ran r to its lower bound -5 (where the logarithm turns complex), reduced chi^2
7.2e4 against 1.01 without the effect, and said "converged". The Model lab sees it by comparing versions
("the misfit rose"); `linpar analyze` has one fit only. Knowing for certain takes a second fit without the
effect on every such analysis; what the fit alone shows is the usual sign of it: a parameter of an added
effect held on its bound while the model misses the data by far more than the noise. Such an effect is
imitating something it cannot be, or stuck where it does harm, and the user should compare with the model
without it. (On its bound with the model at the noise, an effect is merely superfluous: the fit report's
notes say that already.)
"""
from __future__ import annotations

from analysis.effects import get_effect
from analysis.effects.base import Effect
from analysis.model.composed import Model
from analysis.model.defaults import DEFAULT_EFFECTS

# Far above the noise: the validity's yellow limit for a model's misfit (analysis.thresholds).
FAR_ABOVE_NOISE_CHI2 = 100.0


def added_effects(model: Model) -> tuple[Effect, ...]:
    """The model's effects of a category the default model does not have (another inductance or creep law is
    a form of what the default model holds, not an addition)."""
    base = {get_effect(effect_id).category for effect_id in DEFAULT_EFFECTS}
    return tuple(e for e in model.effects if e.category not in base)


def stuck_effect_notes(fit) -> list[str]:
    """One line per added effect with a parameter on its bound while a channel's reduced chi^2 is far above the
    noise; none when the fit is near the noise or no added effect is on a bound."""
    if fit is None:
        return []
    by_channel = fit.chi2_red_by_channel()
    worst = max(by_channel.values(), default=0.0)
    if worst <= FAR_ABOVE_NOISE_CHI2:
        return []
    notes = []
    for effect in added_effects(fit.model):
        stuck = [spec for spec in effect.params if spec.on_bound(fit.values[spec.name])]
        if not stuck:
            continue
        where = ", ".join(f"{spec.name} = {_shown(spec, fit.values[spec.name])}" for spec in stuck)
        without = ",".join(e.id for e in fit.model.effects if e is not effect) or "none"
        chi = ", ".join(f"{name} {value:.3g}" for name, value in by_channel.items())
        notes.append(f"the added effect {effect.id} ended with {where} on a bound while the model misses the data "
                     f"by far more than the noise (reduced chi^2 {chi}): it may fit worse than leaving it out; "
                     f"compare with --model {without}")
    return notes


def _shown(spec, value: float) -> str:
    unit = "" if spec.display_unit in ("-", "1") else f" {spec.display_unit}"
    return f"{value * spec.display_scale:.3g}{unit}"
