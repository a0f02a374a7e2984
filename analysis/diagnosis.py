"""Diagnosis: which physical effect does the model lack?

From a fitted model, every candidate (add an effect of a category the model
does not have yet, or swap an effect for an alternative of its category) is
refitted, warm-started from the current fit, and ranked by how much it
lowers BIC. With honest per-line uncertainties BIC = chi^2 + k ln n, so an
extra parameter must buy a chi^2 drop of ln n (about 7) to pay for itself:
an effect that only fits noise raises BIC.

The greedy path takes the best candidate while it lowers BIC by more than
MIN_BIC_GAIN (10: "very strong" evidence on Kass and Raftery's scale) and
stops when none does, so data with nothing missing end with nothing added.
"""
from __future__ import annotations

import threading
from concurrent.futures import Executor
from dataclasses import dataclass
from typing import Callable, Sequence

from analysis.effects import CATALOGUE, Effect
from analysis.fit import FitData, FitError, FitResult, fit_model, screen_fit
from analysis.model import Model
from analysis.startvalues import start_context
from analysis import residuals

MIN_BIC_GAIN = 10.0
MAX_STEPS = 6


@dataclass(frozen=True)
class Candidate:
    action: str                  # "add" or "replace"
    effect: Effect
    replaces: Effect | None
    fit: FitResult | None        # None when the refit failed
    delta_bic: float             # BIC(candidate) - BIC(current); negative is better
    error: str | None = None

    @property
    def effects(self) -> tuple[str, ...]:
        return self.fit.model.effect_ids if self.fit else ()


@dataclass(frozen=True)
class Step:
    fit: FitResult
    candidates: tuple[Candidate, ...]   # ranked, best first, from this step's model
    residual: str                       # where the residual sat before choosing
    chosen: Candidate | None


@dataclass(frozen=True)
class Diagnosis:
    steps: tuple[Step, ...]

    @property
    def start(self) -> FitResult:
        return self.steps[0].fit

    @property
    def final(self) -> FitResult:
        return self.steps[-1].fit

    @property
    def first_candidates(self) -> tuple[Candidate, ...]:
        return self.steps[0].candidates


def candidate_models(model: Model) -> list[tuple[str, Effect, Effect | None, Model]]:
    """Every model one move away: add an effect of a new category, or swap one within its category."""
    present = {e.category: e for e in model.effects}
    moves = []
    for effect in CATALOGUE.values():
        if not model.with_displacement and effect.site.name == "DISPLACEMENT":
            continue
        current = present.get(effect.category)
        if current is None:
            moves.append(("add", effect, None, model.with_effects(model.effects + (effect,))))
        elif current.id != effect.id:
            swapped = tuple(effect if e is current else e for e in model.effects)
            moves.append(("replace", effect, current, model.with_effects(swapped)))
    return moves


def _refit(data: FitData, model: Model, start: dict, cancel) -> FitResult:
    return fit_model(data, model, start=start, cancel=cancel)


def _run(calls, executor: Executor | None, cancel: threading.Event | None) -> list:
    """Results (fit, error) of the calls, in order, on the pool when there is one."""
    if executor is not None:
        futures = [executor.submit(fn, *args) for fn, args in calls]
        return [_outcome(f.result) for f in futures]
    return [_outcome(lambda: fn(*args), cancel) for fn, args in calls]


def _best_starts(data: FitData, current: FitResult, moves, executor, cancel) -> dict[int, dict]:
    """For effects that ask for several start points (a narrow resonance), the most promising one.

    Each start is screened by a short fit of the new effect's parameters
    alone; only the best goes on to the full refit.
    """
    ctx = start_context(data.impedance)
    calls, owners = [], []
    for index, (_, effect, _, model) in enumerate(moves):
        starts = effect.starts(ctx)
        if len(starts) > 1:
            for start in starts:
                calls.append((screen_fit, (data, model, {**current.values, **start}, set(effect.param_names))))
                owners.append(index)
    best: dict[int, tuple[float, dict]] = {}
    for index, (fit, _) in zip(owners, _run(calls, executor, cancel)):
        if fit is not None and (index not in best or fit.chi2 < best[index][0]):
            best[index] = (fit.chi2, fit.values)
    return {index: values for index, (_, values) in best.items()}


def rank_candidates(data: FitData, current: FitResult, executor: Executor | None = None,
                    cancel: threading.Event | None = None) -> tuple[Candidate, ...]:
    """Every candidate refitted, warm-started from `current`, ranked by delta BIC (best first)."""
    moves = candidate_models(current.model)
    screened = _best_starts(data, current, moves, executor, cancel)
    ctx = start_context(data.impedance)
    calls = []
    for index, (_, effect, _, model) in enumerate(moves):
        # The new effect starts from its guess; the rest from the current fit.
        start = screened.get(index) or {**current.values, **effect.guess(ctx)}
        calls.append((_refit, (data, model, start, None if executor else cancel)))
    candidates = []
    for (action, effect, replaces, _), (fit, error) in zip(moves, _run(calls, executor, cancel)):
        candidates.append(Candidate(action, effect, replaces, fit,
                                    (fit.bic - current.bic) if fit else float("inf"), error))
    return tuple(sorted(candidates, key=lambda c: c.delta_bic))


def _outcome(call, cancel: threading.Event | None = None) -> tuple[FitResult | None, str | None]:
    try:
        return call(), None
    except (FitError, ValueError, ArithmeticError) as exc:
        if cancel is not None and cancel.is_set():
            raise
        return None, str(exc)


def explain(current: FitResult, candidate: Candidate) -> str:
    """Why this candidate explains (or does not explain) the residual."""
    effect = candidate.effect
    if candidate.fit is None:
        return f"{effect.id}: the refit failed ({candidate.error})"
    before = current.chi2_red_by_channel()
    after = candidate.fit.chi2_red_by_channel()
    change = ", ".join(f"{ch} {before[ch]:.3g} -> {after[ch]:.3g}" for ch in before if ch in after)
    verb = f"replacing {candidate.replaces.id} by {effect.id}" if candidate.replaces else f"adding {effect.id}"
    head = f"{verb} ({effect.title}) changes the reduced chi^2 {change}, delta BIC {candidate.delta_bic:+.1f}."
    if candidate.delta_bic > -MIN_BIC_GAIN:
        return head + " Not enough to pay for its parameters: the data do not ask for it."
    return f"{head} It cures: {effect.signature} Physically: {effect.physics}"


def diagnose(data: FitData, start_model: Model, executor: Executor | None = None,
             cancel: threading.Event | None = None, start_fit: FitResult | None = None,
             progress: Callable[[str], None] | None = None, max_steps: int = MAX_STEPS) -> Diagnosis:
    """Rank the candidates from `start_model`, then follow the greedy path."""
    current = start_fit or fit_model(data, start_model, cancel=cancel)
    steps: list[Step] = []
    while True:
        if progress:
            progress(f"trying every effect on {current.model.describe()}")
        ranked = rank_candidates(data, current, executor, cancel)
        best = ranked[0] if ranked and ranked[0].delta_bic < -MIN_BIC_GAIN else None
        steps.append(Step(current, ranked, residuals.describe(current), best))
        if best is None:
            break
        current = best.fit
        if len(steps) == max_steps:   # out of steps: the last model, not ranked further
            steps.append(Step(current, (), residuals.describe(current), None))
            break
    return Diagnosis(tuple(steps))
