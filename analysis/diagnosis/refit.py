"""A refit the model lab's checkboxes ask for: from the version it changes and from the model's own start.

The version the user changes has its values bent to make up for the physics it lacks (on a recording with
an eddy-current Bl, lr2,creep-log ends with Bl, Mms and LE far from the truth). Started from those alone, with
the new effect's parameters fitted first against them, ticking bl-eddy ended at a reduced chi^2 of 1.7e5 where
`linpar analyze --model lr2,creep-log,bl-eddy` reaches 1.01; ticking breakup on a cone mode's recording ended
above the version it started from. So a refit starts as the diagnosis's candidates do (the version's values,
each new effect from its guess on what that version leaves, a swapped creep law at the same compliance at fs)
and, unless that already meets the noise, also from the model's own start values, as `linpar analyze --model`
does; the lower chi^2 is kept.
"""
from __future__ import annotations

import math
import threading

from analysis.diagnosis.noise_floor import channels_at_noise
from analysis.diagnosis.starts import residual_context, same_compliance_at_fs
from analysis.effects.base import Site
from analysis.fit.least_squares import FitData, FitError, FitResult, fit_model
from analysis.model.composed import Model


def warm_start(data: FitData, model: Model, current: FitResult) -> dict[str, float]:
    """`current`'s values, each effect `model` adds (or swaps in) from its guess on what `current` leaves."""
    ctx = residual_context(data, current)
    had = {e.id for e in current.model.effects}
    categories = {e.category for e in current.model.effects}
    start = dict(current.values)
    swapped_compliance = False
    for effect in model.effects:
        if effect.id not in had:
            start.update(effect.guess(ctx))
            swapped_compliance |= effect.site is Site.COMPLIANCE and effect.category in categories
    if swapped_compliance:
        start = same_compliance_at_fs(current, model, start)
    return start


def refit(data: FitData, model: Model, current: FitResult, cancel: threading.Event | None = None) -> FitResult:
    """`model` fitted to `data` from `current`'s values (warm_start) and, unless that meets the noise on every
    channel, from the model's own start values; the fit with the lower chi^2. A start whose fit fails is passed
    over; when both fail, the first's error is raised. A cancelled fit raises FitCancelled."""
    fits, errors = [], []
    for start in (warm_start(data, model, current), None):
        if fits and channels_at_noise(fits[0]):
            break           # nothing left for another start to find
        try:
            fits.append(fit_model(data, model, start=start, cancel=cancel))
        except (FitError, ValueError, ArithmeticError) as exc:
            if cancel is not None and cancel.is_set():
                raise
            errors.append(exc)
    if not fits:
        raise errors[0]
    return min(fits, key=lambda fit: fit.chi2 if math.isfinite(fit.chi2) else math.inf)
