"""Re against the nominal impedance entered: a remark between what real drivers show (0.6-0.95 times) and what
turns the validity red (outside 0.3-2 times), nothing otherwise."""
import pytest

from analysis.validity.nominal_remark import re_nominal_remark


@pytest.mark.parametrize("re_ohm, nominal, says", [
    (3.0, 8, "a 4 Ω driver entered as 8 Ω"),        # the case: 0.375 times
    (6.2, 8, ""),                                   # 0.78: a real 8 Ω driver
    (3.2, 4, ""),
    (7.8, 8, "reads low"),                          # 0.95 < 0.975 < 2: unusual, a remark
    (2.0, 8, ""),                                   # 0.25: red already (plausibility), no second word on it
    (3.0, None, ""), (3.0, True, ""), (None, 8, ""), (3.0, 0, ""),
])
def test_the_remark(re_ohm, nominal, says):
    remark = re_nominal_remark(re_ohm, nominal)
    assert (says in remark) if says else remark == ""
