"""A refit the model lab's checkboxes ask for reaches what the model's own start reaches (`linpar analyze --model`),
also from a version whose values the physics it lacks has bent."""
from __future__ import annotations

import pytest

from analysis.diagnosis.noise_floor import channels_at_noise
from analysis.diagnosis.refit import refit, warm_start
from analysis.effects import parse_effects
from analysis.fit import FitData, fit_model
from analysis.model import Model
from analysis.spectra import estimate_spectra
from tests.builders import PAPER, TYPICAL_NOISE, recording

# Physics of the catalogue the version lacks, with the seed of a recording on which the version's values alone
# led the refit astray (reduced chi^2 1.5e5 and 1.7e5 where the model's own start reaches 1.01 and 1.04).
CASES = {
    "bl-eddy": ({"dBl": 0.15, "f_Bl": 2000.0}, 3),
    "breakup": ({"f2": 1500.0, "Q2": 8.0, "mu2": 0.1}, 0),
}


def _data(effect_id: str) -> FitData:
    extra, seed = CASES[effect_id]
    truth = recording({**PAPER.parameters, **extra}, f"lr2,creep-log,{effect_id}", noise=TYPICAL_NOISE, seed=seed)
    return FitData.from_spectra(estimate_spectra(truth))


@pytest.mark.parametrize("effect_id", sorted(CASES))
def test_checking_the_effect_the_data_have_reaches_the_noise_as_the_models_own_start_does(effect_id):
    data = _data(effect_id)
    version = fit_model(data, Model(parse_effects("lr2,creep-log")))
    model = Model(parse_effects(f"lr2,creep-log,{effect_id}"))
    refitted = refit(data, model, version)
    assert refitted.model.effect_ids == model.effect_ids
    assert refitted.chi2 == pytest.approx(fit_model(data, model).chi2, rel=0.01)
    assert channels_at_noise(refitted), refitted.chi2_red_by_channel()


def test_a_version_far_from_the_data_is_refitted_from_the_models_own_start_too():
    """The version's values 50 % off (its fit stopped after one step): from them the refit ends at a reduced
    chi^2 of 8e6; from the model's own start at the noise."""
    data = _data("bl-eddy")
    lacking = Model(parse_effects("lr2,creep-log"))
    fitted = fit_model(data, lacking)
    off = fit_model(data, lacking, start={name: 1.5 * value for name, value in fitted.values.items()},
                    per_parameter=1)
    model = Model(parse_effects("lr2,creep-log,bl-eddy"))
    assert fit_model(data, model, start=warm_start(data, model, off)).chi2_red > 100       # the premise
    assert refit(data, model, off).chi2 == pytest.approx(fit_model(data, model).chi2, rel=0.01)


def test_the_new_effect_starts_from_its_guess_and_the_rest_from_the_version():
    data = _data("bl-eddy")
    version = fit_model(data, Model(parse_effects("lr2,creep-log")))
    start = warm_start(data, Model(parse_effects("lr2,creep-log,bl-eddy")), version)
    assert {name: start[name] for name in version.values} == version.values
    assert {"dBl", "f_Bl"} <= set(start)
