"""The spline kept as a linear map per set of knots: CubicSpline's values, within float64 rounding."""
import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from analysis.validity.knot_spline import spline_at


def _knots(seed, n=100):
    rng = np.random.default_rng(seed)
    return np.sort(np.log(rng.choice(np.arange(7, 13654), n, replace=False) * 48000 / 65536))


@pytest.mark.parametrize("columns", [None, 1, 2])
def test_the_values_are_cubicspline_s_at_points_inside_at_and_beyond_the_knots(columns):
    rng = np.random.default_rng(7)
    knots = _knots(1)
    shape = (knots.size,) if columns is None else (knots.size, columns)
    values = rng.standard_normal(shape) + 1j * rng.standard_normal(shape)
    points = np.r_[knots[0] - 0.3, knots[[0, 17, -1]], rng.uniform(knots[0], knots[-1], 40), knots[-1] + 0.2]
    expected = CubicSpline(knots, values, extrapolate=True)(points)
    got = spline_at(knots, values, points)
    assert got.shape == expected.shape
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12 * np.max(np.abs(values)))


def test_a_cubic_is_reproduced_exactly_and_a_second_set_of_knots_gets_its_own_map():
    # Not-a-knot ends reproduce any cubic: a check that does not lean on scipy's own values.
    cubic = np.polynomial.Polynomial([0.5, -1.0, 0.25, 0.03])
    for seed in (2, 3):
        knots = _knots(seed, n=60)
        points = np.linspace(knots[0] - 0.5, knots[-1] + 0.5, 25)
        np.testing.assert_allclose(spline_at(knots, cubic(knots), points), cubic(points), rtol=1e-9, atol=1e-9)


def test_four_knots_and_real_values():
    knots = np.log(np.array([10.0, 20.0, 50.0, 200.0]))
    values = np.array([1.0, 3.0, -2.0, 0.5])
    points = np.log(np.array([5.0, 15.0, 120.0, 400.0]))
    np.testing.assert_allclose(spline_at(knots, values, points), CubicSpline(knots, values)(points),
                               rtol=1e-12, atol=1e-12)
