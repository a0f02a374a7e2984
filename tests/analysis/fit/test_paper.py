"""The seed paper's two-step identification, chosen by name: right where the model holds, honest sigmas."""
import numpy as np
import pytest

from analysis.curves.fitting import FitRange, fit_curves
from analysis.errors import LinparError
from analysis.fit.methods import METHODS, UnknownMethodError, check_method
from analysis.pipeline import analyze_recording, result_json
from tests.analysis.curves.test_fitting import curve
from tests.builders import PAPER, TYPICAL_NOISE, recording

FITTED = ("RE", "LE", "L2", "R2", "CMES", "LCES", "RES", "Bl", "lambda")


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_paper_method_finds_the_truth_within_its_uncertainty(seed):
    result = analyze_recording(recording(noise=TYPICAL_NOISE, seed=seed), method="paper")
    fit = result.fit
    assert fit.method == "paper" and result_json(result)["model"]["method"] == "paper"
    for name in FITTED:
        truth = PAPER.parameters[name]
        assert fit.stderr[name] is not None and fit.stderr[name] < 0.02 * truth, name
        assert abs(fit.values[name] - truth) < 3.5 * fit.stderr[name], (name, fit.values[name], truth)
    assert max(fit.chi2_red_by_channel().values()) < 2.5     # each step's misfit at the noise


def test_each_step_fits_its_own_channel():
    fit = analyze_recording(recording(noise=TYPICAL_NOISE, seed=4), method="paper").fit
    assert "Z step" in fit.message and "Hx step" in fit.message
    # Bl carries the Z step's uncertainty too: never tighter than the joint fit's
    joint = analyze_recording(recording(noise=TYPICAL_NOISE, seed=4)).fit
    assert fit.stderr["Bl"] >= 0.9 * joint.stderr["Bl"]


def test_the_paper_method_on_magnitude_only_curves():
    values = PAPER.parameters
    result = fit_curves(curve(values, "impedance", phase=False), curve(values, "displacement", phase=False),
                        "lr2,creep-log", 0.0133, FitRange(hx_f_max=1e5), method="paper")
    assert result.fit.method == "paper"
    for name in ("RE", "Bl", "CMES", "LCES", "RES", "lambda"):
        assert result.fit.values[name] == pytest.approx(values[name], rel=1e-4), name


def test_without_the_laser_the_paper_method_is_the_impedance_fit():
    result = analyze_recording(recording(noise=TYPICAL_NOISE, seed=5, displacement=False), method="paper")
    assert result.parameters["Bl"].value is None
    assert result.parameters["fs"].value == pytest.approx(
        1 / (2 * np.pi * np.sqrt(PAPER.parameters["CMES"] * PAPER.parameters["LCES"])), rel=0.01)


def test_an_unknown_method_is_named_with_the_known_ones():
    assert check_method("paper") == "paper"
    with pytest.raises(UnknownMethodError, match="joint, paper") as info:
        check_method("magic")
    assert isinstance(info.value, LinparError)
    assert tuple(METHODS) == ("joint", "paper", "alternating")
