"""Fitting imported curves: exact recovery, magnitude-only, ranges, honest uncertainties, the JSON shape."""
import dataclasses

import numpy as np
import pytest

from analysis.curves.fitting import (FitRange, CurveFitError, covariance_with_bounds, curve_data, curve_json,
                                fit_curves, log_thinned, weighted_residual)
from analysis.derived import parameter_table
from analysis.effects import parse_effects
from analysis.importers import read_curve
from analysis.model.composed import Model
from analysis.spectra import TransferFunction
from tests.builders import DRIVERS, PAPER

FREQS = np.logspace(np.log10(5.0), np.log10(20e3), 400)


def curve(values, name, effects="lr2,creep-log", freqs=FREQS, phase=True, noise=0.0, seed=0):
    model = Model(parse_effects(effects))
    s = 2j * np.pi * freqs
    v = model.impedance(s, values) if name == "impedance" else model.displacement(s, values)
    if noise:
        rng = np.random.default_rng(seed)
        v = v * (1 + noise * (rng.standard_normal(len(v)) + 1j * rng.standard_normal(len(v))) / np.sqrt(2))
    if not phase:
        v = np.abs(v).astype(complex)
    n = len(freqs)
    return TransferFunction(name, "ohm" if name == "impedance" else "m/V", freqs, np.arange(n), v,
                            np.full(n, np.nan), phase, False)


def write_zma(path, tf, scale=1.0):
    lines = ["* written by the test", "* Data: Impedance (ohms), Phase (degrees)"]
    lines += [f"{f:.9e} {abs(v) * scale:.12e} {np.degrees(np.angle(v)):.12e}" for f, v in zip(tf.freqs, tf.value)]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("driver", ["paper", "woofer-12in"])
def test_noise_free_curves_give_the_parameters_back(driver):
    values = DRIVERS[driver]
    result = fit_curves(curve(values, "impedance"), curve(values, "displacement"), "lr2,creep-log", 0.0133,
                        FitRange(hx_f_max=1e5))
    for name in ("RE", "Bl", "CMES", "LCES", "RES", "lambda"):
        assert result.fit.values[name] == pytest.approx(values[name], rel=1e-5), name
    assert result.parameters["Vas"].value is not None


def test_a_zma_round_trip(tmp_path):
    values = PAPER.parameters
    path = write_zma(tmp_path / "paper.zma", curve(values, "impedance"))
    z = read_curve(path).transfer
    result = fit_curves(z, None, "lr2,creep-log")
    fs = 1 / (2 * np.pi * np.sqrt(values["CMES"] * values["LCES"]))
    assert result.parameters["fs"].value == pytest.approx(fs, rel=1e-6)
    assert result.parameters["Bl"].value is None and "added-mass" in result.parameters["Bl"].reason


def test_magnitude_only_curves_still_give_the_parameters():
    values = DRIVERS["midwoofer-6in"]
    result = fit_curves(curve(values, "impedance", phase=False), curve(values, "displacement", phase=False),
                        "lr2,creep-log", None, FitRange(hx_f_max=1e5))
    assert result.fit.values["Bl"] == pytest.approx(values["Bl"], rel=1e-3)
    assert result.parameters["Mms"].value == pytest.approx(values["CMES"] * values["Bl"] ** 2, rel=3e-3)
    assert set(result.validity.imported.magnitude_only) == {"impedance", "displacement"}


def test_uncertainties_come_from_the_scatter_and_cover_the_truth():
    values = PAPER.parameters
    pulls = []
    for seed in range(4):
        r = fit_curves(curve(values, "impedance", noise=0.01, seed=seed),
                       curve(values, "displacement", noise=0.01, seed=seed + 100), "lr2,creep-log")
        assert r.fit.chi2_red == pytest.approx(1.0, abs=0.15)      # 1 % noise, estimated from the local scatter
        pulls.append((r.fit.values["Bl"] - values["Bl"]) / r.fit.stderr["Bl"])
    assert np.all(np.abs(pulls) < 4)
    assert "local scatter" in r.validity.imported.uncertainties


def test_ranges_limit_each_channel_and_hx_defaults_to_four_fs():
    values = PAPER.parameters
    r = fit_curves(curve(values, "impedance"), curve(values, "displacement"), "lr2,creep-log", None,
                   FitRange(f_min=10.0, f_max=5000.0))
    fs = 1 / (2 * np.pi * np.sqrt(values["CMES"] * values["LCES"]))
    assert r.ranges["impedance"][0] >= 10.0 and r.ranges["impedance"][1] <= 5000.0
    assert r.ranges["displacement"][1] <= 4 * fs * 1.05 and r.ranges["displacement"][1] > 3.5 * fs
    assert any("4 x fs" in n for n in r.notes)
    with pytest.raises(CurveFitError, match="lines between"):
        fit_curves(curve(values, "impedance"), None, "lr2", None, FitRange(f_min=100.0, f_max=101.0))


def test_linear_grids_are_thinned_log_grids_are_not():
    assert log_thinned(np.arange(1.0, 10001.0), 100).sum() < 300
    assert log_thinned(FREQS, 100).all()
    assert log_thinned(np.arange(1.0, 10001.0), None).all()


def test_a_parameter_on_its_bound_is_held_and_the_others_get_uncertainties():
    # MINPACK gives no covariance when a parameter ends on a bound (the bound transform has zero slope there).
    values = dict(PAPER.parameters)
    z, x = curve(values, "impedance", noise=0.005), curve(values, "displacement", noise=0.005, seed=1)
    fit = fit_curves(z, x, "lr2,creep-log", None, FitRange(hx_f_max=1e5)).fit
    data, _ = curve_data(z, x, FitRange(hx_f_max=1e5))          # the lines and noise the fit saw
    residual = lambda v: weighted_residual(fit.model, v, data)    # noqa: E731
    no_covar = dataclasses.replace(fit, covar=None, stderr={n: None for n in fit.values})
    again, held = covariance_with_bounds(no_covar, residual)      # the Jacobian's covariance is MINPACK's
    assert held == []
    for name in ("Bl", "CMES", "RE", "lambda"):
        assert again.stderr[name] == pytest.approx(fit.stderr[name], rel=0.02), name
    on_bound = dataclasses.replace(no_covar, values={**fit.values, "LE": 0.0})
    fixed, held = covariance_with_bounds(on_bound, residual)
    assert held == ["LE"] and fixed.stderr["LE"] is None
    assert fixed.stderr["Bl"] > 0 and parameter_table(fixed, None)["Mms"].std > 0


def test_covariance_with_bounds_leaves_a_complete_fit_alone():
    z = curve(PAPER.parameters, "impedance", noise=0.01)
    r = fit_curves(z, None, "lr2,creep-log")
    data, _ = curve_data(z)
    same, held = covariance_with_bounds(r.fit, lambda v: weighted_residual(r.fit.model, v, data))
    assert same is r.fit and held == []


def test_the_json_has_the_shape_of_a_recording_analysis():
    values = PAPER.parameters
    doc = curve_json(fit_curves(curve(values, "impedance"), curve(values, "displacement"), "lr2,creep-log", 0.0133))
    assert set(doc) == {"parameters", "model", "validity"}
    assert set(doc["model"]) == {"effects", "method", "chi2_red", "aic", "bic", "n_data", "n_parameters", "converged",
                                "notes"}
    assert doc["validity"]["overall"] == "unknown" and "no per-line noise" in doc["validity"]["note"]
    assert doc["parameters"]["Bl"]["unit"] == "T*m" and doc["parameters"]["Bl"]["std"] >= 0
