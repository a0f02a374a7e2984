"""A model with nothing left to find: the noise floor, where the greedy path ends without refitting.

Every candidate's refit (about 40 of them) is most of a diagnosis's time,
and on a model that already explains the measurement down to its noise it
only confirms that no effect pays for itself. The path ends there, without
them, when all three hold:

1. every channel's chi^2 is within chance of its noise: chi^2_c <= m_c +
   3 sqrt(2 m_c) for the m_c values of channel c (chi^2 with m_c degrees of
   freedom has mean m_c and standard deviation sqrt(2 m_c));
2. no site's smooth correction (analysis.diagnosis.sites) removes more than
   its own flexibility takes from noise alone: fitting pure noise with edf
   effective parameters lowers chi^2 by about edf, standard deviation
   sqrt(2 edf), so a drop above edf + 3 sqrt(2 edf) is structure;
3. no effect of the model has a parameter undetermined or on a bound. Such
   a parameter says the effect has become superfluous (LR-3's second stage
   once a creep law explains what it had bent towards), which the path
   mends by swapping it for a simpler one of its category (LR-3 for LR-2):
   at the noise floor that swap pays by the parameters it saves. Rules 1
   and 2 holding, the path then ranks those swaps only (an addition is not
   looked for at the noise floor, as above): 3 refits, not 40.

The sites' corrections are the ones the diagnosis reports at its end, so
the check costs nothing a diagnosis did not already compute. What it gives
up: an effect whose whole gain is within the chi^2's scatter (rule 1) and
that no site's correction sees above its own chance drop (rule 2). The
acceptance rule would take such an effect when its chi^2 drop exceeds
MIN_BIC_GAIN + k ln n (about 20 to 40): effects that small are not looked
for on a model already at its noise floor, and the words say so.
"""
from __future__ import annotations

from analysis.diagnosis import acceptance
from analysis.diagnosis.chance import CHANCE_SIGMAS, within_chance  # noqa: F401 (the tests use them here)
from analysis.diagnosis.sites import SiteResult
from analysis.effects.base import Effect
from analysis.fit.least_squares import FitResult


SKIPPED_WORDS = ("No candidate was refitted: the model meets the noise on every channel and no site's smooth "
                 "correction removes more than noise would, so no effect, of the catalogue or of your own, has "
                 "anything to explain (one whose whole effect is within the noise is not looked for).")
# The same, said of a path that took steps before it met the noise: what it took did the explaining.
ENDED_WORDS = ("The path ended there without refitting the candidates again: the model meets the noise on every "
               "channel and no site's smooth correction removes more than noise would, so nothing is left to "
               "explain (an effect whose whole effect is within the noise is not looked for).")


def channels_at_noise(fit: FitResult) -> bool:
    """Rule 1: every channel's chi^2 within chance of its number of values."""
    return all(within_chance(ch.chi2, ch.n_points) for ch in fit.channels.values())


def nothing_to_find(fit: FitResult, sites: dict) -> bool:
    """Rules 1 to 3: the model meets the noise, no site's correction removes more than noise would, and no
    effect of the model looks superfluous."""
    return meets_noise(fit, sites) and not idle_effects(fit)


def meets_noise(fit: FitResult, sites: dict) -> bool:
    """Rules 1 and 2: the model meets the noise, and no site's correction (`sites`, by site: all the usable
    sites' results for `fit`) removes more than noise would."""
    return channels_at_noise(fit) and all(_noise_only(fit, s) for s in sites.values())


def superfluous_parameters(fit: FitResult) -> list[str]:
    """The parameters undetermined or on a bound (their effect may have nothing left to do)."""
    return acceptance.idle_parameters(fit)


def idle_effects(fit: FitResult) -> tuple[Effect, ...]:
    """Rule 3: the model's effects with a superfluous parameter (a lumped parameter's has no simpler form)."""
    idle = set(superfluous_parameters(fit))
    return tuple(e for e in fit.model.effects if idle & set(e.param_names))


def _noise_only(fit: FitResult, site: SiteResult) -> bool:
    return within_chance(fit.chi2 - site.chi2, site.edf)
