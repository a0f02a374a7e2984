"""When the diagnosis may add an effect: flags, the acceptance rule, and the verdict.

A raw delta-BIC threshold fails when the model is far from the data: at a
reduced chi^2 of 10^4 any flexible effect lowers chi^2 by far more than
k ln n, whatever it is. A candidate is therefore accepted only when all of
these hold (docs/diagnosis.md says why each is needed):

1. No blocking flag: none of its parameters on a bound, outside its
   typical range, or undetermined (sigma above |value|); no channel whose
   chi^2 rises by more than chance. (Another parameter newly on a bound or
   undetermined is flagged too, and said with the step, but does not block:
   an effect already in the model may have become superfluous.)
2. It pays at the misfit's own scale: with s^2 = max(1, reduced chi^2 of
   the current model), delta chi^2 / s^2 + delta k * ln n < -MIN_BIC_GAIN.
   At the noise floor this is the ordinary BIC rule; far from it, an effect
   must remove a share of the misfit, not just many sigma of it. A swap that
   simplifies (fewer parameters, for an effect with a parameter undetermined
   or on a bound) needs only to lower that BIC: the margin guards against
   adding what the data do not ask for, and here the data have already said
   the simpler effect is enough (LR-3 with R3 on its bound pays one
   parameter's ln n, about 6, for nothing; swapping it for LR-2 saves only that).
3. It explains its site's misfit: a smooth, flexible correction at the
   effect's own site (analysis.diagnosis.sites) shows how much of the misfit any
   effect there could remove. The candidate must remove most of that:

       chi^2(candidate) <= chi^2(site) + (1 - SITE_SHARE) * (chi^2(current) - chi^2(site)) + d + 3 sqrt(2 d)

   with d = max(edf(site) - k(effect), 1); near the noise floor the last
   terms are what the correction's extra freedom buys by chance. A wrong
   effect soaks up a part of the misfit, often a great many sigma, but a
   small share of what its site's correction removes; the right one takes
   nearly all of it. The share is not 1 because a site's correction also
   takes up some of the misfit of physics missing elsewhere (the electrical
   site soaks up part of a missing creep's trace in Z), which the right
   effect cannot.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from analysis.effects.base import Effect, ParamSpec
from analysis.fit.least_squares import FitResult

if TYPE_CHECKING:  # pragma: no cover
    from analysis.diagnosis.sites import SiteResult

MIN_BIC_GAIN = 10.0
NOISE_FLOOR_CHI2 = 2.0          # "explained": reduced chi^2 at or below this on every channel
NOISE_INFLATED_CHI2 = 0.5       # far below 1: the noise estimate is too large (drift between periods?)
CHANNEL_RISE_SHARE = 0.05       # a channel's chi^2 may rise by chance and by this share of itself
SITE_SHARE = 0.8                # rule 3: the share of its site's correction's gain a candidate must reach

# Flag codes (stable: the GUI and the JSON key their texts on them).
AT_BOUND = "at-bound"
ATYPICAL = "atypical"
UNDETERMINED = "undetermined"
CHANNEL_WORSE = "channel-worse"
STEP_CAP = "step-cap"
NOISE_INFLATED = "noise-inflated"

# Why a candidate was (not) accepted.
ACCEPTED = "accepted"
FLAGGED = "flagged"
NO_GAIN = "no-gain"
MISFIT_LEFT = "misfit-left"
FAILED = "failed"

CHANNEL_WORDS = {"impedance": "impedance Z", "displacement": "displacement Hx"}


@dataclass(frozen=True, slots=True)
class Flag:
    code: str
    message: str
    parameter: str | None = None
    channel: str | None = None
    # A blocking flag keeps the greedy path from taking the candidate; the others (on parameters of
    # effects already in the model) go along with the step taken and are said with it.
    blocking: bool = True

    def as_json(self) -> dict:
        return {"code": self.code, "parameter": self.parameter, "channel": self.channel, "message": self.message,
                "blocking": self.blocking}


@dataclass(frozen=True, slots=True)
class Assessment:
    """Whether the greedy path may take a candidate, and why (not)."""

    accepted: bool
    reason: str                      # ACCEPTED, FLAGGED, NO_GAIN, MISFIT_LEFT or FAILED
    scaled_delta_bic: float          # rule 2
    site_gap: float | None = None    # rule 3: the left-hand side minus the allowance (<= 0 passes)
    message: str = ""

    def as_json(self) -> dict:
        return {"accepted": self.accepted, "reason": self.reason, "scaled_delta_bic": _finite(self.scaled_delta_bic),
                "site_gap": _finite(self.site_gap), "message": self.message}


def _finite(x: float | None) -> float | None:
    return None if x is None or not math.isfinite(x) else float(x)


def _display(spec: ParamSpec, value: float) -> str:
    unit = "" if spec.display_unit in ("-", "1") else f" {spec.display_unit}"
    return f"{value * spec.display_scale:.3g}{unit}"


def parameter_flags(fit: FitResult, names: tuple[str, ...] | None = None, typical: bool = True) -> list[Flag]:
    """Flags on the fit's parameters (all of them, or `names`): on a bound, outside the typical range, undetermined."""
    flags = []
    for spec in fit.model.param_specs:
        name = spec.name
        if names is not None and name not in names:
            continue
        value = fit.values[name]
        shown = _display(spec, value)
        if spec.on_bound(value):
            side = "lower" if value - spec.min <= spec.max - value else "upper"
            flags.append(Flag(AT_BOUND, f"{name} = {shown} ended on its {side} bound: the data push it further "
                                        "than the effect allows", name))
            continue      # a parameter held on its bound has no standard error: one flag is enough
        if typical and not spec.within_typical(value):
            flags.append(Flag(ATYPICAL, f"{name} = {shown} is outside its typical range ({spec.typical_text()})",
                              name))
        sigma = fit.stderr.get(name)
        if sigma is None or not math.isfinite(sigma) or sigma > abs(value):
            what = "no standard error" if sigma is None or not math.isfinite(sigma) else \
                f"± {_display(spec, sigma)}, more than the value itself"
            flags.append(Flag(UNDETERMINED, f"{name} = {shown} is not determined by the data ({what})", name))
    return flags


def channel_flags(current: FitResult, candidate: FitResult) -> list[Flag]:
    """Channels whose chi^2 rises by more than chance (3 sigma of chi^2) and CHANNEL_RISE_SHARE of itself."""
    flags = []
    for name, after in candidate.channels.items():
        before = current.channels.get(name)
        if before is None:
            continue
        allowed = 3.0 * math.sqrt(2.0 * before.n_points) + CHANNEL_RISE_SHARE * before.chi2
        if after.chi2 - before.chi2 > allowed:
            flags.append(Flag(CHANNEL_WORSE, f"the reduced chi^2 of {CHANNEL_WORDS.get(name, name)} rises from "
                                             f"{before.chi2_red:.3g} to {after.chi2_red:.3g}: the effect trades "
                                             "one channel's misfit for the other's", channel=name))
    return flags


def candidate_flags(current: FitResult, fit: FitResult | None, effect: Effect) -> tuple[Flag, ...]:
    """The effect's own parameters and channels that get worse (blocking); any other parameter newly
    flagged (not blocking: an effect already in the model may have become superfluous, which the
    next step can mend)."""
    if fit is None:
        return ()
    own = parameter_flags(fit, effect.param_names)
    before = {(f.code, f.parameter) for f in parameter_flags(current, typical=False)}
    others = [dataclasses.replace(f, blocking=False)
              for f in parameter_flags(fit, tuple(n for n in fit.values if n not in effect.param_names),
                                       typical=False)
              if (f.code, f.parameter) not in before]
    return tuple(own + channel_flags(current, fit) + others)


def misfit_scale(fit: FitResult) -> float:
    """s^2: the reduced chi^2 when the model misses by more than the noise, else 1."""
    return max(1.0, fit.chi2_red)


def scaled_delta_bic(current: FitResult, candidate: FitResult) -> float:
    """Rule 2: delta BIC with chi^2 in units of the current misfit."""
    n = current.n_data
    return (candidate.chi2 - current.chi2) / misfit_scale(current) + \
        (candidate.n_varying - current.n_varying) * math.log(n)


def site_gap(current: FitResult, candidate: FitResult, effect: Effect, site: "SiteResult") -> float:
    """Rule 3: the chi^2 the candidate leaves above what it may (<= 0 passes)."""
    d = max(site.edf - len(effect.params), 1.0)
    allowed = site.chi2 + (1.0 - SITE_SHARE) * max(current.chi2 - site.chi2, 0.0) + d + 3.0 * math.sqrt(2.0 * d)
    return candidate.chi2 - allowed


def idle_parameters(fit: FitResult, names: tuple[str, ...] | None = None) -> list[str]:
    """The parameters (all, or `names`) undetermined or on a bound: their effect may have nothing left to do."""
    return [f.parameter for f in parameter_flags(fit, names, typical=False) if f.code in (UNDETERMINED, AT_BOUND)]


def simplifies(current: FitResult, fit: FitResult | None, replaced: Effect | None) -> bool:
    """A swap to fewer parameters, for an effect with a parameter undetermined or on a bound in `current`."""
    if fit is None or replaced is None or fit.n_varying >= current.n_varying:
        return False
    return bool(idle_parameters(current, replaced.param_names))


def assess(current: FitResult, fit: FitResult | None, effect: Effect, flags: tuple[Flag, ...],
           site: "SiteResult | None" = None, simplifying: bool = False) -> Assessment:
    """The acceptance rule for one candidate. `site`: the smooth correction at its site, None when not
    computed (then rule 3 is not applied: only candidates passing rules 1 and 2 need it). `simplifying`:
    the candidate `simplifies` the model, and rule 2 asks only that it lower the scaled BIC."""
    if fit is None:
        return Assessment(False, FAILED, math.inf, message="the refit failed")
    gain = scaled_delta_bic(current, fit)
    blocking = [f for f in flags if f.blocking]
    if blocking:
        return Assessment(False, FLAGGED, gain, message="flagged: " + "; ".join(f.message for f in blocking))
    if gain >= (0.0 if simplifying else -MIN_BIC_GAIN):
        return Assessment(False, NO_GAIN, gain, message=(
            f"it does not pay at the misfit's scale (delta BIC {gain:+.1f} with chi^2 in units of the current "
            f"reduced chi^2 {misfit_scale(current):.3g})"))
    if site is None:
        return Assessment(True, ACCEPTED, gain, message="it pays for its parameters")
    gap = site_gap(current, fit, effect, site)
    if gap > 0:
        return Assessment(False, MISFIT_LEFT, gain, gap, message=(
            f"it removes less than {100 * SITE_SHARE:.0f} % of what a smooth correction at the {effect.site.key} "
            "site removes: it absorbs part of a misfit it does not explain"))
    return Assessment(True, ACCEPTED, gain, gap, message="it pays for its parameters and explains its site's misfit")


def noise_flags(fit: FitResult) -> list[Flag]:
    """A reduced chi^2 far below 1: the noise estimate is inflated, e.g. by drift between periods."""
    return [Flag(NOISE_INFLATED, f"the reduced chi^2 of {CHANNEL_WORDS.get(name, name)} is {ch.chi2_red:.2g}, far "
                                 "below 1: the noise estimate is larger than the scatter the model leaves (drift "
                                 "between periods, e.g. a voice coil warming up, inflates it); see the drift "
                                 "finding of the validity check", channel=name)
            for name, ch in fit.channels.items() if ch.chi2_red < NOISE_INFLATED_CHI2]


def at_noise_floor(fit: FitResult) -> bool:
    return all(v <= NOISE_FLOOR_CHI2 for v in fit.chi2_red_by_channel().values())


# The four verdicts.
NOTHING_MISSING = "nothing-missing"
EXPLAINED = "explained"
PARTLY_EXPLAINED = "partly-explained"
UNEXPLAINED = "unexplained"


def verdict(start: FitResult, final: FitResult, steps_taken: int) -> str:
    if steps_taken == 0:
        return NOTHING_MISSING if at_noise_floor(start) else UNEXPLAINED
    return EXPLAINED if at_noise_floor(final) else PARTLY_EXPLAINED


def flags_json(flags) -> list[dict]:
    return [f.as_json() for f in flags]

