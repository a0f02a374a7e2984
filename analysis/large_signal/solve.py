"""Weighted least squares of the large-signal regressions, with each line's noise from the scatter between periods.

Every recording contributes its electrical and mechanical equations line by
line, each line weighted by the reciprocal of its equation error's variance
(weights.py). With the weights right and the model right, chi^2 / dof is 1;
above 1, the misfit is the model's (or the simulation's), and the
coefficients' covariance is scaled by it (lmfit's scale_covar) so that the
bands stay honest.

Complex lines count as two data each (real and imaginary parts, each with
half the line's variance); the columns are scaled to unit norm before the
solve, which keeps the polynomials' powers and the physical units (ohm next
to kg) well conditioned.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# The largest share of a direction's regressor power that the bias compensation takes out (solve_normal).
MAX_NOISE_SHARE = 0.5


@dataclass(frozen=True, slots=True)
class Block:
    """One equation of one recording: regressors (bins, p), target (bins,), weights (bins,)."""

    phi: np.ndarray
    target: np.ndarray
    weight: np.ndarray
    equation: str
    recording: int


@dataclass(frozen=True, slots=True)
class Solution:
    theta: np.ndarray
    cov: np.ndarray           # unscaled: (A^T A)^-1 in the data's noise units
    chi2: float
    n_data: int
    chi2_by_equation: dict     # equation -> (chi2, n_data)
    inverse: np.ndarray | None = None     # (G - C)^-1, for the covariance's sandwich

    @property
    def n_params(self) -> int:
        return self.theta.size

    @property
    def dof(self) -> int:
        return max(self.n_data - self.n_params, 1)

    @property
    def chi2_red(self) -> float:
        return self.chi2 / self.dof

    @property
    def bic(self) -> float:
        return self.chi2 + self.n_params * np.log(self.n_data)

    @property
    def aic(self) -> float:
        return self.chi2 + 2.0 * self.n_params

    def scaled_cov(self) -> np.ndarray:
        """The covariance, inflated by chi^2_red when the misfit exceeds the noise (never shrunk)."""
        return self.cov * max(self.chi2_red, 1.0)

    def residual_vector(self, blocks: list[Block]) -> np.ndarray:
        return np.concatenate([_split(np.sqrt(b.weight) * (b.target - b.phi @ self.theta)) for b in blocks])


def solve(blocks: list[Block]) -> Solution:
    """The weighted least-squares solution of the stacked blocks."""
    p = blocks[0].phi.shape[1]
    gram = np.zeros((p, p))
    rhs = np.zeros(p)
    for b in blocks:
        weighted = b.phi * b.weight[:, None]
        gram += (weighted.conj().T @ b.phi).real
        rhs += (weighted.conj().T @ b.target).real
    theta, inverse = solve_normal(gram, rhs)
    return solution(theta, inverse, [(b.equation, b.target - b.phi @ theta, b.weight) for b in blocks])


def solve_normal(gram: np.ndarray, rhs: np.ndarray, noise_gram: np.ndarray | None = None,
                 noise_rhs: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(theta, covariance) from the normal equations G theta = r, bias-compensated when the regressors' own
    noise (noise_gram C, noise_rhs c) is given: (G - C) theta = r - c.

    Through the unit-diagonal G (columns scaled to unit norm) and its
    eigenvectors: a p x p problem (p ~ 40) instead of an SVD of the 10^4 x p
    data, ~20x faster, which counts as the searches solve it hundreds of
    times. Directions the data do not determine (eigenvalues below 1e-13 of
    the largest: singular values below ~3e-7) are left out, as a truncated
    SVD would. Returns (theta, (G - C)^-1); the covariance is the sandwich
    (G - C)^-1 M (G - C)^-1, M the covariance of the normal equations' right
    side: G itself for independent lines (identify.py estimates it from the
    periods, which also sees lines whose noise is correlated).

    With C: in G's metric, C has eigenvalues mu in [0, 1), each the share of
    a direction's "signal" that is the regressors' noise. A direction that
    is mostly noise cannot be corrected reliably (G - C is then near
    singular, or not even positive), so its mu is capped at MAX_NOISE_SHARE:
    it stays somewhat shrunk, and its variance large ((G - C)^-1 G (G - C)^-1
    is never smaller than G^-1).
    """
    norms = np.sqrt(np.maximum(np.diag(gram), 0.0))
    norms[norms == 0] = 1.0
    scale = np.outer(norms, norms)
    values, vectors = np.linalg.eigh(gram / scale)
    keep = values > values[-1] * 1e-13
    whiten = vectors[:, keep] / np.sqrt(values[keep])          # W^T G W = I on the kept directions
    shares = np.zeros(int(keep.sum()))
    turn = np.eye(shares.size)
    if noise_gram is not None:
        shares, turn = np.linalg.eigh(whiten.T @ (noise_gram / scale) @ whiten)
        shares = np.clip(shares, 0.0, MAX_NOISE_SHARE)
        rhs = rhs - noise_rhs
    basis = whiten @ turn
    inverse = (basis / (1.0 - shares)) @ basis.T / scale
    return inverse @ rhs, inverse


def solution(theta: np.ndarray, cov: np.ndarray, residuals) -> Solution:
    """The Solution of theta, from each block's (equation, residual, weight)."""
    by_eq: dict = {}
    for equation, r, weight in residuals:
        chi2 = float(np.sum(weight * (r.real**2 + r.imag**2)))
        old = by_eq.get(equation, (0.0, 0))
        by_eq[equation] = (old[0] + chi2, old[1] + 2 * r.size)
    chi2 = sum(c for c, _ in by_eq.values())
    return Solution(theta, cov, chi2, int(sum(n for _, n in by_eq.values())), by_eq)


def _split(z: np.ndarray) -> np.ndarray:
    return np.concatenate([z.real, z.imag])
