"""A least-squares fit that has stopped improving: noticed, ended, and polished from its best point.

A fit whose chi^2 has not dropped by more than STALL_CHI2 (in noise units) and STALL_RELATIVE of itself
over STALL_ITERATIONS iterations has stopped: it wanders along a direction the data do not determine
(an effect that is not there) or crawls along a parameter held at its bound, which MINPACK's own tests
can follow for thousands of evaluations. At that pace halving chi^2 would take 10^5 iterations.
analysis.fit.least_squares ends such a fit through its iteration callback (analysis.fit.bounded_leastsq) and polishes
it from its best point.
"""
from __future__ import annotations

import dataclasses
from typing import Callable, Mapping

import numpy as np

from analysis.fit.bounded_leastsq import LeastSquaresResult, Start, bounded_leastsq

STALL_CHI2 = 1e-3
STALL_RELATIVE = 1e-5
STALL_ITERATIONS = 10
POLISH_TOLERANCE = 1e-8        # the short fit from a stalled fit's best point, for its covariance
POLISH_PER_PARAMETER = 20


class StallWatch:
    """Counts the evaluations since chi^2 last improved by more than STALL_CHI2; keeps the best point."""

    def __init__(self, n_varying: int):
        self.n_varying = n_varying
        self.window = STALL_ITERATIONS * (n_varying + 1)      # an iteration costs a Jacobian: n + 1 evaluations
        self.best = np.inf
        self.best_values: dict[str, float] | None = None
        self.since = 0
        self.stalled = False

    def seen(self, values: Mapping[str, float], residual: np.ndarray) -> bool:
        """Record one evaluation; True (end the fit) once the fit has stalled."""
        chi2 = float(np.dot(residual, residual))
        if chi2 < self.best - max(STALL_CHI2, STALL_RELATIVE * self.best):
            self.since = 0
        else:
            self.since += 1
        if chi2 < self.best:
            self.best, self.best_values = chi2, dict(values)
        self.stalled = self.since > self.window
        return self.stalled

    def polished(self, residual: Callable[[dict[str, float]], np.ndarray], start: Start,
                 result: LeastSquaresResult) -> LeastSquaresResult:
        """After a stalled fit, a short fit from its best point, which gives the covariance; `result` when
        the fit did not stall, or when the polish neither gets a covariance nor keeps the best chi^2."""
        if not self.stalled or self.best_values is None:
            return result
        polished = bounded_leastsq(residual, start.moved_to(self.best_values), xtol=POLISH_TOLERANCE,
                                   ftol=POLISH_TOLERANCE, max_nfev=POLISH_PER_PARAMETER * (self.n_varying + 1))
        polished = dataclasses.replace(polished, nfev=polished.nfev + result.nfev)
        return polished if polished.covar is not None or polished.chisqr <= self.best else result
