"""The site fit's small linear algebra: where it starts, its effective number of parameters, the correction's
standard error. Its matrices are a few dozen wide, and go through numpy's own loops and LU solves, not BLAS's
threads (see gram)."""
from __future__ import annotations

import numpy as np

# Of the linearised start's step, tried in turn (linearised_start).
START_FRACTIONS = (1.0, 0.5, 0.25)


def linearised_start(problem) -> np.ndarray:
    """Where the site fit starts: the current fit's parameters, and the correction's coefficients from one
    Gauss-Newton step of the coefficients alone (the penalised linear least squares of the model linearised
    at h = 0), halved until it lowers chi^2; all zero when no such step does.

    From zero, Levenberg-Marquardt's first steps are held to a trust region and most of a site fit's
    Jacobians (each a QR of a few hundred rows by a hundred columns in MINPACK) only walk the coefficients
    to where this one linear solve puts them: on the real-like woofer's eight site fits 12-40 Jacobians
    each from zero, 3-28 from here, to the same chi^2 within the fit's tolerance.
    """
    x0 = np.zeros(problem.k + 2 * problem.n_basis)
    r0 = problem.residual(x0)
    J = problem.jacobian(x0)[:, problem.k:]
    try:
        step = np.linalg.solve(gram(J), -np.einsum("ij,i->j", J, r0))
    except np.linalg.LinAlgError:
        return x0
    chi2 = np.einsum("i,i->", r0, r0)
    for fraction in START_FRACTIONS:
        x = x0.copy()
        x[problem.k:] = fraction * step
        with np.errstate(all="ignore"):     # a step too far can make the model divide by zero: refused below
            r = problem.residual(x)
        if np.all(np.isfinite(x)) and np.einsum("i,i->", r, r) < chi2:
            return x
    return x0


def h_std(jac: np.ndarray, problem, freqs: np.ndarray, birge: float) -> np.ndarray:
    """Standard error of h (the larger of its real and imaginary part's) at `freqs`, the model's parameters held.

    Held, because the question is whether the data see the correction at a
    frequency at all; how it shares a smooth trend with Mms or Cms (which it
    can imitate) is another matter, and would make every point look unseen.
    """
    k, m = problem.k, problem.n_basis
    J = np.asarray(jac)[:, k:]
    covariance = inverse(gram(J)) * birge
    design = problem.correction.design(freqs)
    var_re = np.einsum("ij,jk,ik->i", design, covariance[:m, :m], design)
    var_im = np.einsum("ij,jk,ik->i", design, covariance[m:, m:], design)
    return np.sqrt(np.maximum(np.maximum(var_re, var_im), 0.0))


def effective_dof(jac: np.ndarray, n_model: int, n_data: int) -> float:
    """Trace of the correction's hat matrix: tr((J'J + P'P)^-1 J_d'J_d) over all parameters, less the model's own."""
    J = np.asarray(jac)
    seen = gram(J[:n_data])
    total = seen + gram(J[n_data:])
    try:
        hat = np.linalg.solve(total, seen)
    except np.linalg.LinAlgError:      # the model's own parameters degenerate: the least-squares answer
        hat = np.linalg.lstsq(total, seen, rcond=None)[0]
    return float(max(np.trace(hat) - n_model, 0.0))


# The matrices here are a few dozen wide. OpenBLAS spreads a product or an SVD of that size over its threads,
# which on a busy 2-core machine costs 10-50 times the work itself (J'J 6 ms of CPU against 0.07 ms on one
# thread, pinv 45 ms against 0.8 ms; measured with another developer's load): numpy's own loops (einsum) and
# LU solves stay on one thread.
def gram(J: np.ndarray) -> np.ndarray:
    """J'J without BLAS's threads."""
    return np.einsum("ij,ik->jk", J, J)


def inverse(A: np.ndarray) -> np.ndarray:
    """The inverse of a symmetric matrix, its pseudo-inverse when singular."""
    try:
        return np.linalg.inv(A)
    except np.linalg.LinAlgError:
        return np.linalg.pinv(A)
