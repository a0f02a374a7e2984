"""A curve the model misses by more than QA's fit-error tolerance is yellow where the result is read
(analysis.curves.misfit), not "validity: unknown"."""
import dataclasses

import numpy as np
import pytest

from analysis.curves.fitting import curve_json, fit_curves
from analysis.validity.findings import MODEL_MISFIT
from analysis.validity.fit import CURVES_MISFIT_REMEDY
from analysis.importers import read_uiv
from tests.analysis.curves.test_fitting import curve
from tests.builders import DRIVERS, REAL_DATA


def _misfits(result) -> dict:
    return {f.channel: f for f in result.validity.findings if f.code == MODEL_MISFIT}


def test_an_impedance_whose_phase_was_read_in_the_wrong_unit_is_yellow_with_the_remedy():
    """Radians read as degrees: the phase 57 times too small, the curve no driver's model can follow."""
    z = curve(DRIVERS["paper"], "impedance", noise=0.003, seed=3)
    wrong = np.abs(z.value) * np.exp(1j * np.angle(z.value) * np.pi / 180)
    result = fit_curves(dataclasses.replace(z, value=wrong))
    found = _misfits(result)["impedance"]
    assert result.validity.overall == "yellow" and found.remedy == CURVES_MISFIT_REMEDY
    assert found.value > 5.0 and "tolerance 5 %" in found.message
    assert curve_json(result)["validity"]["overall"] == "yellow"
    right = fit_curves(z)
    assert _misfits(right) == {} and right.validity.overall == "unknown"


def test_the_real_woofers_laser_fitted_from_below_its_sweep_is_yellow():
    """Its sweep started at 5 Hz; the file holds lines from 1 Hz, and the displacement misses by ~26 %."""
    path = REAL_DATA / "woofer_uiv_laser/meas_data_UIV_spectra_1Hz-10kHz.csv"
    if not path.is_file():
        pytest.skip("the real data set (tests.builders.REAL_DATA) is not on this machine")
    curves = read_uiv(path)
    result = fit_curves(curves.impedance, curves.displacement)
    assert set(_misfits(result)) == {"displacement"} and result.validity.overall == "yellow"
    assert "the model misses this curve by" in result.report()
