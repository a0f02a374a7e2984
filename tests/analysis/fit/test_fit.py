"""The fit recovers known parameters, and its uncertainties are honest."""
import threading

import numpy as np
import pytest

from analysis.effects import parse_effects
from analysis.fit.least_squares import FitCancelled, FitData, fit_model
from analysis.model.composed import Model
from analysis.spectra import estimate_spectra
from analysis.synthesis import ChannelNoise
from tests.builders import DRIVERS, PAPER, TYPICAL_NOISE, multitone, recording


def _fit(rec, effects="lr2,creep-log", displacement=True):
    data = FitData.from_spectra(estimate_spectra(rec))
    return fit_model(data, Model(parse_effects(effects), with_displacement=displacement))


@pytest.mark.parametrize("effects", ["lr2,creep-log", "lr2", "none"])
def test_noise_free_data_recover_every_parameter_to_1e6(effects):
    model = Model(parse_effects(effects))
    truth = {p.name: PAPER.parameters[p.name] for p in model.param_specs}
    result = _fit(recording(truth, effects, n_periods=2), effects)
    for name, value in truth.items():
        assert result.values[name] == pytest.approx(value, rel=1e-6), name
    assert result.success


def test_noise_free_impedance_only_recovers_the_electrical_parameters():
    model = Model(parse_effects("lr2,creep-log"), with_displacement=False)
    truth = {p.name: PAPER.parameters[p.name] for p in model.param_specs}
    result = _fit(recording(truth, displacement=False, n_periods=2), displacement=False)
    for name, value in truth.items():
        assert result.values[name] == pytest.approx(value, rel=1e-6), name


@pytest.mark.parametrize("driver", sorted(DRIVERS))
def test_fit_converges_from_data_driven_start_values_on_drivers_of_every_size(driver):
    truth = DRIVERS[driver]
    mt = multitone(f_min=3.0, f_max=20000.0)
    result = _fit(recording(truth, mt=mt, noise=TYPICAL_NOISE, seed=5))
    for name, value in truth.items():
        z = (result.values[name] - value) / result.stderr[name]
        assert abs(z) < 4.5, f"{driver} {name}: {result.values[name]} vs {value} ({z:.1f} sigma)"
    assert max(result.chi2_red_by_channel().values()) < 1.5


def test_noisy_fits_scatter_as_their_reported_standard_errors_over_20_seeds():
    mt = multitone(period_samples=8192, f_min=5, f_max=10000)
    noise = ChannelNoise(voltage=3e-4, current=3e-4, displacement=3e-8)
    names = list(PAPER.parameters)
    values, errors = [], []
    for seed in range(20):
        result = _fit(recording(mt=mt, noise=noise, n_periods=8, seed=100 + seed))
        values.append([result.values[n] for n in names])
        errors.append([result.stderr[n] for n in names])
    values, errors = np.array(values), np.array(errors)
    truth = np.array([PAPER.parameters[n] for n in names])
    z = (values - truth) / errors
    # each parameter within 3 of its reported standard errors (one in 370 may stray: allow 4)
    assert np.all(np.abs(z) < 4.0), dict(zip(names, np.abs(z).max(axis=0)))
    assert np.mean(np.abs(z) > 3) < 0.02
    # the reported standard error agrees with the observed scatter within 30 %
    observed = values.std(axis=0, ddof=1)
    reported = np.sqrt(np.mean(errors**2, axis=0))
    for name, ratio in zip(names, observed / reported):
        assert 0.7 < ratio < 1.3, f"{name}: observed/reported scatter {ratio:.2f}"


def test_reduced_chi2_is_about_one_when_the_model_is_right():
    result = _fit(recording(noise=TYPICAL_NOISE, n_periods=8, seed=1))
    for name, chi2_red in result.chi2_red_by_channel().items():
        assert chi2_red == pytest.approx(1.0, abs=0.2), name


def test_a_missing_effect_shows_in_chi2_and_bic():
    rec = recording(noise=TYPICAL_NOISE, n_periods=8, seed=2)
    full = _fit(rec)
    without_creep = _fit(rec, "lr2")
    assert without_creep.chi2_red_by_channel()["displacement"] > 10 * full.chi2_red_by_channel()["displacement"]
    assert without_creep.bic > full.bic + 100


def test_correlations_come_from_the_jacobian():
    result = _fit(recording(noise=TYPICAL_NOISE, n_periods=8, seed=3))
    corr = result.correlation()
    assert corr.shape == (len(result.varying),) * 2
    np.testing.assert_allclose(np.diag(corr), 1.0)
    assert np.all(np.abs(corr) <= 1.0 + 1e-9)
    i, j = result.varying.index("L2"), result.varying.index("R2")
    assert abs(corr[i, j]) > 0.1   # L2 and R2 trade off against each other


def test_a_cancelled_fit_raises():
    cancel = threading.Event()
    cancel.set()
    data = FitData.from_spectra(estimate_spectra(recording(noise=TYPICAL_NOISE, n_periods=2)))
    with pytest.raises(FitCancelled):
        fit_model(data, Model(parse_effects("lr2,creep-log")), cancel=cancel)
