"""A cubic spline through fixed knots, kept as a linear map: built once per set of knots, cheap per use.

The spectral checks interpolate H = Y/U between the excited lines (cubic
spline in log f, analysis.validity.unexcited) whenever the voltage carries
something on an unexcited line, which noise alone makes happen in about half
of a live measurement's periods. scipy's CubicSpline took ~0.6 ms a frame
there (input checks and a banded solve each time), for the same ~100 knots
every period.

A spline's coefficients are linear in its values at the knots: for values
y, the coefficients of piece i are C[:, i, :] @ y, where C holds the
coefficients of the spline through each unit vector, worked out once per set
of knots by CubicSpline itself (not-a-knot ends, as CubicSpline's default).
A use then takes the rows of C for the pieces its points fall in: the same
spline as CubicSpline(knots, y, extrapolate=True), to float64 rounding (the
same terms summed in another order).
"""
from __future__ import annotations

import functools

import numpy as np

_KEPT_KNOT_SETS = 8     # a measurement uses one set (its excited lines); a few more when a line is NaN


def spline_at(knots: np.ndarray, values: np.ndarray, points: np.ndarray) -> np.ndarray:
    """The not-a-knot cubic spline through (knots, values) at `points`, the end pieces extended beyond the
    knots. knots: increasing, at least 4; values: (knots,) or (knots, columns), real or complex."""
    knots = np.ascontiguousarray(knots, dtype=np.float64)
    points = np.asarray(points, dtype=np.float64)
    basis = _basis(knots.tobytes())
    piece = np.clip(np.searchsorted(knots, points, side="right") - 1, 0, knots.size - 2)
    coefficients = np.matmul(basis[:, piece, :], values)       # (4, points[, columns]), highest power first
    t = (points - knots[piece]).reshape(points.shape + (1,) * (values.ndim - 1))
    return ((coefficients[0] * t + coefficients[1]) * t + coefficients[2]) * t + coefficients[3]


@functools.lru_cache(maxsize=_KEPT_KNOT_SETS)
def _basis(knot_bytes: bytes) -> np.ndarray:
    """(4, pieces, knots): the coefficients of each piece of the spline through each unit vector."""
    from scipy.interpolate import CubicSpline      # 0.1 s to import: only once the voltage carries off its lines
    knots = np.frombuffer(knot_bytes, dtype=np.float64)
    basis = np.ascontiguousarray(CubicSpline(knots, np.eye(knots.size)).c)
    basis.flags.writeable = False
    return basis
