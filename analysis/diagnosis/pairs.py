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

The mode need not make Hx worse to need its partner: where the spot's own
mode sits above the coil's, `breakup` alone takes most of Z and some of Hx,
and is refused by rule 3 (the mechanical site's correction, which reshapes
Hx through Zm, removes more). When no single candidate is taken, each such
candidate (it passed rules 1 and 2, then left its site's misfit) is paired
too, with the effects acting on the channel it improved least (by the share
of its chi^2 removed) that are credible on their own: each passed rules 1
and 2 and lowered that channel's chi^2. (Pairing it with every such effect
tried 10 and 12 more refits a round on the real-like woofer, most with
partners the data had already refused.)
"""
from __future__ import annotations

import dataclasses
from concurrent.futures import Executor
import threading

from analysis.diagnosis import acceptance, determined
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


def leaves_channel(current: FitResult, candidate) -> str | None:
    """The channel a candidate refused by rule 3 improved least (the larger share of its chi^2 left), when
    it passed rules 1 and 2: its site's correction removed more, and the rest may be the other channel's own."""
    assessment = candidate.assessment
    if candidate.fit is None or assessment is None or assessment.reason != acceptance.MISFIT_LEFT:
        return None
    left = {name: candidate.fit.channels[name].chi2 / max(ch.chi2, 1e-300)
            for name, ch in current.channels.items() if name in candidate.fit.channels}
    return max(left, key=left.get) if len(left) > 1 else None


def credible_partner(current: FitResult, partner, channel: str) -> bool:
    """A partner for a candidate rule 3 refused: it passed rules 1 and 2 alone and lowered `channel`'s chi^2."""
    assessment = partner.assessment
    return assessment is not None and assessment.reason in (acceptance.ACCEPTED, acceptance.MISFIT_LEFT) \
        and channel in partner.fit.channels and partner.fit.channels[channel].chi2 < current.channels[channel].chi2


def pair_moves(current: FitResult, ranked, mend=trades_channels, eligible=None) -> list[tuple[object, object]]:
    """(first, partner) candidates to refit together: the best candidates for which `mend` names a channel
    (by default the channel-trading ones, with the channel they worsen) with every candidate that acts on
    that channel alone (whose own refit gives the partner's start) and, when given, is `eligible(partner,
    channel)`."""
    # An effect on one channel's sense (the current's, the laser's) moves the other channel only through the
    # parameters it bends: what it worsens there is no physics of the other channel to pair it with.
    firsts = [c for c in ranked if getattr(c, "partner", None) is None and mend(c) is not None
              and c.action == "add" and c.effect.site not in MENDING_SITE.values()][:MAX_FIRST]
    moves = []
    for first in firsts:
        channel = mend(first)
        site = MENDING_SITE.get(channel)
        for partner in ranked:
            if partner.fit is None or partner.effect.site is not site or partner.replaces is not None \
                    or getattr(partner, "partner", None) is not None \
                    or partner.effect.category == first.effect.category \
                    or (eligible is not None and not eligible(partner, channel)):
                continue
            moves.append((first, partner))
    return moves


def rank_pairs(data: FitData, current: FitResult, ranked, refit, run, executor: Executor | None,
               cancel: threading.Event | None, candidate_type, refused: bool = False) -> list:
    """The pairs of `pair_moves` refitted (through `refit` on `run`, as the single candidates are), flagged
    and assessed by rules 1 and 2; each is a `candidate_type` whose effect is the first and partner the second.
    refused=True: the pairs of the candidates rule 3 refused (leaves_channel), not the channel-trading ones."""
    calls, kept = [], []
    if refused:
        moves = pair_moves(current, ranked, lambda c: leaves_channel(current, c),
                           lambda partner, channel: credible_partner(current, partner, channel))
    else:
        moves = pair_moves(current, ranked)
    for first, partner in moves:
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
        fit = determined.with_undetermined_held(data, fit, both.param_names)
        flags = acceptance.candidate_flags(current, fit, both)
        pairs.append(candidate_type(action=first.action, effect=first.effect, replaces=None, fit=fit,
                                    delta_bic=(fit.bic - current.bic) if fit else float("inf"), error=error,
                                    flags=flags, assessment=acceptance.assess(current, fit, both, flags),
                                    partner=partner.effect))
    return pairs
