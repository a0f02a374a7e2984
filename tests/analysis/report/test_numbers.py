"""Numbers for people (analysis.report.numbers): a parameter the data do not determine is not printed as a number,
and the relative column reads alike on every row."""
import pytest

from analysis.derived import ParameterValue
from analysis.report.numbers import NOT_DETERMINED, determined, parameter_cells


def _p(name, value, std, display_unit="-", scale=1.0):
    return ParameterValue(name=name, value=value, std=std, unit="SI", display_unit=display_unit, display_scale=scale)


@pytest.mark.parametrize("p, cells", [
    # The imported Dayton curve: "Qms 6 25 440 %" and "Le 3.5 3.5 mH 100 %" on the customer's page.
    (_p("Qms", 5.65, 24.9), (NOT_DETERMINED, "25", "", "440 %")),
    (_p("LE", 3.5e-3, 3.5e-3, "mH", 1e3), (NOT_DETERMINED, "3.5", "mH", "100 %")),
    (_p("Rms", 2.6, 1.9, "kg/s"), ("2.6", "1.9", "kg/s", "73 %")),          # 73 %: poorly known, but known
])
def test_a_sigma_as_large_as_the_value_reads_not_determined(p, cells):
    assert parameter_cells(p) == cells
    assert determined(p) == (cells[0] != NOT_DETERMINED)


def test_levels_and_given_values_are_never_judged_by_a_relative_sigma():
    assert determined(_p("sensitivity", 0.4, 0.6, "dB SPL"))       # a level in dB has no relative uncertainty
    assert determined(_p("Sd", 0.0133, None, "cm²", 1e4))          # given, not measured


def test_the_relative_column_keeps_two_digits_on_every_row():
    """The U/I/V woofer's Mms read "3 %" beside Cms' "2.8 %"."""
    cells = [parameter_cells(_p("Mms", 11.81e-3, 0.3535e-3, "g", 1e3))[3],
             parameter_cells(_p("Cms", 0.0837e-3, 0.0023e-3, "mm/N", 1e3))[3],
             parameter_cells(_p("Bl", 10.799, 0.091, "T*m"))[3]]
    assert cells == ["3.0 %", "2.7 %", "0.84 %"]
