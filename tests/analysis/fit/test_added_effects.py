"""An added effect held on its bound far from the data is said; one near the noise, or a default effect, is not."""
from types import SimpleNamespace

from analysis.effects import parse_effects
from analysis.fit.added_effects import added_effects, stuck_effect_notes
from analysis.model.composed import Model

MODEL = Model(parse_effects("lr2,creep-log,breakup"))


def _fit(chi2_red: float, **values):
    defaults = {s.name: s.default for s in MODEL.param_specs}
    return SimpleNamespace(model=MODEL, values={**defaults, **values},
                           chi2_red_by_channel=lambda: {"impedance": chi2_red, "displacement": 1.0})


def test_only_what_the_default_model_lacks_is_added():
    assert [e.id for e in added_effects(MODEL)] == ["breakup"]
    assert added_effects(Model(parse_effects("lr3,creep-3p"))) == ()     # other forms, nothing added


def test_an_added_effect_on_its_bound_far_from_the_data_is_said_with_the_model_to_compare():
    low = MODEL.spec("Q2").min
    notes = stuck_effect_notes(_fit(7.2e4, Q2=low))
    assert len(notes) == 1
    assert "breakup" in notes[0] and "Q2 = " in notes[0] and "--model lr2,creep-log" in notes[0]
    assert "7.2e+04" in notes[0]


def test_nothing_is_said_near_the_noise_or_of_a_default_effect_or_off_the_bounds():
    assert stuck_effect_notes(_fit(1.05, Q2=MODEL.spec("Q2").min)) == []        # merely superfluous
    assert stuck_effect_notes(_fit(7.2e4, R2=MODEL.spec("R2").min)) == []       # lr2 is the default's
    assert stuck_effect_notes(_fit(7.2e4)) == []
    assert stuck_effect_notes(None) == []
