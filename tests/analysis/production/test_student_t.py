"""Student's t two-sided tail without scipy (analysis.production.student_t): against closed forms and scipy."""
import math

import pytest
from scipy.special import stdtr

from analysis.production.student_t import t_two_sided

T_GRID = (0.0, 1e-6, 1e-3, 0.1, 0.5, 1.0, 1.5, 1.7, 1.73, 1.8, 1.96, 2.0, 2.5, 3.0, 4.0, 5.0, 7.0, 10.0, 20.0, 30.0,
          100.0, 1e3, 1e5)
DF_GRID = (0.5, 1.0, 1.5, 2.0, 3.0, 4.7, 10.0, 19.9, 20.0, 39.9, 40.1, 100.0, 999.5, 1e4, 66666.3, 1e5, 1e6, 1e7, 1e9)


@pytest.mark.parametrize("df", DF_GRID)
def test_it_agrees_with_scipy_over_a_grid(df):
    """Relative 1e-13, and df/2 ulps more at large df (the continued fraction's rounding near t ~ 2).

    One point is scipy's own: at df = 1, t = 1e-6 stdtr is 2.8e-11 off the closed form, which this function
    meets to 1e-14 (the next test)."""
    for t in T_GRID:
        want = float(2.0 * stdtr(df, -t))
        got = t_two_sided(t, df)
        tolerance = 5e-11 if (df, t) == (1.0, 1e-6) else 1e-13 + 1e-16 * df
        if want > 1e-290:
            assert got == pytest.approx(want, rel=tolerance, abs=0), (t, df)
        else:                                    # underflow: both (next to) nothing
            assert 0.0 <= got <= 1e-290, (t, df, got)
        assert t_two_sided(-t, df) == got        # two-sided: the sign of t does not matter


@pytest.mark.parametrize("t", T_GRID)
def test_it_agrees_with_the_closed_forms_of_one_and_two_degrees_of_freedom(t):
    cauchy = 2.0 * math.atan2(1.0, t) / math.pi              # df = 1: 1 - 2 atan(t) / pi
    s = math.sqrt(2.0 + t * t)
    two = 2.0 / (s * (s + t))                                # df = 2: 1 - t / sqrt(2 + t^2)
    for df, want in ((1.0, cauchy), (2.0, two)):
        assert t_two_sided(t, df) == pytest.approx(want, rel=1e-14, abs=0), (t, df)


def test_near_the_continued_fractions_switch_it_stays_accurate():
    """x = (a + 1)/(a + b + 2), where the continued fraction changes side: t ~ 1.73 at large df."""
    for df in (1e3, 66666.3, 1e6):
        for k in range(60):
            t = 1.0 + 0.02 * k
            assert t_two_sided(t, df) == pytest.approx(float(2.0 * stdtr(df, -t)), rel=1e-13 + 1e-16 * df)


def test_what_is_not_a_t_distribution_is_refused():
    with pytest.raises(ValueError):
        t_two_sided(1.0, 0.0)
    with pytest.raises(ValueError):
        t_two_sided(float("nan"), 3.0)
    assert t_two_sided(float("inf"), 3.0) == 0.0
