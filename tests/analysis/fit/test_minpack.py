"""MINPACK's lmdif loaded without the scipy.optimize package: the same bits as scipy.optimize.leastsq, by both
of analysis.fit.minpack's paths, and a fit that leaves the scipy.optimize and scipy.linalg packages unimported."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from scipy.optimize import leastsq as public_leastsq

from analysis.fit import minpack
from tests.fresh_import import REPO
from tests.pace import paced

T = np.linspace(0, 1, 200)
Y = 2.0 * np.exp(-T / 0.3) * np.cos(2 * np.pi * 7.0 * T + 0.4) + 0.02 * np.random.default_rng(5).standard_normal(200)


def _residual(x):
    return x[0] * np.exp(-T / x[1]) * np.cos(2 * np.pi * x[2] * T + x[3]) - Y


# A fit that converges, one stopped by its evaluation limit (no covariance), one of a single parameter.
CASES = {"converges": (_residual, [1.0, 0.5, 6.5, 0.0], 2000),
         "evaluation limit": (_residual, [1.0, 0.5, 6.5, 0.0], 12),
         "one parameter": (lambda x: _residual([x[0], 0.3, 7.0, 0.4]), [1.0], 2000)}
OPTIONS = dict(xtol=1e-12, ftol=1e-12, gtol=0.0, epsfcn=1e-10, factor=100)


def _public(func, x0, maxfev):
    best, covariance, _, _, ier = public_leastsq(func, x0, full_output=1, maxfev=maxfev, diag=None, **OPTIONS)
    return best, covariance, ier


def _same_bits(ours: minpack.LeastSquares, theirs) -> None:
    best, covariance, ier = theirs
    assert ours.ier == ier
    assert np.array_equal(ours.best, best)
    assert (ours.covariance is None) == (covariance is None)
    if covariance is not None:
        assert np.array_equal(ours.covariance, covariance)


@pytest.mark.parametrize("case", sorted(CASES))
def test_the_directly_loaded_routines_give_scipys_bits(case):
    func, x0, maxfev = CASES[case]
    assert minpack.load_compiled_routines() is not None       # the direct path is the one taken
    ours = minpack.leastsq(func, x0, maxfev=maxfev, **OPTIONS)
    _same_bits(ours, _public(func, x0, maxfev))
    if case == "evaluation limit":
        assert ours.ier == 5 and ours.covariance is None
    else:
        assert ours.ier in minpack.SUCCESS and ours.covariance is not None


@pytest.mark.parametrize("case", sorted(CASES))
def test_without_the_compiled_routines_the_public_leastsq_gives_the_same(monkeypatch, case):
    func, x0, maxfev = CASES[case]
    monkeypatch.setattr(minpack, "load_compiled_routines", lambda: None)
    _same_bits(minpack.leastsq(func, x0, maxfev=maxfev, **OPTIONS), _public(func, x0, maxfev))


def test_an_exception_of_the_residual_passes_through():
    class Stop(Exception):
        pass

    calls = []

    def residual(x):
        calls.append(1)
        if len(calls) > 5:
            raise Stop
        return _residual(x)

    with pytest.raises(Stop):
        minpack.leastsq(residual, [1.0, 0.5, 6.5, 0.0], maxfev=2000, **OPTIONS)


FIT_AND_LIST = ("import sys\n"
                "import numpy as np\n"
                "from analysis.fit.bounded_leastsq import Start, bounded_leastsq\n"
                "t = np.linspace(0, 1, 50)\n"
                "result = bounded_leastsq(lambda p: p['a'] * t + p['b'] - (2 * t + 1), "
                "Start.of(dict(a=1.0, b=0.0), dict(a=(0.0, 5.0), b=(-np.inf, np.inf))), xtol=1e-10, ftol=1e-10, "
                "max_nfev=500)\n"
                "print(round(result.values['a'], 6), round(result.values['b'], 6), result.covar is not None)\n"
                "print(','.join(sorted(m for m in sys.modules if m.startswith('scipy'))))\n")


def test_a_fit_in_a_fresh_process_imports_neither_scipy_optimize_nor_scipy_linalg():
    out = subprocess.run([sys.executable, "-c", FIT_AND_LIST], cwd=REPO, capture_output=True, text=True,
                         timeout=paced(300))
    assert out.returncode == 0, out.stderr
    fitted, modules = out.stdout.strip().split("\n")
    assert fitted == "2.0 1.0 True"
    loaded = modules.split(",")
    assert "scipy.optimize._minpack" in loaded and "scipy.linalg._flapack" in loaded
    assert "scipy.optimize" not in loaded and "scipy.linalg" not in loaded
