"""Large-signal identification (analysis.large_signal) against the nonlinear simulator's known curves.

The issue's case: Bl(x) = Bl (1 - 0.03 x - 0.01 x^2), Kms(x) = Kms (1 + 0.04 x
+ 0.05 x^2), x in mm, the paper's driver otherwise (without creep: the
simulator's creep acts on its small-signal part only, which no large-signal
model can match), the project multitone to about +-4 mm, 4 periods of 16,384
samples and the bench's sensor noise.
"""
from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from analysis.large_signal import LargeSignalError, LimitThresholds, Prediction, large_signal
from analysis.large_signal.data import recording_data
from analysis.large_signal.distortion import harmonics, recording_fit
from analysis.large_signal.trust import delay_doubtful, delay_not_found
from analysis.large_signal.words import format_large_signal
from analysis.recording.format import make_recording
from tests.large_signal_truth import (KNOWN_LEVEL_V, KNOWN_OFFSET_M, KNOWN_X_BL_M, clean_periods, inner,
                                      known_driver, noisy_recording, relative_errors)

PERIOD = 16384


@pytest.fixture(scope="module")
def known():
    driver = known_driver(PERIOD)
    block, mt = clean_periods(driver, KNOWN_LEVEL_V, 4)
    prediction = Prediction(6.0, sine_hz=40.0, two_tones_hz=(30.0, 500.0))
    return driver, block, mt, large_signal([noisy_recording(block, mt)], predictions=[prediction])


def test_the_issues_known_polynomials_come_back(known, record_property):
    driver, _, _, result = known
    lo, hi = result.model.x_range
    assert lo < -3.5e-3 and hi > 3.5e-3                          # "a multitone to about +-4 mm"
    for name in ("Bl", "Kms"):
        worst, at_rest = relative_errors(result.model, driver, name)
        record_property(f"{name}_worst_error_80_percent", worst)
        record_property(f"{name}_0_error", at_rest)
        assert worst < 0.03, name
        assert abs(at_rest) < 0.01, name
    offset, x_bl = result.derived.offset_m, result.derived.limits["X_Bl"]
    record_property("offset_m", offset)
    record_property("X_Bl_m", x_bl.value)
    assert offset == pytest.approx(KNOWN_OFFSET_M, abs=1e-4)
    assert x_bl.value == pytest.approx(KNOWN_X_BL_M, abs=1e-4) and not x_bl.beyond_range
    assert "move the coil 1.50 mm in" in result.derived.coil_advice()


def test_the_inductance_and_the_constants_come_back_and_no_term_is_invented(known):
    driver, _, _, result = known
    x = inner(result.model.x_range)
    assert np.max(np.abs(result.model.Le(x) / driver.le(x) - 1.0)) < 0.01
    for name, truth in (("RE", driver.values["RE"]), ("Mms", driver.values["CMES"] * driver.values["Bl"] ** 2),
                        ("R2", driver.values["R2"])):
        assert result.model.value(name) == pytest.approx(truth, rel=0.005), name
    orders = result.identification.orders
    assert orders.le_i == 0 and not orders.rms_v and not orders.creep      # absent from the truth: BIC leaves them
    assert result.derived.asymmetry_percent > 0        # Kms rises faster outwards (0.04 x)


def test_every_term_the_simulator_has_is_found_when_present():
    """Le(x), L2(x), Le(i) and Rms(v) on as well: each is kept by BIC and near its truth. A quarter step for the
    simulator's nonlinear part: at one step per sample its error at 10 kHz (where Le(x) and L2(x) act) is a few
    % of the nonlinear part."""
    driver = known_driver(8192, substeps=4, le_poly=(-20.0, 2e3), l2_poly=(-30.0, 2e3),
                          le_i_poly=(0.0, -0.004), rms_v2=0.15, i_range_a=5.0)
    block, mt = clean_periods(driver, KNOWN_LEVEL_V, 4)
    result = large_signal([noisy_recording(block, mt)])
    model, orders = result.model, result.identification.orders
    x = inner(model.x_range)
    assert orders.le_i >= 1 and orders.rms_v and orders.l2 >= 1
    for name, truth in (("Bl", driver.bl), ("Kms", driver.kms), ("Le", driver.le), ("L2", driver.l2)):
        assert np.max(np.abs(model.curves[name](x) / truth(x) - 1.0)) < 0.02, name
    le0, rms0 = driver.values["LE"], driver.values["Bl"] ** 2 / driver.values["RES"]
    assert model.value("q2") == pytest.approx(-0.004 * le0, rel=0.2)
    assert model.value("r") == pytest.approx(0.15 * rms0, rel=0.2)


@pytest.mark.slow
def test_the_two_sigma_band_holds_the_truth_at_90_percent_of_the_points_over_20_noise_seeds(record_property):
    """20 noise realisations on one simulated signal (8,192-sample periods, 4 of them: ~1 s each). The nonlinear
    part is stepped 8 times per sample, so that the simulator's own error stays below the noise."""
    driver = known_driver(8192, substeps=8)
    block, mt = clean_periods(driver, 8.0, 4)
    inside = {"Bl": [], "Kms": [], "Le": []}
    for seed in range(20):
        result = large_signal([noisy_recording(block, mt, seed=seed)])
        x = np.linspace(*result.model.x_range, 41)
        for name, truth in (("Bl", driver.bl), ("Kms", driver.kms), ("Le", driver.le)):
            curve = result.model.curves[name]
            inside[name].append(np.abs(curve(x) - truth(x)) <= 2.0 * curve.sigma(x))
    coverage = {name: float(np.mean(hits)) for name, hits in inside.items()}
    for name, value in coverage.items():
        record_property(f"coverage_{name}", value)
    assert coverage["Bl"] >= 0.9 and coverage["Kms"] >= 0.9 and coverage["Le"] >= 0.9, coverage


def test_the_distortion_predicted_at_a_second_level_is_the_simulators_within_1_db(known, record_property):
    """Identified at 10.5 V, predicted at 6 V: a 40 Hz sine's H2 and H3 of the current (against the simulator
    driven by the same sine), and the multitone's distortion of current and displacement (against a simulated
    recording at 6 V)."""
    driver, _, _, result = known
    sine = harmonics(result.model, 40.0, 6.0, period=PERIOD)
    k = int(round(sine["frequency_hz"] * PERIOD / 48000))
    u = 6.0 * np.sqrt(2.0) * np.sin(2 * np.pi * k * np.arange(PERIOD) / PERIOD)
    driver.reset()
    current = driver.process(np.tile(u, 3)).current[-PERIOD:]
    spectrum = np.abs(np.fft.rfft(current))
    for h in (2, 3):
        simulated = 20 * np.log10(spectrum[h * k] / spectrum[k])
        predicted = sine["current"][f"H{h}_db"]
        record_property(f"H{h}_current_difference_db", predicted - simulated)
        assert predicted == pytest.approx(simulated, abs=1.0), h
    block, mt = clean_periods(driver, 6.0, 4)
    fit = recording_fit(result.model, recording_data(noisy_recording(block, mt, seed=5)), 0.0, 0.0)
    for channel in fit.channels.values():
        assert channel.predicted_db == pytest.approx(channel.measured_db, abs=1.0), channel.channel
        assert channel.explained_percent > 90.0


def serial_laser_recording(delay_s: float):
    """The known driver at 8 V as the serial laser gives it: the displacement's mean removed (the cone's shift
    under drive is lost with it) and ``delay_s`` late; the sidecar marks the laser's band."""
    driver = known_driver(8192)
    block, mt = clean_periods(driver, 8.0, 4)
    rec = noisy_recording(block, mt)
    n = mt.period_samples
    s = 2j * np.pi * np.fft.rfftfreq(n, 1 / 48000)
    x = rec.signal("displacement").reshape(-1, n)
    late = np.fft.irfft(np.fft.rfft(x, axis=1) * np.exp(-s * delay_s), n, axis=1).ravel()
    late -= late[2 * n:].mean()
    signals = {"voltage": rec.signal("voltage"), "current": rec.signal("current"), "displacement": late}
    laser = make_recording(48000, signals, n, 2, rec.excited_bins, driver=dict(rec.driver),
                           extra={"displacement_max_hz": 1760.0})
    return driver, block, laser


@pytest.mark.parametrize("band", ["fast", -1760.0, 5e6])
def test_a_laser_band_that_is_no_frequency_is_one_line_as_the_spectra_say_it(band):
    """The large-signal data read the sidecar's displacement_max_hz with the spectra's rule (analysis.spectra)."""
    _driver, _block, laser = serial_laser_recording(0.0)
    laser = dataclasses.replace(laser, extra={**laser.extra, "displacement_max_hz": band})
    with pytest.raises(LargeSignalError, match="displacement_max_hz .*: found .*, expected a frequency"):
        recording_data(laser, "r1")


def test_an_unknown_rest_position_and_a_late_laser_are_found():
    """The serial laser 80 us late, its mean removed: both found, and the result trusted."""
    driver, block, laser = serial_laser_recording(80e-6)
    n = laser.period_samples
    result = large_signal([laser])
    ident = result.identification
    assert ident.delays[0] == pytest.approx(80e-6, abs=1e-6)
    # Its 1-sigma is the search's resolution (0.2 us / sqrt 3): the noise's own is ~2 ns, the lines are sharp.
    assert 1e-7 < ident.delays_std[0] < 2e-7 and not ident.delay_at_limit(0)
    # The electrical equation stops at the laser's band too: beyond it, the back-EMF Bl(x) v is not measured.
    assert ident.data[0].electrical_bins[-1] == ident.data[0].mechanical_bins[-1] < ident.data[0].excited_bins[-1]
    recording = result.as_json()["validity"]["recordings"][0]
    assert recording["laser_delay_std_s"] == ident.delays_std[0] and recording["laser_delay_at_limit"] is False
    # Found: the model leaves the noise (~1 against the lines' noise alone), and nothing says otherwise.
    assert recording["laser_delay_found"] is True and result.verdict != "red"
    assert recording["noise_chi2_red"]["electrical"] < 3.0 and ident.voltage_residual_percent[0] < 1.0
    assert "NOT TO BE TRUSTED" not in format_large_signal(result)
    assert delay_not_found(ident, 0) is None and delay_doubtful(ident, 0) is None
    # The rule on the misfits the in-process rig left at 1 and 2 ms link latency (docs/large-signal.md): 1.9 % of
    # the voltage at 2.5e5 times the noise (a delay ~100 us short) a doubt, 44 % at 1.8e8 times not found.
    short = dataclasses.replace(ident, voltage_residual_percent=(1.9,),
                                noise_chi2_red=({"electrical": 2.5e5, "mechanical": 1.0},))
    assert delay_not_found(short, 0) is None and "the delay may be off" in delay_doubtful(short, 0)
    wrong = dataclasses.replace(short, voltage_residual_percent=(44.0,),
                                noise_chi2_red=({"electrical": 1.8e8, "mechanical": 1.0},))
    assert "the laser's delay was not found" in delay_not_found(wrong, 0) and delay_doubtful(wrong, 0) is None
    shift = float(block.displacement[2 * n:].mean())          # what the mean removal took away
    assert ident.offsets[0] == pytest.approx(shift, abs=2e-6)         # x = x_measured + offset
    assert result.derived.offset_m == pytest.approx(KNOWN_OFFSET_M, abs=1e-4)
    x = inner(result.model.x_range)
    assert np.max(np.abs(result.model.Bl(x) / driver.bl(x) - 1.0)) < 0.03


def test_a_laser_4_ms_late_is_placed_from_the_small_signal_model_and_trusted():
    """4 ms late, beyond the +-1 ms search around zero: the search is centred where the linear model places the
    delay (delay_start.py), so it is found and nothing says the delay is doubtful."""
    _, _, laser = serial_laser_recording(4e-3)
    result = large_signal([laser])
    ident = result.identification
    assert ident.delays[0] == pytest.approx(4e-3, abs=1e-6) and not ident.delay_at_limit(0)
    assert ident.voltage_residual_percent[0] < 1.0
    assert not any("delay" in flag for flag in result.flags)


def test_a_laser_delay_not_found_makes_the_result_red_where_the_user_reads_it():
    """80 ms late, beyond every search (-10 ... +40 ms): the search settles in a wrong valley inside its range,
    not on the limit, and Bl(0) comes out ~0, which must never read as a measurement. The weighted chi^2 stays
    low (its weights count the misfit as noise); against the noise alone the electrical equation misses the
    voltage by ~1e9 times it (trust.py)."""
    _, _, laser = serial_laser_recording(80e-3)
    result = large_signal([laser])
    ident = result.identification
    assert not ident.delay_at_limit(0)
    assert ident.voltage_residual_percent[0] > 50.0 and ident.noise_chi2_red[0]["electrical"] > 1e4
    assert result.verdict == "red"
    assert "the laser's delay was not found" in result.flags[0] and "measure again" in result.flags[0]
    validity = result.as_json()["validity"]
    assert validity["verdict"] == "red" and validity["recordings"][0]["laser_delay_found"] is False
    assert "NOT TO BE TRUSTED" in format_large_signal(result)


def test_the_json_is_the_contract_with_polynomials_ascending_in_metres(known):
    _, _, _, result = known
    doc = json.loads(json.dumps(result.as_json(), allow_nan=False))
    assert doc["x_unit"] == "m"
    assert set(doc["curves"]) >= {"Bl", "Kms", "Le"}
    units = {"Bl": "T*m", "Kms": "N/m", "Le": "H"}
    for name, unit in units.items():
        curve = doc["curves"][name]
        assert curve["unit"] == unit and len(curve["std"]) == len(curve["coefficients"])
        lo, hi = curve["x_range"]
        x = 0.5 * hi
        by_hand = sum(c * x**k for k, c in enumerate(curve["coefficients"]))
        assert by_hand == pytest.approx(float(result.model.curves[name](x)), rel=1e-12)
    assert doc["offset_m"] == pytest.approx(KNOWN_OFFSET_M, abs=1e-4)
    assert doc["limits"]["X_Bl"]["criterion"] == "Bl >= 82 %"
    assert set(doc["limits"]) == {"X_Bl", "X_C", "X_L"}
    assert {"electrical", "mechanical"} <= set(doc["model"]["chi2_red"])
    assert doc["validity"]["recordings"][0]["channels"]["current"]["explained_percent"] > 90


def test_thresholds_are_settable_and_move_the_limits(known):
    driver, _, _, result = known
    from analysis.large_signal.limits import derived
    stricter = derived(result.model, LimitThresholds(bl_ratio=0.9))
    assert stricter.limits["X_Bl"].criterion == "Bl >= 90 %"
    # Bl / Bl(0) = 1 - 0.03 x - 0.01 x^2 = 0.9 at x = 2.0 mm
    assert stricter.limits["X_Bl"].value == pytest.approx(2.0e-3, abs=1e-4)
    with pytest.raises(ValueError, match="bl_ratio"):
        LimitThresholds(bl_ratio=1.5)


def test_a_covariance_the_fit_could_not_give_leaves_the_limits_uncertainty_unknown(known):
    """A fit that ends with NaN in a curve's covariance (seen once on a loaded rig) must not crash the limits:
    their values stand, their 1-sigma are unknown (NaN, written as null), never zero."""
    _, _, _, result = known
    from analysis.large_signal.limits import derived
    broken_bl = dataclasses.replace(result.model.Bl, cov=np.full_like(result.model.Bl.cov, np.nan))
    out = derived(dataclasses.replace(result.model, curves={**result.model.curves, "Bl": broken_bl}))
    assert out.limits["X_Bl"].value == pytest.approx(derived(result.model).limits["X_Bl"].value)
    assert np.isnan(out.limits["X_Bl"].std) and np.isnan(out.offset_std)


def test_predictions_at_a_chosen_level(known):
    _, _, _, result = known
    prediction = result.predictions[0]
    assert prediction["multitone"]["peak_displacement_m"] < result.model.x_range[1]
    assert prediction["sine"]["current"]["H3_db"] < -10 and prediction["two_tones"]["current"]["IMD2_db"] < 0


def test_recordings_that_cannot_serve_are_refused_in_one_line(known):
    _, block, mt, _ = known
    good = noisy_recording(block, mt)
    no_laser = make_recording(48000, {"voltage": good.signal("voltage"), "current": good.signal("current")},
                              good.period_samples, 2, good.excited_bins)
    with pytest.raises(LargeSignalError, match="no displacement"):
        large_signal([no_laser])
    with pytest.raises(LargeSignalError, match="different drivers"):
        large_signal([good, noisy_recording(block, mt, driver_name="another")])
    with pytest.raises(LargeSignalError, match="order"):
        large_signal([good], max_order=12)
    with pytest.raises(LargeSignalError, match="at least one"):
        large_signal([])
