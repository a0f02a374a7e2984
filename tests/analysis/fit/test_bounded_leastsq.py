"""MINPACK with lmfit's bound transform: the numbers lmfit 1.3.4 gave on the same problem, the transform itself,
and how a fit ends early (its callback, its evaluation limit)."""
import math

import numpy as np
import pytest

from analysis.fit.bounded_leastsq import Start, bounded_leastsq, from_internal, gradient_scale, to_internal

# A damped cosine with an offset, 200 points of noise 0.02: five parameters, each kind of bound once; the
# offset's true value (-0.05) lies below its lower bound, so the fit ends on it.
T = np.linspace(0, 1, 200)
TRUE = dict(A=2.0, tau=0.3, f=7.0, phi=0.4, c=-0.05)
BOUNDS = dict(A=(0.0, 10.0), tau=(0.01, np.inf), f=(-np.inf, 50.0), phi=(-np.inf, np.inf), c=(0.0, 1.0))
START = dict(A=1.0, tau=0.5, f=6.5, phi=0.0, c=0.2)


def _model(p):
    return p["A"] * np.exp(-T / p["tau"]) * np.cos(2 * np.pi * p["f"] * T + p["phi"]) + p["c"]


Y = _model(TRUE) + 0.02 * np.random.default_rng(3).standard_normal(T.size)


def _fit(fixed=(), end_at=None, max_nfev=1000):
    seen = []

    def callback(values, residual):
        seen.append(dict(values))
        return end_at is not None and len(seen) >= end_at

    result = bounded_leastsq(lambda p: (_model(p) - Y) / 0.02, Start.of(START, BOUNDS, fixed), xtol=1e-12,
                             ftol=1e-12, max_nfev=max_nfev, iter_cb=callback)
    return result, seen


# What lmfit 1.3.4 returned for these fits: Minimizer(residual, params, iter_cb=..., scale_covar=False,
# nan_policy="propagate").minimize(method="leastsq", xtol=1e-12, ftol=1e-12, max_nfev=...), with params of
# START and BOUNDS. Printed with repr: the replacement gave the same bits on the machine that made them.
LMFIT = {
    "all free": dict(
        values=dict(A=2.015432837161002, tau=0.2984528361332952, f=6.992619451122486, phi=0.41905097185201046,
                    c=5.477396314290672e-12),
        variances=[5.836012491514936e-05, 2.5610050497320805e-06, 7.804038535506973e-06, 1.2691624931666151e-05,
                   4.425845554595507e-06],
        chisqr=1380.919868621449, nfev=123, calls=126, message="Fit succeeded.", success=True),
    "phi fixed": dict(
        values=dict(A=1.808201875376065, tau=0.3205106661783539, f=7.22002853398633, phi=0.0,
                    c=5.486971987878064e-11),
        variances=[4.762797805352484e-05, 3.2613592855854982e-06, 3.99095214034166e-06, 9.062664002183634e-06],
        chisqr=13661.785443030542, nfev=94, calls=97, message="Fit succeeded.", success=True),
}


@pytest.mark.parametrize("case", sorted(LMFIT))
def test_a_fit_gives_the_numbers_lmfit_gave(case):
    want = LMFIT[case]
    result, seen = _fit(fixed=("phi",) if case == "phi fixed" else ())
    assert result.varying == tuple(n for n in START if not (case == "phi fixed" and n == "phi"))
    for name, value in want["values"].items():
        assert result.values[name] == pytest.approx(value, rel=1e-9, abs=1e-12), name
    # The values agree to 1e-9; the variances, the diagonal of an inverse formed through the machine's BLAS, to
    # what its kernels round: 1.65e-6 apart on a machine other than the one that printed them.
    assert np.diag(result.covar) == pytest.approx(want["variances"], rel=1e-5)
    assert result.chisqr == pytest.approx(want["chisqr"], rel=1e-9)
    assert (result.nfev, len(seen), result.message, result.success) == (want["nfev"], want["calls"],
                                                                        want["message"], want["success"])
    assert not result.aborted


def test_a_fit_ended_by_its_callback_returns_where_it_was_last_evaluated_without_covariance():
    result, seen = _fit(end_at=25)
    # lmfit: nfev 23, the callback called once more at the end (26), these values, its words.
    assert (result.nfev, len(seen), result.success, result.aborted) == (23, 26, False, True)
    assert result.values == pytest.approx(dict(A=2.185665839642166, tau=0.19482292696120673, f=7.38063329217421,
                                               phi=0.5881791527019614, c=0.012686651989481323), rel=1e-9)
    assert result.values == seen[24] and result.covar is None and math.isnan(result.chisqr)
    assert result.message == "Tolerance seems to be too small. Could not estimate error-bars."


def test_a_fit_at_its_evaluation_limit_stops_there_and_is_evaluated_once_more():
    result, seen = _fit(max_nfev=30)
    assert (result.nfev, len(seen), result.success, result.aborted, result.covar) == (30, 33, False, True, None)
    assert result.values == pytest.approx(dict(A=1.921622563807166, tau=0.2748937374691043, f=7.189206997702449,
                                               phi=0.3372815982577604, c=0.010727833041865864), rel=1e-9)
    assert result.chisqr == pytest.approx(8429.630440319746, rel=1e-9)


def test_a_callback_that_ends_the_first_evaluation_leaves_the_start():
    result, seen = _fit(end_at=1)
    assert result.values == pytest.approx({**START}, rel=1e-12) and result.aborted and not result.success


@pytest.mark.parametrize("bound", [(0.0, 10.0), (0.01, np.inf), (-np.inf, 50.0), (-np.inf, np.inf)])
@pytest.mark.parametrize("value", [0.3, 2.0, 7.5])
def test_the_transform_goes_there_and_back_and_its_slope_is_its_derivative(bound, value):
    u = to_internal(value, bound)
    assert from_internal(u, bound) == pytest.approx(value, rel=1e-12)
    h = 1e-6
    slope = (from_internal(u + h, bound) - from_internal(u - h, bound)) / (2 * h)
    assert gradient_scale(u, bound) == pytest.approx(slope, rel=1e-6)


@pytest.mark.parametrize("u", [-1e6, -3.0, 0.0, 2.0, 1e6])
def test_any_internal_value_lands_inside_the_bounds(u):
    for bound in [(0.0, 10.0), (0.01, np.inf), (-np.inf, 50.0)]:
        assert bound[0] <= from_internal(u, bound) <= bound[1]


def test_a_start_is_clipped_into_its_bounds_and_bounds_without_room_are_refused():
    start = Start.of({"a": -1.0, "b": 5.0}, {"a": (0.0, 1.0), "b": (0.0, 1.0)}, fixed={"b"})
    assert start.values == {"a": 0.0, "b": 1.0} and start.varying == ("a",)
    assert start.moved_to({"a": 0.5, "b": 2.0}).values == {"a": 0.5, "b": 1.0}
    with pytest.raises(ValueError, match="no room"):
        Start.of({"a": 1.0}, {"a": (1.0, 1.0)})
