"""Where a candidate's refit starts: the current fit, the effect's guess, or the best of its screened starts.

Effects with a narrow resonance (a cone mode) ask for several start points (Effect.starts): each is
screened by a short fit of the effect's own parameters, and only the best goes on to the refit. Delays
start from the phase slope the current fit leaves; a swapped creep law from the compliance the current
fit has at fs.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from analysis.fit.least_squares import FitData, FitError, FitResult, screen_fit
from analysis.fit.startvalues import StartContext, phase_slope, start_context
from analysis.model.composed import Model
from analysis.model.lumped import resonance_frequency

SCREENS_PER_TASK = 5


def residual_context(data: FitData, current: FitResult) -> StartContext:
    """The data's start context plus what the current fit leaves: the phase slopes where delays start."""
    ctx = start_context(data.impedance)
    slopes = {}
    for name, field in (("impedance", "z_phase_slope"), ("displacement", "x_phase_slope")):
        ch = current.channels.get(name)
        if ch is not None and ch.has_phase:
            slopes[field] = phase_slope(ch.freqs, ch.measured, ch.model, ch.std)
    return dataclasses.replace(ctx, **slopes)


def _screen_starts(data: FitData, model: Model, starts: list[dict], vary: set[str]) -> FitResult | None:
    """The best of short fits of `vary` alone from each of `starts` (None when none ran)."""
    best = None
    for start in starts:
        try:
            fit = screen_fit(data, model, start, vary)
        except (FitError, ValueError, ArithmeticError):
            continue
        if best is None or fit.chi2 < best.chi2:
            best = fit
    return best


def screen_calls(data: FitData, current: FitResult, moves, ctx) -> tuple[list, list[int]]:
    """For effects that ask for several start points (a narrow resonance), the screens that pick one.

    Each start is screened by a short fit of the new effect's parameters alone; only the best goes on
    to the full refit. A few starts go to the pool as one task: one screen is a few milliseconds, about
    what handing a task to a process costs. Returns the calls and, for each, the index of its move.
    """
    calls, owners = [], []
    for index, (_, effect, _, model) in enumerate(moves):
        starts = [{**current.values, **start} for start in effect.starts(ctx)]
        if len(starts) > 1:
            for chunk in range(0, len(starts), SCREENS_PER_TASK):
                calls.append((_screen_starts, (data, model, starts[chunk:chunk + SCREENS_PER_TASK],
                                               set(effect.param_names)), 0.0))
                owners.append(index)
    return calls, owners


def best_starts(owners: list[int], handles: list) -> dict[int, dict]:
    """The screens' most promising start per move (by the move's index)."""
    best: dict[int, tuple[float, dict]] = {}
    for index, handle in zip(owners, handles):
        fit, _ = handle.outcome()
        if fit is not None and (index not in best or fit.chi2 < best[index][0]):
            best[index] = (fit.chi2, fit.values)
    return {index: values for index, (_, values) in best.items()}


def same_compliance_at_fs(current: FitResult, model: Model, start: dict) -> dict:
    """A swapped creep law starts with the compliance the current fit has at fs.

    The laws normalise LCES differently (the compliance at fs for the log laws, above the creep band for
    creep-3p and creep-zener): started from the old LCES, a law whose factor at fs is far from 1 starts
    far from the data and can crawl for thousands of evaluations into a poor minimum.
    """
    s = np.array([2j * np.pi * resonance_frequency(current.values)])
    before = abs(np.atleast_1d(current.model.motional_compliance_factor(s, current.values))[0])
    after = abs(np.atleast_1d(model.motional_compliance_factor(s, start))[0])
    if not (np.isfinite(before) and np.isfinite(after) and after > 0):
        return start
    return {**start, "LCES": start["LCES"] * before / after}
