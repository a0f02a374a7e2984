"""What an effect would change on the current data: its signature, beside the misfit the current fit leaves.

The model lab's "New effect…" dialog draws it while the user writes the effect: the current model with
the new effect at its start values (the other parameters at the current fit), relative to the current
model, channel by channel; and the misfit of the current fit, measured / model - 1. An effect that can
explain the misfit changes the model where, and roughly as, the misfit lies.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.effects.base import Effect
from analysis.fit.least_squares import FitResult
from analysis.model.composed import Model


@dataclass(frozen=True, slots=True)
class ChannelSignature:
    channel: str             # "impedance" or "displacement"
    freqs: np.ndarray
    change: np.ndarray       # complex: model with the effect / model without - 1
    misfit: np.ndarray       # complex (real for a magnitude-only channel): measured / model - 1


def with_effect(model: Model, effect: Effect) -> Model:
    """The model with `effect` added, or swapped for the effect of its category (analysis.model.composed.ModelError if not)."""
    kept = tuple(e for e in model.effects if e.category != effect.category and e.id != effect.id)
    return model.with_effects(kept + (effect,))


def channel_misfit(channel) -> np.ndarray:
    """measured / model - 1 of a fitted channel: complex, or of the sizes alone for a magnitude-only channel."""
    with np.errstate(all="ignore"):
        if channel.has_phase:
            return channel.measured / channel.model - 1.0
        return np.abs(channel.measured) / np.abs(channel.model) - 1.0


def signature(fit: FitResult, effect: Effect) -> tuple[ChannelSignature, ...]:
    """Each channel of `fit` with the change `effect` makes at its start values, and the misfit left."""
    model = with_effect(fit.model, effect)
    values = {**fit.values, **{p.name: p.default for p in effect.params}}
    out = []
    for name, ch in fit.channels.items():
        s = 2j * np.pi * ch.freqs
        with np.errstate(all="ignore"):
            changed = model.impedance(s, values) if name == "impedance" else model.displacement(s, values)
            change = changed / ch.model - 1.0
        out.append(ChannelSignature(name, ch.freqs, change, channel_misfit(ch)))
    return tuple(out)
