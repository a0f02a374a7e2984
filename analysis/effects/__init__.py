"""The effects catalogue: every effect the model lab can add, by id.

CATALOGUE holds the built-in effects; effects of the user's own (files, packages) are registered in
analysis.effects.registry and found by get_effect, parse_effects and available_effects beside them.
get_effect imports the module of the effect asked for only; CATALOGUE (every module) is made on first use
(analysis.effects.catalogue).
"""
from __future__ import annotations

from typing import Mapping

from analysis.effects import catalogue
from analysis.effects.base import Effect, ParamSpec, Site
from analysis.errors import LinparError
from analysis.model.defaults import DEFAULT_EFFECTS


def __getattr__(name: str):
    """CATALOGUE, made on first use (analysis.effects.catalogue)."""
    if name == "CATALOGUE":
        value = globals()["CATALOGUE"] = catalogue.CATALOGUE
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def categories() -> dict[str, list[Effect]]:
    grouped: dict[str, list[Effect]] = {}
    for effect in catalogue.CATALOGUE.values():
        grouped.setdefault(effect.category, []).append(effect)
    return grouped


class UnknownEffectError(LinparError, LookupError):
    """An effect id that is neither in the catalogue nor registered (a user's --model, an old archive's effects)."""


def available_effects() -> tuple[Effect, ...]:
    """The catalogue, then the registered effects of the user's own: what a diagnosis tries."""
    from analysis.effects import registry
    return tuple(catalogue.CATALOGUE.values()) + registry.user_effects()


def get_effect(effect_id: str, extra: Mapping[str, Effect] | None = None) -> Effect:
    """The effect of that id: from `extra` (e.g. a stored result's own user effects), the catalogue, the registry."""
    if extra and effect_id in extra:
        return extra[effect_id]
    built_in = catalogue.built_in(effect_id)        # the catalogue's, then its FORMS
    if built_in is not None:
        return built_in
    from analysis.effects import registry
    for effect in registry.user_effects():
        if effect.id == effect_id:
            return effect
    known = ", ".join(sorted(catalogue.IDS))
    users = ", ".join(e.id for e in registry.user_effects())
    raise UnknownEffectError(f"unknown effect {effect_id!r}; known effects: {known}"
                             + (f"; effects of the user's own: {users}" if users else
                                " (an effect of your own needs --effects-file FILE or a file in the user folder)"))


def parse_effects(text: str | None, extra: Mapping[str, Effect] | None = None) -> tuple[Effect, ...]:
    """'lr2,creep-log' -> the effects; '' or 'none' or 'textbook' -> none."""
    if text is None:
        return tuple(get_effect(i) for i in DEFAULT_EFFECTS)
    ids = [t.strip() for t in text.split(",") if t.strip()]
    if ids in (["none"], ["textbook"]):
        return ()
    return tuple(get_effect(i, extra) for i in ids)


__all__ = ["CATALOGUE", "DEFAULT_EFFECTS", "Effect", "ParamSpec", "Site", "UnknownEffectError", "available_effects",
           "categories",
           "get_effect", "parse_effects"]
