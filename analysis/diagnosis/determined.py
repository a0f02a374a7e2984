"""Which parameters the data determine, each judged with the ones they do not fix held.

A fit's covariance is all or nothing: one parameter the data cannot see
(L3 of an LR-3 whose second stage has become superfluous once a creep law
explains what it had bent towards) makes (J'J) singular, and then no
parameter gets a standard error. The diagnosis flags a candidate whose own
parameters are undetermined; judged on the whole covariance, the right
effect (creep-log, at the noise floor) was refused because of another
effect's degenerate parameters.

So when a fit has no standard error for a parameter that is not on a bound,
the Jacobian is taken at the fit and its columns are kept one by one, the
candidate's own parameters last: a column that would make the scaled J'J
singular (a parameter the data do not fix, given those kept) is held. The
standard errors of the kept ones come from their covariance; the held ones
keep none, and are flagged undetermined as before. Holding the degenerate
parameters of the effects already in the model first means a new effect's
parameter is undetermined only when the data cannot fix it with every
determined parameter of the model free. (Which parameter of a degenerate
group is held does not change the others' standard errors: the kept columns
span the same space.)

It costs two model evaluations per parameter, for the fits that lack a
standard error only.
"""
from __future__ import annotations

import dataclasses
from typing import Sequence

import numpy as np

from analysis.fit.covariance import MAX_CONDITION, jacobian, normal_inverse
from analysis.fit.least_squares import FitData, FitResult, _residual_vector, channel_sigmas


def complete(fit: FitResult) -> bool:
    """Every varying parameter off its bounds has a standard error."""
    specs = {s.name: s for s in fit.model.param_specs}
    return all(fit.stderr.get(n) is not None for n in fit.varying if not specs[n].on_bound(fit.values[n]))


def with_undetermined_held(data: FitData, fit: FitResult | None, last: Sequence[str] = ()) -> FitResult | None:
    """`fit` with a standard error for every parameter the data determine, those they do not held (no standard
    error). `last`: the parameters judged after all the others (a candidate's own). Unchanged when complete."""
    if fit is None or complete(fit):
        return fit
    specs = {s.name: s for s in fit.model.param_specs}
    names = [n for n in fit.varying if not specs[n].on_bound(fit.values[n])]
    names = [n for n in names if n not in last] + [n for n in names if n in last]
    use_x = fit.model.with_displacement
    sigmas = channel_sigmas(data, use_x)
    J = jacobian(lambda p: _residual_vector(fit.model, p, data, use_x, sigmas), fit.values, names, specs)
    kept = _independent_columns(J)
    covar = normal_inverse(J[:, kept]) if kept else None
    if covar is None:
        return fit
    # Scaled as analysis.fit.least_squares.result_of scales the whole covariance.
    birge = max(1.0, fit.chi2_red) if fit.noise_known else fit.chi2_red
    stderr = {n: None for n in fit.values}
    for i, k in enumerate(kept):
        variance = covar[i, i] * birge
        stderr[names[k]] = float(np.sqrt(variance)) if variance >= 0 else None
    return dataclasses.replace(fit, stderr=stderr)


def _independent_columns(J: np.ndarray) -> list[int]:
    """The columns kept in order, each one that leaves the column-scaled J'J well conditioned."""
    kept: list[int] = []
    for k in range(J.shape[1]):
        column = J[:, k]
        norm = np.linalg.norm(column)
        if not np.all(np.isfinite(column)) or norm == 0:
            continue
        trial = kept + [k]
        scaled = J[:, trial] / np.linalg.norm(J[:, trial], axis=0)
        if np.linalg.cond(scaled.T @ scaled) <= MAX_CONDITION:
            kept = trial
    return kept
