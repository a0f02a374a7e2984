"""Numbers fitted to imported curves that no driver has (analysis.curves.plausible_numbers): a plain |Hx| table in
mm/V read as m/V is red with the remedy that mends it, not printed as a result beside "validity: unknown"."""
import dataclasses

import pytest

from analysis.curves.fitting import curve_json, fit_curves
from analysis.curves.plausible_numbers import HX_SCALE
from analysis.importers import read_uiv
from analysis.validity.plausibility import EFFICIENCY, MASS_PER_AREA
from tests.analysis.curves.test_fitting import curve
from tests.builders import DRIVERS, REAL_DATA

SD_M2 = 0.0133          # the paper driver's cone


def _curves(hx_scale: float, phase: bool):
    values = DRIVERS["paper"]
    z = curve(values, "impedance", phase=phase, noise=0.003, seed=1)
    hx = curve(values, "displacement", phase=phase, noise=0.003, seed=2)
    return z, dataclasses.replace(hx, value=hx.value * hx_scale)


@pytest.mark.parametrize("phase", [True, False])
def test_an_hx_curve_in_mm_per_volt_read_as_m_per_volt_is_red_and_names_the_option(phase):
    result = fit_curves(*_curves(1e3, phase), sd_m2=SD_M2)
    doc = curve_json(result)
    assert doc["validity"]["overall"] == "red"
    found = {f["code"]: f for f in doc["validity"]["channels"]["displacement"]["findings"]}
    assert {MASS_PER_AREA, EFFICIENCY} <= set(found)
    assert all(f["remedy"] == HX_SCALE and "--mm-per-volt" in f["remedy"] for f in found.values())
    assert "validity: red" in result.report() and "--mm-per-volt" in result.report()


@pytest.mark.parametrize("phase", [True, False])
def test_the_same_curves_in_their_unit_are_not_judged_for_their_numbers(phase):
    result = fit_curves(*_curves(1.0, phase), sd_m2=SD_M2)
    assert result.validity.overall == "unknown" and "displacement" not in result.validity.channels


def test_the_real_woofers_uiv_spectra_hold_numbers_a_driver_has_and_in_mm_do_not():
    """A woofer measured by others (no Sd known: the moving mass alone is judged): its spectra as they are hold a
    driver's numbers; the same laser read 1000 times too large gives a cone of milligrams."""
    path = REAL_DATA / "woofer_uiv_laser/meas_data_UIV_spectra_1Hz-10kHz.csv"
    if not path.is_file():
        pytest.skip("the real data set (tests.builders.REAL_DATA) is not on this machine")
    curves = read_uiv(path)
    result = fit_curves(curves.impedance, curves.displacement)
    assert result.validity.overall != "red"
    assert not {f.code for f in result.validity.findings} & {MASS_PER_AREA, EFFICIENCY}
    hx = dataclasses.replace(curves.displacement, value=curves.displacement.value * 1e3)
    result = fit_curves(curves.impedance, hx)
    (found,) = [f for f in result.validity.findings if f.code == MASS_PER_AREA]
    assert result.validity.overall == "red" and found.remedy == HX_SCALE
