"""Diagnosis: which physical effect does the model lack, and where is the physics missing?

From a fitted model, every candidate (add an effect of a category the model
does not have yet, or swap an effect for an alternative of its category) is
refitted, warm-started from the current fit, and ranked by how much it
lowers BIC. With honest per-line uncertainties BIC = chi^2 + k ln n, so an
extra parameter must buy a chi^2 drop of ln n (about 7) to pay for itself.

That alone is not enough far from the noise floor (at a reduced chi^2 of
10^4 any flexible effect lowers BIC by thousands), so the greedy path takes
the best-ranked candidate that passes the acceptance rule of
analysis.diagnosis.acceptance: no flag, a gain at the misfit's own scale, and no more
misfit left than a smooth correction at its site leaves. It stops when none
does, or at the step cap. Then the site localisation (analysis.diagnosis.sites) says
where the misfit that is left belongs, and the verdict says how much the
catalogue explained.
"""
from __future__ import annotations

import collections
import dataclasses
import threading
from concurrent.futures import Executor
from dataclasses import dataclass
from enum import StrEnum
from typing import Callable

from analysis.diagnosis import acceptance, determined, jobs, noise_floor, pairs, residuals
from analysis.diagnosis.acceptance import MIN_BIC_GAIN, Assessment, Flag
from analysis.diagnosis.sites import SiteResult, first_among_tied, fit_site, localise, usable_sites
from analysis.diagnosis.starts import best_starts, residual_context, same_compliance_at_fs, screen_calls
from analysis.effects import Effect, available_effects
from analysis.effects.base import Site
from analysis.fit.least_squares import FitData, FitResult, fit_model
from analysis.model.composed import Model, ModelError

MAX_STEPS = 6
# A candidate's refit gets fewer evaluations than a fit of one's choice: every candidate the path takes
# on the recordings of tests/analysis/diagnosis/test_diagnosis.py and test_new_physics.py needs at most 91 per
# parameter (the closed box), while one the data do not ask for wanders along its undetermined parameters,
# or crawls along one held at a bound, until the budget ends it without a covariance (flagged undetermined).
CANDIDATE_EVALUATIONS_PER_PARAMETER = 120
# Far from the data (reduced chi^2 above this) the current fit's parameters are bent: effects that bend
# every parameter when missing (Effect.cold_start) are also refitted from the data's own start values.
FAR_CHI2 = 100.0

__all__ = ["MIN_BIC_GAIN", "MAX_STEPS", "Action", "Candidate", "Step", "Diagnosis", "candidate_models",
           "rank_candidates", "diagnose", "explain"]


class Action(StrEnum):
    """A candidate's move: an effect of a category the model lacks added, or the model's one of its category
    replaced (str-valued: the JSON says "add" or "replace")."""

    ADD = "add"
    REPLACE = "replace"


@dataclass(frozen=True, kw_only=True)
class Candidate:
    action: Action
    effect: Effect
    replaces: Effect | None
    fit: FitResult | None        # None when the refit failed
    delta_bic: float             # BIC(candidate) - BIC(current); negative is better
    error: str | None = None
    flags: tuple[Flag, ...] = ()
    assessment: Assessment | None = None
    partner: Effect | None = None   # a second effect taken with this one (analysis.diagnosis.pairs)

    @property
    def judged(self):
        """What the acceptance rule judges: the effect, or the pair."""
        return self.effect if self.partner is None else pairs.PairedEffect(self.effect, self.partner)

    @property
    def label(self) -> str:
        """The move's effect ids: 'breakup' or 'breakup + breakup-spot'."""
        return self.effect.id if self.partner is None else f"{self.effect.id} + {self.partner.id}"

    @property
    def effects(self) -> tuple[str, ...]:
        return self.fit.model.effect_ids if self.fit else ()

    @property
    def accepted(self) -> bool:
        return self.assessment is not None and self.assessment.accepted


@dataclass(frozen=True, kw_only=True)
class Step:
    fit: FitResult
    candidates: tuple[Candidate, ...]   # ranked, best first, from this step's model
    residual: str                       # where the residual sat before choosing
    chosen: Candidate | None
    flags: tuple[Flag, ...] = ()        # of this step's model (and the step cap on the last one)
    at_noise_floor: bool = False        # nothing to find: no candidate refitted (analysis.diagnosis.noise_floor)


@dataclass(frozen=True, kw_only=True)
class Diagnosis:
    """The greedy path from a start model, its first candidates ranked and the sites of what is left
    (analysis.diagnosis.result.DiagnosisResult adds the recording's words, its text and its JSON)."""

    steps: tuple[Step, ...]
    sites: tuple[SiteResult, ...] = ()   # of the final model, best first
    step_cap_reached: bool = False

    @property
    def start(self) -> FitResult:
        return self.steps[0].fit

    @property
    def final(self) -> FitResult:
        """Where the diagnosis ends: the last model of the path, or the candidate a ranking would take."""
        last = self.steps[-1]
        return last.chosen.fit if last.chosen is not None else last.fit

    @property
    def first_candidates(self) -> tuple[Candidate, ...]:
        return self.steps[0].candidates

    @property
    def steps_taken(self) -> int:
        return sum(1 for step in self.steps if step.chosen is not None)

    @property
    def verdict(self) -> str:
        return acceptance.verdict(self.start, self.final, self.steps_taken)

    @property
    def final_flags(self) -> tuple[Flag, ...]:
        """The flags of the final model (and the step cap when the path reached it)."""
        last = self.steps[-1]
        return _model_flags(last.chosen.fit) if last.chosen is not None else last.flags


def candidate_models(model: Model, effects: tuple[Effect, ...] | None = None
                     ) -> list[tuple[Action, Effect, Effect | None, Model]]:
    """Every model one move away: add an effect of a new category, or swap one within its category.

    `effects`: what may be tried (default: the catalogue and the registered effects of the user's own).
    A move whose model cannot be composed (an effect of one's own reusing a parameter name of an effect
    in the model) is left out.
    """
    present = {e.category: e for e in model.effects}
    moves = []
    for effect in available_effects() if effects is None else effects:
        if not model.with_displacement and effect.needs_displacement:
            continue
        current = present.get(effect.category)
        try:
            if current is None:
                moves.append((Action.ADD, effect, None, model.with_effects(model.effects + (effect,))))
            elif current.id != effect.id:
                swapped = tuple(effect if e is current else e for e in model.effects)
                moves.append((Action.REPLACE, effect, current, model.with_effects(swapped)))
        except ModelError:
            continue
    return moves


def _refit(data: FitData, model: Model, start: dict, cancel) -> FitResult:
    return fit_model(data, model, start=start, cancel=cancel, per_parameter=CANDIDATE_EVALUATIONS_PER_PARAMETER)


def rank_candidates(data: FitData, current: FitResult, executor: Executor | None = None,
                    cancel: threading.Event | None = None, costs: dict[str, float] | None = None,
                    passing: Callable[[Site], None] | None = None,
                    effects: tuple[Effect, ...] | None = None) -> tuple[Candidate, ...]:
    """Every candidate refitted, warm-started from `current`, flagged and ranked by delta BIC (best first).

    Their assessment applies rules 1 and 2 of the acceptance rule; rule 3
    (the site's correction) is applied by the greedy path to those that pass.
    `costs`: what each effect's refit cost before (by effect id), to hand the costliest to the pool first.
    `passing`: told the site of each single candidate that passes rules 1 and 2 as soon as it does (on the
    pool, while other refits still run), so that rule 3's site fit can start behind them.
    `effects`: what may be tried (default: candidate_models's).
    """
    moves = candidate_models(current.model, effects)
    ctx = residual_context(data, current)
    screens, screen_owners = screen_calls(data, current, moves, ctx)
    screen_handles = jobs.submit(screens, executor, cancel)
    screened_moves = set(screen_owners)
    far = current.chi2_red > FAR_CHI2
    refit_cancel = None if executor else cancel

    def refit_calls(indices, screened: dict[int, dict]) -> tuple[list, list[int]]:
        calls, owners = [], []
        for index in indices:
            _, effect, replaced, model = moves[index]
            cost = (costs or {}).get(effect.id, 0.0)
            # The new effect starts from its guess; the rest from the current fit.
            start = screened.get(index) or {**current.values, **effect.guess(ctx)}
            if replaced is not None and effect.site is Site.COMPLIANCE:
                start = same_compliance_at_fs(current, model, start)
            calls.append((_refit, (data, model, start, refit_cancel), cost))
            owners.append(index)
            if far and effect.cold_start:
                # From the data's own start values, the effect from the best of its screened starts if it has any.
                own = {name: start[name] for name in effect.param_names} if index in screened else effect.guess(ctx)
                calls.append((_refit, (data, model, own, refit_cancel), cost))
                owners.append(index)
        return calls, owners

    # The refits that need no screen go to the pool behind the screens, the others once theirs are back.
    plain_calls, plain_owners = refit_calls([i for i in range(len(moves)) if i not in screened_moves], {})
    plain_handles = jobs.submit(plain_calls, executor, cancel)
    screened = best_starts(screen_owners, screen_handles)
    narrow_calls, narrow_owners = refit_calls(sorted(screened_moves), screened)
    narrow_handles = jobs.submit(narrow_calls, executor, cancel)
    owned = sorted(zip(plain_owners + narrow_owners, plain_handles + narrow_handles), key=lambda pair: pair[0])
    calls_left = collections.Counter(plain_owners + narrow_owners)
    outcomes: dict[int, tuple[FitResult | None, str | None]] = {}
    judged: dict[int, Candidate] = {}
    for call in jobs.as_ready([handle for _, handle in owned]):
        index, handle = owned[call]
        fit, error = handle.outcome()
        kept = outcomes.get(index)
        if kept is None or kept[0] is None or (fit is not None and fit.chi2 < kept[0].chi2):
            outcomes[index] = (fit, error)
        calls_left[index] -= 1
        if calls_left[index] == 0:
            judged[index] = _judged(data, current, moves[index], *outcomes[index])
            if passing is not None and judged[index].accepted:
                passing(judged[index].effect.site)
    candidates = [judged[index] for index in range(len(moves))]
    candidates += pairs.rank_pairs(data, current, candidates, _refit, jobs.run, executor, cancel, Candidate)
    return tuple(sorted(candidates, key=lambda c: c.delta_bic))


def _judged(data: FitData, current: FitResult, move, fit: FitResult | None, error: str | None) -> Candidate:
    """A single candidate, flagged and assessed by rules 1 and 2 (its own parameters judged determined or not
    with those of the others the data do not fix held: analysis.diagnosis.determined)."""
    action, effect, replaces, _ = move
    fit = determined.with_undetermined_held(data, fit, effect.param_names)
    flags = acceptance.candidate_flags(current, fit, effect)
    return Candidate(action=action, effect=effect, replaces=replaces, fit=fit,
                     delta_bic=(fit.bic - current.bic) if fit else float("inf"), error=error,
                     flags=flags, assessment=acceptance.assess(
                         current, fit, effect, flags, simplifying=acceptance.simplifies(current, fit, replaces)))


class _SiteFits:
    """The site corrections of one model, each fitted once, on the pool when there is one."""

    def __init__(self, data: FitData, fit: FitResult, executor: Executor | None):
        self.data, self.fit, self.executor = data, fit, executor
        self.done: dict[Site, SiteResult] = {}
        self.started: dict[Site, object] = {}    # handed to the pool, not yet waited for

    def start(self, site: Site) -> None:
        """Hand `site`'s fit to the pool now (without a pool: nothing, need() fits it)."""
        if self.executor is not None and site not in self.done and site not in self.started:
            self.started[site] = self.executor.submit(fit_site, self.data, self.fit, site)

    def need(self, sites) -> None:
        wanted = tuple(s for s in dict.fromkeys(sites) if s not in self.done)
        for site in wanted:
            self.start(site)
        for site in [s for s in self.started if s in wanted]:
            self.done[site] = self.started.pop(site).result()
        left = tuple(s for s in wanted if s not in self.done)
        if left:
            self.done.update((r.site, r) for r in localise(self.data, self.fit, self.executor, sites=left))

    def collected(self) -> dict[Site, SiteResult]:
        """Every site fitted, those started included."""
        self.need(tuple(self.started))
        return self.done


def choose(current: FitResult, ranked: tuple[Candidate, ...], sites: _SiteFits
           ) -> tuple[tuple[Candidate, ...], Candidate | None]:
    """Rule 3 for the candidates that pass rules 1 and 2; the best accepted one (None: stop)."""
    passing = [c for c in ranked if c.accepted]
    sites.need(c.effect.site for c in passing)
    judged = []
    for c in ranked:
        if c.accepted:
            site = sites.done[c.effect.site]
            c = dataclasses.replace(c, assessment=acceptance.assess(
                current, c.fit, c.judged, c.flags, site, simplifying=acceptance.simplifies(current, c.fit, c.replaces)))
        judged.append(c)
    chosen = next((c for c in judged if c.accepted), None)
    return tuple(judged), chosen


def explain(current: FitResult, candidate: Candidate) -> str:
    """Why this candidate explains (or does not explain) the residual."""
    effect = candidate.effect
    if candidate.fit is None:
        return f"{effect.id}: the refit failed ({candidate.error})"
    before = current.chi2_red_by_channel()
    after = candidate.fit.chi2_red_by_channel()
    change = ", ".join(f"{ch} {before[ch]:.3g} -> {after[ch]:.3g}" for ch in before if ch in after)
    verb = f"replacing {candidate.replaces.id} by {effect.id}" if candidate.replaces else f"adding {candidate.label}"
    title = effect.title if candidate.partner is None else f"{effect.title}, with {candidate.partner.title}"
    head = f"{verb} ({title}) changes the reduced chi^2 {change}, delta BIC {candidate.delta_bic:+.1f}."
    assessment = candidate.assessment
    if assessment is None or (not assessment.accepted and assessment.reason == acceptance.NO_GAIN
                              and candidate.delta_bic > -MIN_BIC_GAIN):
        return head + " Not enough to pay for its parameters: the data do not ask for it."
    if not assessment.accepted:
        return f"{head} Not taken: {assessment.message}."
    if candidate.partner is not None:
        return (f"{head} Together they cure what neither does alone: {effect.signature} And: "
                f"{candidate.partner.signature}")
    return f"{head} It cures: {effect.signature} Physically: {effect.physics}"


def diagnose(data: FitData, start_model: Model, executor: Executor | None = None,
             cancel: threading.Event | None = None, start_fit: FitResult | None = None,
             progress: Callable[[str], None] | None = None, max_steps: int = MAX_STEPS,
             locate: bool = True, follow: bool = True) -> Diagnosis:
    """Rank the candidates from `start_model`, follow the greedy path, then locate what is left.

    follow=False ranks the start model's candidates only (the model lab's "Diagnose"): the
    diagnosis then ends at the candidate the path would take (Diagnosis.final), nothing is
    adopted. locate=False skips the site localisation of the final model.
    """
    current = determined.with_undetermined_held(data, start_fit or fit_model(data, start_model, cancel=cancel))
    steps: list[Step] = []
    capped = False
    while True:
        sites = _SiteFits(data, current, executor)
        tried = None        # every effect
        if noise_floor.channels_at_noise(current):
            sites.need(usable_sites(current.model))
            if noise_floor.meets_noise(current, sites.done):
                idle = {e.category for e in noise_floor.idle_effects(current)}
                if not idle:
                    steps.append(Step(fit=current, candidates=(), residual=residuals.describe(current),
                                      chosen=None, flags=_model_flags(current), at_noise_floor=True))
                    break
                # At the noise floor only a simpler form of an idle effect is looked for (noise_floor rule 3).
                tried = tuple(e for e in available_effects() if e.category in idle)
        if progress:
            progress(f"trying every effect on {current.model.describe()}")
        ranked = rank_candidates(data, current, executor, cancel, costs=_refit_costs(steps), passing=sites.start,
                                 effects=tried)
        ranked, best = choose(current, ranked, sites)
        if best is None:    # the candidates rule 3 refused, tried with what acts on the channel they left
            refused = pairs.rank_pairs(data, current, ranked, _refit, jobs.run, executor, cancel, Candidate,
                                      refused=True)
            if refused:
                ranked, best = choose(current, tuple(sorted(ranked + tuple(refused), key=lambda c: c.delta_bic)),
                                      sites)
        steps.append(Step(fit=current, candidates=ranked, residual=residuals.describe(current), chosen=best,
                          flags=_model_flags(current)))
        if best is None or not follow:
            break
        current = best.fit
        if len(steps) == max_steps:   # out of steps: the last model, not ranked further
            capped = True
            cap = Flag(acceptance.STEP_CAP, f"the path stopped at its cap of {max_steps} step(s): the last model "
                                            "was not ranked further")
            sites = _SiteFits(data, current, executor)
            steps.append(Step(fit=current, candidates=(), residual=residuals.describe(current), chosen=None,
                              flags=_model_flags(current) + (cap,)))
            break
    result = Diagnosis(steps=tuple(steps), step_cap_reached=capped)
    if not locate:
        return result
    if progress:
        progress("looking for the site of the misfit left")
    final = result.final
    known = sites.collected() if final is sites.fit else None
    located = localise(data, final, executor, known=known, cancel=cancel)
    taken = {site for step in result.steps if step.chosen is not None for site in _sites_of(step.chosen)}
    return dataclasses.replace(result, sites=first_among_tied(located, taken))


def _refit_costs(steps: list[Step]) -> dict[str, float]:
    """What each effect's refit cost in the last round (its evaluations): the next round's estimate."""
    last = steps[-1].candidates if steps else ()
    return {c.effect.id: float(c.fit.nfev) for c in last if c.partner is None and c.fit is not None}


def _sites_of(candidate: Candidate) -> tuple[Site, ...]:
    return (candidate.effect.site,) + ((candidate.partner.site,) if candidate.partner is not None else ())


def _model_flags(fit: FitResult) -> tuple[Flag, ...]:
    return tuple(acceptance.parameter_flags(fit) + acceptance.noise_flags(fit))
