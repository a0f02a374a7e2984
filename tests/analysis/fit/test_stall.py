"""The stall watch: a fit that stopped improving is ended, and its best point kept."""
import numpy as np
import pytest

from analysis.fit.bounded_leastsq import LeastSquaresResult, Start
from analysis.fit.stall import STALL_ITERATIONS, StallWatch


def _values(x: float) -> dict[str, float]:
    return {"x": x}


def _residual(chi2: float) -> np.ndarray:
    return np.array([np.sqrt(chi2)])


def test_a_fit_that_keeps_improving_is_never_stopped():
    watch = StallWatch(n_varying=1)
    assert not any(watch.seen(_values(k), _residual(1000.0 - k)) for k in range(500))


def test_a_flat_fit_is_stopped_after_its_window_with_its_best_point_kept():
    watch = StallWatch(n_varying=2)
    window = STALL_ITERATIONS * 3
    watch.seen(_values(1.0), _residual(50.0))
    watch.seen(_values(2.0), _residual(40.0))             # the best point
    flags = [watch.seen(_values(3.0 + k), _residual(40.0 + 1e-6 * (k % 2))) for k in range(window + 1)]
    assert not any(flags[:-1]) and flags[-1]
    assert watch.best == pytest.approx(40.0) and watch.best_values == {"x": 2.0}


def test_far_from_the_noise_a_gain_small_against_chi2_is_no_gain():
    watch = StallWatch(n_varying=0)
    chi2 = [1e8 - 10.0 * k for k in range(STALL_ITERATIONS + 2)]    # 10 < 1e-5 of 1e8 each time
    flags = [watch.seen(_values(0.0), _residual(c)) for c in chi2]
    assert flags[-1] and not flags[0]


def test_a_stalled_fit_is_polished_from_its_best_point_to_the_minimum():
    # chi^2 = (x - 3)^2 * 1e4: the watch saw x = 2.9 as best; the polish from there finds x = 3 and its variance.
    def residual(values):
        return np.array([100.0 * (values["x"] - 3.0), 1.0])

    watch = StallWatch(n_varying=1)
    watch.seen({"x": 2.9}, residual({"x": 2.9}))
    watch.stalled = True
    start = Start.of({"x": 0.0}, {"x": (-10.0, 10.0)})
    stalled = LeastSquaresResult(values={"x": 4.0}, varying=("x",), covar=None, success=False, message="ended",
                                 nfev=100, chisqr=1e4 + 1.0, aborted=True)
    polished = watch.polished(residual, start, stalled)
    assert polished.values["x"] == pytest.approx(3.0, abs=1e-6) and polished.nfev > 100     # both fits counted
    assert polished.covar is not None and polished.covar[0, 0] == pytest.approx(1e-4, rel=1e-3)
