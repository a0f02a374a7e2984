"""Effects tried in pairs: one that cures a channel but worsens the other, with one acting on the other.

A cone mode seen in the impedance and at the laser's spot is two effects:
`breakup` takes the mode out of Z, but the spot on the outer cone sees more
than the coil, so Hx gets worse and the candidate is refused (its channel
flag); `breakup-spot` alone takes part of Hx and leaves Z. Neither passes
alone; together they explain both channels.

So when a candidate lowers the misfit of one channel and raises the
other's (its only blocking flag is that rise), it is refitted with each
effect that acts on the worsened channel alone: the displacement site's
effects for Hx (breakup-spot, a laser's delay or low-pass), the current
site's for Z. A pair is judged by the same acceptance rule as a single
effect (analysis.diagnosis.acceptance): flags on both effects' parameters,
no channel worse, a gain at the misfit's scale for both effects'
parameters, and most of what the first effect's site's correction removes.
"""
from __future__ import annotations

import dataclasses
from concurrent.futures import Executor
import threading

from analysis.diagnosis import acceptance
from analysis.effects.base import Effect, Site
from analysis.fit.least_squares import FitData, FitResult
from analysis.model.composed import ModelError

# A channel's own effects: what can mend a channel the first effect made worse without touching the other.
MENDING_SITE = {"displacement": Site.DISPLACEMENT, "impedance": Site.CURRENT}
# Only the few candidates that gain most are paired: each pair is a full refit.
MAX_FIRST = 3


@dataclasses.dataclass(frozen=True)
class PairedEffect:
    """Two effects taken as one move: what the acceptance rule sees (its site is the first effect's)."""

    first: Effect
    second: Effect

    @property
    def site(self) -> Site:
        return self.first.site

    @property
    def params(self) -> tuple:
        return self.first.params + self.second.params

    @property
    def param_names(self) -> tuple[str, ...]:
        return self.first.param_names + self.second.param_names


def trades_channels(candidate) -> str | None:
    """The channel a candidate makes worse when that rise is its only blocking flag and it gains overall."""
    if candidate.fit is None:
        return None
    blocking = [f for f in candidate.flags if f.blocking]
    worse = {f.channel for f in blocking if f.code == acceptance.CHANNEL_WORSE}
    if len(worse) != 1 or len(blocking) != 1 or candidate.delta_bic >= -acceptance.MIN_BIC_GAIN:
        return None
    return worse.pop()


def pair_moves(current: FitResult, ranked) -> list[tuple[object, object]]:
    """(first, partner) candidates to refit together: the best channel-trading candidates with every
    candidate that acts on the channel they worsen (whose own refit gives the partner's start)."""
    # An effect on one channel's sense (the current's, the laser's) moves the other channel only through the
    # parameters it bends: what it worsens there is no physics of the other channel to pair it with.
    firsts = [c for c in ranked if trades_channels(c) is not None and c.action == "add"
              and c.effect.site not in MENDING_SITE.values()][:MAX_FIRST]
    moves = []
    for first in firsts:
        site = MENDING_SITE.get(trades_channels(first))
        for partner in ranked:
            if partner.fit is None or partner.effect.site is not site or partner.replaces is not None \
                    or partner.effect.category == first.effect.category:
                continue
            moves.append((first, partner))
    return moves


def rank_pairs(data: FitData, current: FitResult, ranked, refit, run, executor: Executor | None,
               cancel: threading.Event | None, candidate_type) -> list:
    """The pairs of `pair_moves` refitted (through `refit` on `run`, as the single candidates are), flagged
    and assessed by rules 1 and 2; each is a `candidate_type` whose effect is the first and partner the second."""
    calls, kept = [], []
    for first, partner in pair_moves(current, ranked):
        try:
            model = first.fit.model.with_effects(first.fit.model.effects + (partner.effect,))
        except ModelError:
            continue
        start = {**first.fit.values, **{n: partner.fit.values[n] for n in partner.effect.param_names}}
        calls.append((refit, (data, model, start, None if executor else cancel)))
        kept.append((first, partner))
    pairs = []
    for (first, partner), (fit, error) in zip(kept, run(calls, executor, cancel)):
        both = PairedEffect(first.effect, partner.effect)
        flags = acceptance.candidate_flags(current, fit, both)
        pairs.append(candidate_type(action=first.action, effect=first.effect, replaces=None, fit=fit,
                                    delta_bic=(fit.bic - current.bic) if fit else float("inf"), error=error,
                                    flags=flags, assessment=acceptance.assess(current, fit, both, flags),
                                    partner=partner.effect))
    return pairs
