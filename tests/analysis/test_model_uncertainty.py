"""The model part of the uncertainty: it covers the truth where the model misses physics, and is 0 where not.

The realistic recordings (tests/realistic_drivers.py) have several physics at once, none in any model's
form; their truth is known. The statistical uncertainty alone leaves the truth 2-8 std away on each of
them (asserted, so the coverage below is no accident of a generous noise); with the model part the truth
of RE, Bl, Mms and Kms lies within 2 reported std.
"""
import math
import threading

import pytest

from analysis.effects import parse_effects
from analysis.fit import FitCancelled
from analysis.model import Model
from analysis.model_uncertainty import alternative_models, describes_the_data, model_uncertainty
from analysis.pipeline import analyze_recording
from tests.builders import TYPICAL_NOISE, recording
from tests.realistic_drivers import REALISTIC, realistic_recording

LUMPED = ("RE", "Bl", "Mms", "Kms")


def z_score(p, truth):
    return math.inf if not p.std else (p.value - truth) / p.std


@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("name", sorted(REALISTIC))
def test_the_truth_lies_within_two_reported_std_on_realistic_recordings(name, seed):
    statistical = analyze_recording(realistic_recording(name, seed))
    truth = REALISTIC[name].truth
    assert max(abs(z_score(statistical.parameters[k], truth[k])) for k in LUMPED) > 2.0   # the noise alone does not
    result = model_uncertainty(statistical)
    for k in LUMPED:
        p = result.parameters[k]
        assert p.value == statistical.parameters[k].value, k        # the reported value stays the fit's
        assert abs(p.value - truth[k]) <= 2.0 * p.std, (k, p.value, truth[k], p.std)
        assert p.std_model > 0 and p.std == pytest.approx(math.hypot(p.std_noise or 0.0, p.std_model)), k
        assert p.std_model < 0.15 * truth[k], k          # wide, but still a measurement


def test_a_recording_the_model_describes_gets_no_model_part_and_no_refit(monkeypatch):
    result = analyze_recording(recording(noise=TYPICAL_NOISE, seed=3))
    assert describes_the_data(result.fit)
    monkeypatch.setattr("analysis.model_uncertainty.fit_with", lambda *a, **k: pytest.fail("refitted"))
    after = model_uncertainty(result)
    for name, p in after.parameters.items():
        if p.value is None:
            continue
        assert p.std_model == 0.0 and p.std == result.parameters[name].std and p.std_noise == p.std, name


def test_the_alternatives_exchange_the_blocked_impedance_and_the_creep_law():
    models = alternative_models(Model(parse_effects("lr2,creep-log,delay-x")))
    ids = {m.effect_ids for m in models}
    assert len(ids) == 7 and all("delay-x" in i for i in ids)
    assert frozenset({"leach", "creep-log-causal", "delay-x"}) in {frozenset(i) for i in ids}
    assert alternative_models(Model(parse_effects("none"))) == []


def test_a_cancelled_model_part_stops():
    statistical = analyze_recording(realistic_recording("woofer", 0))
    cancel = threading.Event()
    cancel.set()
    with pytest.raises(FitCancelled):
        model_uncertainty(statistical, cancel)

