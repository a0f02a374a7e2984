"""The covariance of the large-signal coefficients: a sandwich whose middle comes from the periods.

    cov = (G - C)^-1 M (G - C)^-1

G - C is the bias-compensated normal matrix (solve.py). M, the covariance
of the normal equations' right side, is not taken as G (which would assume
every line's noise independent of its neighbours'): the regressors are
products, x^j i, and the noise of i is spread by x's spectrum over +-(x's
bandwidth). The right side is therefore summed over blocks of lines wider
than that, and M taken from how each block's sum scatters between the
periods (each block's lines correlated, the blocks independent). The misfit
counted as noise in the weights (weights.misfit_variance) is added as
independent.

tau2, lambda and the laser delays were searched, not solved for: each enters
as one more column, the model's sensitivity to it (a central difference),
so that the coefficients' covariance is the one left after not knowing them
either (Le(0) and tau2 trade off, for one).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from analysis.large_signal.columns import ELECTRICAL, MECHANICAL, Nuisance, Orders, build_columns, stacked
from analysis.large_signal.fitting import FitState
from analysis.large_signal.solve import Solution, solve_normal

NOISE_BLOCK_HZ = 400.0     # wider than the displacement's band, which spreads the current's noise


def covariance(fit: FitState, orders: Orders, nu: Nuisance, sol: Solution) -> tuple[np.ndarray, list[float]]:
    """The coefficients' covariance (module doc), searched parameters included; and each recording's laser
    delay's 1-sigma, s (0 where no delay was searched), from the same matrix."""
    names = orders.names()
    p = len(names)
    sensitivities = _sensitivities(fit, orders, nu, sol.theta)
    q = len(sensitivities[0][0]) if sensitivities else 0
    gram, noise_gram, meat = np.zeros((p + q, p + q)), np.zeros((p + q, p + q)), np.zeros((p + q, p + q))
    index = [fit.max_names.index(n) for n in names]
    for k, d in enumerate(fit.data):
        periods = fit.columns(k, True)
        mean_e, mean_m = stacked(fit.mean_cols[k], names, nu)
        per_e, per_m = stacked(periods, names, nu)
        block = max(int(np.ceil(NOISE_BLOCK_HZ / d.bin_width)), 8)
        for eq, phi, per, target, weight, misfit, extra in (
                (ELECTRICAL, mean_e, per_e, periods.target_e, fit.weights[k][0], fit.misfits[k][0],
                 sensitivities[k][0]),
                (MECHANICAL, mean_m, per_m, None, fit.weights[k][1], fit.misfits[k][1],
                 sensitivities[k][1])):
            phi = np.concatenate([phi, np.stack(extra, axis=-1)], axis=-1) if q else phi
            weighted = phi * weight[:, None]
            gram += (weighted.conj().T @ phi).real
            if fit.corrections:
                noise_gram[:p, :p] += fit.corrections[k][eq][0][np.ix_(index, index)]
            r = (-(per @ sol.theta)) if target is None else target - per @ sol.theta
            dev = r - r.mean(axis=0)
            n_periods = dev.shape[0]
            for start in range(0, phi.shape[0], block):
                part = slice(start, start + block)
                scores = (weighted[part].conj().T @ dev[:, part].T).real      # (p + q, P)
                meat += scores @ scores.T / (n_periods * (n_periods - 1))
            meat += (weighted.conj().T @ (weighted * (misfit / 2.0)[:, None])).real
    _, inverse = solve_normal(gram, np.zeros(p + q), noise_gram if fit.corrections else None,
                              np.zeros(p + q))
    full = inverse @ meat @ inverse
    delayed = [k for k, d in enumerate(fit.data) if d.laser_delay_possible]
    first = q - len(delayed)            # the delays' columns come after tau2's (and lambda's)
    delay_std = [0.0] * len(fit.data)
    for j, k in enumerate(delayed):
        delay_std[k] = float(np.sqrt(max(full[p + first + j, p + first + j], 0.0)))
    return full[:p, :p], delay_std

def _sensitivities(fit: FitState, orders: Orders, nu: Nuisance, theta: np.ndarray) -> list:
    """Per recording, ([electrical], [mechanical]) d(Phi theta)/d(parameter) of every searched parameter."""
    names = orders.names()
    steps = [("tau2", nu.tau2 * 1e-3)] + ([("lam", 1e-3)] if orders.creep else [])
    out = []
    for k, cols in enumerate(fit.mean_cols):
        electrical, mechanical = [], []
        for field_name, h in steps:
            value = getattr(nu, field_name)
            plus = stacked(cols, names, dataclasses.replace(nu, **{field_name: value + h}))
            minus = stacked(cols, names, dataclasses.replace(nu, **{field_name: value - h}))
            electrical.append((plus[0] - minus[0]) @ theta / (2 * h))
            mechanical.append((plus[1] - minus[1]) @ theta / (2 * h))
        out.append((electrical, mechanical))
    for k, d in enumerate(fit.data):
        if not d.laser_delay_possible:
            continue
        h = 2e-6
        shifted = []
        for delay in (fit.delays[k] + h, fit.delays[k] - h):
            cols = build_columns(d, fit.offsets[k], delay, fit.x_scale, fit.max_orders)
            shifted.append(stacked(cols, names, nu))
        for j, (electrical, mechanical) in enumerate(out):
            if j == k:
                electrical.append((shifted[0][0] - shifted[1][0]) @ theta / (2 * h))
                mechanical.append((shifted[0][1] - shifted[1][1]) @ theta / (2 * h))
            else:
                electrical.append(np.zeros(fit.mean_cols[j].target_e.shape, dtype=complex))
                mechanical.append(np.zeros(fit.mean_cols[j].X_m.shape, dtype=complex))
    return out
