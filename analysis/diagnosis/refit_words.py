"""What a refit in the model lab did, in words: the misfit before and after, and what went wrong.

"Refitted" alone hides two outcomes a user must act on: a refit whose
chi^2 rose (the fit ended in a poorer minimum than the version it started
from, or the new effect fights the data) and a parameter left on its
bound (the data push it further than the effect allows). Each is said
with what to try.
"""
from __future__ import annotations

import math

from analysis.diagnosis import acceptance
from analysis.fit.least_squares import FitResult

CHANNEL_SHORT = {"impedance": "Z", "displacement": "Hx"}
# chi^2 may rise by chance: by its own noise (3 sigma of a chi^2 of n points) and a few parts per million of
# itself (the optimiser's tolerance on a misfit far above the noise).
RISE_SIGMAS = 3.0
RISE_SHARE = 1e-6


def _chi2_text(chi2_red: dict[str, float]) -> str:
    return ", ".join(f"{CHANNEL_SHORT.get(k, k)} {v:.3g}" for k, v in chi2_red.items())


def chi2_rose(before: FitResult, after: FitResult) -> bool:
    """The refit's total chi^2 is above the start's by more than chance (same data, same lines)."""
    allowed = RISE_SIGMAS * math.sqrt(2.0 * max(before.n_data, 1)) + RISE_SHARE * before.chi2
    return after.chi2 - before.chi2 > allowed


def refit_sentences(before: FitResult, after: FitResult) -> list[str]:
    """The refit's outcome: the first sentence the chi^2 change, then one per problem with what to try."""
    head = (f"Refitted: reduced χ² {_chi2_text(before.chi2_red_by_channel())} → "
            f"{_chi2_text(after.chi2_red_by_channel())}.")
    out = [head]
    if chi2_rose(before, after):
        # Short sentences: with a bound's below them they fit the lab's header at 1280 px (the χ² are in the first).
        out.append("The misfit rose. Try other start values, or uncheck it (the previous version stays).")
    bound = [f for f in acceptance.parameter_flags(after, typical=False) if f.code == acceptance.AT_BOUND]
    for flag in bound:
        out.append(f"{flag.message}. Try widening that bound (your effect's file), or another form.")
    return out


def refit_text(before: FitResult, after: FitResult) -> str:
    return " ".join(refit_sentences(before, after))
