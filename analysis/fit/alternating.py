"""The paper's two steps repeated until they agree: how magnitude-only curves (Klippel LPM exports) are fitted.

The seed paper fits Z for the electrical parameters and the motional branch, then Hx for Bl and the
creep with those held (analysis.fit.paper). Its Z step must fit the creep too, as a nuisance: left at a
start value it would bend CMES and LCES. But the creep barely shows in Z, and on magnitude-only curves
the Z step's creep trades with CMES (the issue's real 6.5" woofer: "on Z alone the creep law chosen
moves Qms by 5 to 40 %"). Here the creep is left to Hx, where it shows, and the steps alternate:

    Z step:   RE, LE, the blocked impedance's own, CMES, LCES, RES        (creep held at Hx's)
    Hx step:  Bl, the creep, the displacement channel's own               (the Z step's held)

until no parameter moves by more than TOLERANCE between rounds (MAX_ROUNDS at most). Neither channel's
misfit bends what the other determines, and the creep no longer trades with the compliance: measured on
LPM-like exports of four realistic drivers, tests/analysis/fit/test_alternating.py and
docs/identification.md.

Uncertainties: those of the two-step estimator at the converged point (analysis.fit.paper's propagation:
each step's covariance scaled by its own channel's Birge ratio, Bl carrying the Z step's uncertainty).
"""
from __future__ import annotations

import threading
from typing import Mapping

from analysis.fit.least_squares import (EVALUATIONS_PER_PARAMETER, FitData, FitResult, _minimize, _start, fit_model,
                                        result_of)
from analysis.fit.paper import _two_step_covariance, bl_from_hx, free_off_bounds, two_step_start
from analysis.model.composed import Model

TOLERANCE = 1e-3
MAX_ROUNDS = 8


def fit_alternating(data: FitData, model: Model, start: Mapping[str, float] | None = None,
                    cancel: threading.Event | None = None, per_parameter: int = EVALUATIONS_PER_PARAMETER
                    ) -> FitResult:
    """Fit `model` by alternating the Z and Hx steps (module doc); without Hx, the Z fit alone."""
    if not model.with_displacement:
        return fit_model(data, model, start, cancel, per_parameter)
    sigmas, values, first, second = two_step_start(data, model, start)
    nfev, success, messages = 0, True, []
    for round_ in range(MAX_ROUNDS):
        before = dict(values)
        z_step = _minimize(model, _start(model, values, second), data, False, sigmas, cancel, per_parameter)
        values = dict(z_step.values)
        if round_ == 0 and "Bl" not in (start or {}):
            values["Bl"] = bl_from_hx(model, values, data, sigmas)
        x_step = _minimize(model, _start(model, values, first), data, True, sigmas, cancel, per_parameter,
                           use_z=False)
        values = dict(x_step.values)
        nfev += z_step.nfev + x_step.nfev
        success = bool(z_step.success and x_step.success)
        messages = [f"Z step: {z_step.message}", f"Hx step: {x_step.message}"]
        if round_ and _moved(before, values) < TOLERANCE:
            break
    free1, free2 = free_off_bounds(model, values, first), free_off_bounds(model, values, second)
    covar = _two_step_covariance(model, values, values, data, sigmas, free1, free2, set())
    return result_of(model, values, tuple(free1 + free2), covar, data, True, sigmas, success,
                     f"{round_ + 1} rounds; " + "; ".join(messages), int(nfev), birge_scaled=True,
                     method="alternating")


def _moved(before: Mapping[str, float], after: Mapping[str, float]) -> float:
    """The largest relative change of a parameter between two rounds."""
    return max(abs(after[n] - before[n]) / max(abs(before[n]), 1e-30) for n in after)
