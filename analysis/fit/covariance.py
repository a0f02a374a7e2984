"""A covariance from a central-difference Jacobian, for fits whose optimiser gives none.

MINPACK gives no covariance when it stops on "tolerance too small" (a realistic subwoofer's joint fit
does), and the paper's two-step fit needs each step's on its own. With J the Jacobian of the weighted
residual at the optimum, cov = (J'J)^-1, before any scaling by the misfit.
"""
from __future__ import annotations

from typing import Callable, Mapping, Sequence

import numpy as np

# Above this condition number of the column-scaled J'J a parameter is not determined by the data.
MAX_CONDITION = 1e12


def jacobian(residual: Callable[[dict], np.ndarray], values: Mapping[str, float], names: Sequence[str],
             specs: Mapping) -> np.ndarray:
    """d residual / d value for each of `names` (central differences, kept inside each parameter's bounds)."""
    base = dict(values)
    columns = []
    for name in names:
        v, spec = base[name], specs[name]
        h = 1e-6 * max(abs(v), abs(spec.default) * 1e-3, 1e-30)
        hi, lo = min(v + h, spec.max), max(v - h, spec.min)
        columns.append((residual({**base, name: hi}) - residual({**base, name: lo})) / (hi - lo))
    return np.column_stack(columns) if columns else np.zeros((len(residual(base)), 0))


def normal_inverse(J: np.ndarray) -> np.ndarray | None:
    """(J'J)^-1, the columns scaled to unit norm first (parameters span twenty decades); None when singular."""
    norms = np.linalg.norm(J, axis=0)
    if not np.all(np.isfinite(J)) or np.any(norms == 0):
        return None
    scaled = J / norms
    jtj = scaled.T @ scaled
    try:
        if np.linalg.cond(jtj) > MAX_CONDITION:
            return None
        return np.linalg.inv(jtj) / np.outer(norms, norms)
    except np.linalg.LinAlgError:
        return None
