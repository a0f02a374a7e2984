"""Imported curves no driver can give (issue 31): an impedance that gives out energy (Re(Z) < 0, phase beyond
±90°) or has no resonance (a resistor) is red with its likely cause, and its parameters are withheld, not
reported as a driver's. Real drivers' curves (measured by others, when present) and catalogue drivers with
odd physics and noise stay free of these findings."""
import numpy as np
import pytest

from analysis.curves import passivity
from analysis.curves.fitting import curve_json, fit_curves
from analysis.importers import read_curve, read_uiv
from analysis.spectra import TransferFunction
from tests.analysis.curves.test_fitting import FREQS, curve
from tests.builders import DRIVERS, REAL_DATA, electrical

LOW_Q = electrical(5.7, 0.4e-3, 15e-3, 0.84e-3, 15.0, 7.0, L2=0.6e-3, R2=8.0, **{"lambda": 0.12})


def _codes(result) -> set[str]:
    return {f["code"] for ch in result.validity.as_json().get("channels", {}).values() for f in ch["findings"]}


def _impedance(values, noise=0.003, **kw) -> TransferFunction:
    """A driver's impedance with 0.3 % noise on each line."""
    return curve(values, "impedance", noise=noise, **kw)


@pytest.mark.parametrize("name", [*DRIVERS, "low-q"])
def test_drivers_2_to_18_inch_and_a_low_q_one_are_passive_with_a_resonance(name):
    z = _impedance(LOW_Q if name == "low-q" else DRIVERS[name])
    assert passivity.passivity_findings(z) == []


@pytest.mark.parametrize("where", ["seas_l16rnx/L16RNX_0g_242_27mV.zma", "seas_l16rnx/L16RNX_16_048g_242_27mV.zma",
                                   "dayton_ls10-44/test_impedance.txt",
                                   "woofer_uiv_laser/meas_data_UIV_spectra_1Hz-10kHz.csv"])
def test_real_drivers_curves_are_passive_with_a_resonance(where):
    path = REAL_DATA / where
    if not path.is_file():
        pytest.skip(f"{where}: the real data set (tests.builders.REAL_DATA) is not on this machine")
    z = read_uiv(path).impedance if path.suffix == ".csv" else read_curve(path, "impedance").transfer
    assert passivity.passivity_findings(z) == []


def _red(z, hx=None):
    result = fit_curves(z, hx)
    found = result.validity.as_json()["channels"]["impedance"]["findings"]
    assert result.validity.overall == "red" and all(f["severity"] == "red" for f in found)
    assert all(p.value is None and "no driver's" in p.reason for p in result.parameters.values())
    doc = curve_json(result)
    assert doc["parameters"]["fs"]["value"] is None and doc["validity"]["overall"] == "red"
    return {f["code"]: f for f in found}


def test_an_impedance_measured_with_the_current_reversed_is_red_and_says_so():
    z = _impedance(DRIVERS["paper"])
    found = _red(TransferFunction(z.name, z.unit, z.freqs, z.bins, -z.value, z.std, True, False))
    assert "current was measured the wrong way round" in found[passivity.NOT_PASSIVE]["remedy"]


def test_an_impedance_with_a_channel_delay_left_in_is_red_and_says_so():
    z = _impedance(DRIVERS["midwoofer-6in"])
    late = z.value * np.exp(-2j * np.pi * z.freqs * 100e-6)           # 100 µs: 90° at 2.5 kHz
    found = _red(TransferFunction(z.name, z.unit, z.freqs, z.bins, late, z.std, True, False))
    assert "delay between the voltage and the current" in found[passivity.NOT_PASSIVE]["remedy"]
    assert abs(found[passivity.NOT_PASSIVE]["value"]) > 90


@pytest.mark.parametrize("ohm, henry", [(8.0, 0.0), (3.3, 0.05e-3), (6.8, 0.5e-3)])
def test_a_resistor_given_as_a_driver_is_red_not_a_driver_with_an_fs(ohm, henry):
    rng = np.random.default_rng(3)
    value = (ohm + 2j * np.pi * FREQS * henry) * (1 + 0.003 * (rng.standard_normal(FREQS.size)
                                                               + 1j * rng.standard_normal(FREQS.size)))
    z = TransferFunction("impedance", "ohm", FREQS, np.arange(FREQS.size), value, np.full(FREQS.size, np.nan),
                         True, False)
    found = _red(z)
    assert set(found) == {passivity.NO_RESONANCE}
    assert "resistor" in found[passivity.NO_RESONANCE]["remedy"]


def test_a_curve_that_starts_above_the_resonance_says_so():
    freqs = FREQS[FREQS > 4 * 27.0]                     # the paper driver's fs is about 27 Hz
    z = _impedance(DRIVERS["paper"], freqs=freqs)
    found = _red(z)
    assert "resonance lies below the curve" in found[passivity.NO_RESONANCE]["message"]
