"""MINPACK's Levenberg-Marquardt (scipy.optimize.leastsq's, analysis.fit.minpack) with bounds, as lmfit's
"leastsq" method runs it.

MINPACK knows no bounds. Each bounded parameter is fitted through an internal variable that can take any
value (MINUIT's transform, as lmfit's Parameter.setup_bounds does it):

    both bounds     value = lo + (sin(u) + 1) (hi - lo) / 2          u = arcsin(2 (value - lo) / (hi - lo) - 1)
    lower only      value = lo - 1 + sqrt(u^2 + 1)                   u = sqrt((value - lo + 1)^2 - 1)
    upper only      value = hi + 1 - sqrt(u^2 + 1)                   u = sqrt((hi - value + 1)^2 - 1)

and MINPACK's covariance of u is taken to the values' by d value / d u (cov_ij * g_i g_j). A parameter on
its bound has g = 0 there: its Jacobian column vanishes and MINPACK gives no covariance, so the fits hold
it at the bound and refit the others (analysis.fit.least_squares). The options, the evaluation count, the
messages and what an ended fit returns are lmfit 1.3's too: fits give the numbers they gave when lmfit ran
them, to the last bit (tests/analysis/fit/test_bounded_leastsq.py). lmfit itself is not used: its
Parameters objects per evaluation took a third of the LPM exports' analysis time (14.4 s -> 9.0 s CPU),
and importing it cost over a second at start-up (scipy.stats, matplotlib).
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable, Collection, Mapping

import numpy as np

from analysis.fit.minpack import leastsq

# An internal start value this small is taken as 0 (lmfit's `tiny`).
TINY = 1.0e-15

# What MINPACK is asked, as lmfit asks it: no gradient test, a small step for the forward differences,
# MINPACK's own step bound and scaling. Its evaluation limit is twice the fit's own, which ends it first.
LMDIF_OPTIONS = dict(gtol=0.0, epsfcn=1.0e-10, factor=100)
# The count a fit reports is lmfit's: it starts at -2, loses one when MINPACK returns and gains the final
# evaluation at the best point, so it is the evaluations made less three (scipy checks the residual's
# shape with one before MINPACK starts).
UNCOUNTED_EVALUATIONS = 2

Residual = Callable[[dict[str, float]], np.ndarray]
# Called after each evaluation with the values and their residual; True ends the fit ("abort").
IterationCallback = Callable[[dict[str, float], np.ndarray], bool]


@dataclass(frozen=True)
class Start:
    """Where a fit starts: every parameter's value (kept inside its bounds), its bounds, those that vary."""

    values: dict[str, float]
    bounds: dict[str, tuple[float, float]]
    varying: tuple[str, ...]

    @classmethod
    def of(cls, values: Mapping[str, float], bounds: Mapping[str, tuple[float, float]],
           fixed: Collection[str] = ()) -> "Start":
        """`values` (in their order), each clipped into its bounds; all but `fixed` vary."""
        for name, (lo, hi) in bounds.items():
            if not lo < hi:
                raise ValueError(f"parameter '{name}': its bounds ({lo}, {hi}) leave it no room")
        clipped = {name: float(min(max(float(v), bounds[name][0]), bounds[name][1])) for name, v in values.items()}
        return cls(clipped, dict(bounds), tuple(n for n in values if n not in fixed))

    def moved_to(self, values: Mapping[str, float]) -> "Start":
        """The same parameters and bounds, from `values`."""
        return replace(self, values={n: _clip(float(values[n]), self.bounds[n]) for n in self.values})


# eq=False: the fit's own result, never compared (its covariance array made == raise); so no __eq__ and
# __hash__ are generated at every start (Python 3.11 execs each dataclass method).
@dataclass(frozen=True, eq=False)
class LeastSquaresResult:
    """What bounded_leastsq found: the values, which varied, their covariance and MINPACK's outcome."""

    values: dict[str, float]        # every parameter, the fixed ones as they started
    varying: tuple[str, ...]
    covar: np.ndarray | None        # of the varying values, unscaled; None when MINPACK gave none
    success: bool
    message: str
    nfev: int
    chisqr: float                   # at `values`; nan when the fit was ended by its callback there
    aborted: bool                   # ended by the callback or by the evaluation limit


def _clip(value: float, bound: tuple[float, float]) -> float:
    lo, hi = bound
    return hi if value > hi else lo if value < lo else value


def to_internal(value: float, bound: tuple[float, float]) -> float:
    """The unbounded variable MINPACK sees for `value` (module doc)."""
    lo, hi = bound
    if lo == -np.inf and hi == np.inf:
        u = value
    elif hi == np.inf:
        u = np.sqrt((value - lo + 1.0) ** 2 - 1)
    elif lo == -np.inf:
        u = np.sqrt((hi - value + 1.0) ** 2 - 1)
    else:
        u = np.arcsin(2 * (value - lo) / (hi - lo) - 1)
    return 0.0 if abs(u) < TINY else float(u)


def from_internal(u: float, bound: tuple[float, float]) -> float:
    """The value of internal variable `u`, clipped into the bounds against rounding."""
    lo, hi = bound
    if lo == -np.inf and hi == np.inf:
        value = float(u)
    elif hi == np.inf:
        value = float(lo - 1.0 + np.sqrt(u * u + 1))
    elif lo == -np.inf:
        value = float(hi + 1 - np.sqrt(u * u + 1))
    else:
        value = float(lo + (np.sin(u) + 1) * (hi - lo) / 2.0)
    return _clip(value, bound)


def gradient_scale(u: float, bound: tuple[float, float]) -> float:
    """d value / d u at `u`."""
    lo, hi = bound
    if lo == -np.inf and hi == np.inf:
        return 1.0
    if hi == np.inf:
        return u / np.sqrt(u * u + 1)
    if lo == -np.inf:
        return -u / np.sqrt(u * u + 1)
    return np.cos(u) * (hi - lo) / 2.0


class _Cancelled(Exception):
    """The fit is cancelled here (not an error: it returns where it was): its callback said so, or the
    evaluation limit was reached."""


class _Evaluations:
    """The residual as MINPACK calls it: internal variables to values, the count, the callback."""

    def __init__(self, residual: Residual, start: Start, max_nfev: int, iter_cb: IterationCallback | None):
        self.residual, self.start, self.max_nfev, self.iter_cb = residual, start, max_nfev, iter_cb
        self.values = dict(start.values)
        self.nfev = -UNCOUNTED_EVALUATIONS
        self.last_internal: np.ndarray | None = None
        self.by_callback = False
        self.hit_limit = False

    def __call__(self, internal: np.ndarray) -> np.ndarray:
        internal = internal.reshape((1,)) if internal.shape == () else internal
        bounds = self.start.bounds
        for name, u in zip(self.start.varying, internal):
            self.values[name] = from_internal(u, bounds[name])
        self.nfev += 1
        self.last_internal = internal
        if self.nfev > self.max_nfev:
            self.hit_limit = True
            raise _Cancelled
        values = dict(self.values)
        out = self.residual(values)
        if self.iter_cb is not None:
            self.by_callback = bool(self.iter_cb(values, out)) or self.by_callback
        if self.by_callback:
            raise _Cancelled
        return np.asarray(out, dtype=np.float64).ravel()


def bounded_leastsq(residual: Residual, start: Start, *, xtol: float, ftol: float, max_nfev: int,
                    iter_cb: IterationCallback | None = None) -> LeastSquaresResult:
    """Minimise sum(residual(values)^2) over `start.varying` within their bounds (MINPACK's lmdif).

    At most `max_nfev` evaluations; `iter_cb` sees each one and may end the fit. An ended fit returns the
    values it was last evaluated at, without covariance, success False.
    """
    evaluate = _Evaluations(residual, start, max_nfev, iter_cb)
    x0 = [to_internal(start.values[n], start.bounds[n]) for n in start.varying]
    with np.errstate(all="ignore"):
        try:
            best, cov, ier = leastsq(evaluate, x0, xtol=xtol, ftol=ftol, maxfev=2 * max_nfev, **LMDIF_OPTIONS)
        except _Cancelled:
            best, cov, ier = evaluate.last_internal, None, -1
        aborted = ier == -1
        evaluate.nfev = min(evaluate.nfev - 1, max_nfev - 1)
        chisqr = np.nan
        try:
            final = evaluate(best)       # the values at `best`, evaluated once more (and counted, as lmfit does)
            chisqr = max(float((final ** 2).sum()), 1.0e-250 * len(final))
        except _Cancelled:
            pass
        message = _MESSAGES.get(ier, "Tolerance seems to be too small.")
        if ier == 5:
            message = message.format(2 * max_nfev)
        if cov is not None:
            g = np.atleast_2d([gradient_scale(u, start.bounds[n]) for n, u in zip(start.varying, best)])
            cov = cov * np.dot(g.T, g)
        else:
            message += " Could not estimate error-bars."
    return LeastSquaresResult(values=dict(evaluate.values), varying=start.varying, covar=cov,
                              success=ier in (1, 2, 3, 4), message=message, nfev=evaluate.nfev, chisqr=chisqr,
                              aborted=aborted)


# lmfit's words for MINPACK's outcomes (an ended fit is -1, and reads as the last).
_MESSAGES = {
    0: "Invalid Input Parameters. I.e. more variables than data points given, tolerance < 0.0, or no data provided.",
    1: "Fit succeeded.", 2: "Fit succeeded.", 3: "Fit succeeded.",
    4: "One or more variable did not affect the fit.",
    5: "Too many function calls (max set to {:d})! Use: minimize(func, params, ..., max_nfev=NNN) to increase this "
       "maximum.",
}
