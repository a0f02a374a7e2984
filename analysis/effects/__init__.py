"""The effects catalogue: every effect the model lab can add, by id."""
from __future__ import annotations

from analysis.effects.base import Effect, ParamSpec, Site
from analysis.effects import breakup, channels, creep, inductance
from analysis.errors import LinparError

# Grouped by category; within a category the effects are alternatives (one per model).
_ALL: tuple[Effect, ...] = (
    inductance.lr2,
    inductance.lr3,
    inductance.leach,
    inductance.wright,
    creep.creep_log,
    creep.creep_log_causal,
    creep.creep_3p,
    creep.creep_fractional,
    creep.creep_rs,
    channels.delay_current,
    channels.lowpass_current,
    channels.delay_x,
    channels.lowpass_x,
    channels.lowpass2_x,
    breakup.breakup,
    breakup.breakup_spot,
)

CATALOGUE: dict[str, Effect] = {e.id: e for e in _ALL}
DEFAULT_EFFECTS = ("lr2", "creep-log")


def categories() -> dict[str, list[Effect]]:
    grouped: dict[str, list[Effect]] = {}
    for effect in CATALOGUE.values():
        grouped.setdefault(effect.category, []).append(effect)
    return grouped


class UnknownEffectError(LinparError, LookupError):
    """An effect id that is not in the catalogue (a user's --model, an old archive's effects)."""


def get_effect(effect_id: str) -> Effect:
    effect = CATALOGUE.get(effect_id)
    if effect is None:
        known = ", ".join(sorted(CATALOGUE))
        raise UnknownEffectError(f"unknown effect {effect_id!r}; known effects: {known}")
    return effect


def parse_effects(text: str | None) -> tuple[Effect, ...]:
    """'lr2,creep-log' -> the effects; '' or 'none' or 'textbook' -> none."""
    if text is None:
        return tuple(get_effect(i) for i in DEFAULT_EFFECTS)
    ids = [t.strip() for t in text.split(",") if t.strip()]
    if ids in (["none"], ["textbook"]):
        return ()
    return tuple(get_effect(i) for i in ids)


__all__ = ["CATALOGUE", "DEFAULT_EFFECTS", "Effect", "ParamSpec", "Site", "UnknownEffectError", "categories",
           "get_effect", "parse_effects"]
