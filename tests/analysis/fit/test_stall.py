"""The stall watch: a fit that stopped improving is ended, and its best point kept."""
import lmfit
import numpy as np
import pytest

from analysis.fit.stall import STALL_ITERATIONS, StallWatch


def _params(x: float) -> lmfit.Parameters:
    params = lmfit.Parameters()
    params.add("x", value=x)
    return params


def _residual(chi2: float) -> np.ndarray:
    return np.array([np.sqrt(chi2)])


def test_a_fit_that_keeps_improving_is_never_stopped():
    watch = StallWatch(n_varying=1)
    assert not any(watch.seen(_params(k), _residual(1000.0 - k)) for k in range(500))


def test_a_flat_fit_is_stopped_after_its_window_with_its_best_point_kept():
    watch = StallWatch(n_varying=2)
    window = STALL_ITERATIONS * 3
    watch.seen(_params(1.0), _residual(50.0))
    watch.seen(_params(2.0), _residual(40.0))             # the best point
    flags = [watch.seen(_params(3.0 + k), _residual(40.0 + 1e-6 * (k % 2))) for k in range(window + 1)]
    assert not any(flags[:-1]) and flags[-1]
    assert watch.best == pytest.approx(40.0) and watch.best_params(_params(0.0))["x"].value == 2.0


def test_far_from_the_noise_a_gain_small_against_chi2_is_no_gain():
    watch = StallWatch(n_varying=0)
    chi2 = [1e8 - 10.0 * k for k in range(STALL_ITERATIONS + 2)]    # 10 < 1e-5 of 1e8 each time
    flags = [watch.seen(_params(0.0), _residual(c)) for c in chi2]
    assert flags[-1] and not flags[0]
