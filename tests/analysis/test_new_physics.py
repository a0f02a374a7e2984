"""The physics the catalogue lacked, found by the diagnosis on recordings that have it.

For each effect added with issue 14, a recording of the paper's driver from the project's simulator with
that physics and realistic noise (tests.builders.TYPICAL_NOISE), diagnosed from the default model
lr2,creep-log: the effect is ranked first, the greedy path ends `explained` at a reduced chi^2 <= 2 on
every channel, and RE, Bl, Mms and Kms are within 1 % of the truth (each of these effects leaves them
their meaning: Mms the whole low-frequency moving mass, air load included; Kms the suspension's own).
"""
import math

import pytest

from analysis.diagnosis import acceptance
from analysis.diagnosis.candidates import diagnose
from analysis.effects import parse_effects
from analysis.fit.least_squares import FitData
from analysis.model.composed import Model
from analysis.spectra import estimate_spectra
from analysis.diagnosis.words import first_site
from analysis.effects.base import Site
from analysis.synthesis import synthesize_recording
from tests.builders import PAPER, TYPICAL_NOISE, recording
from tests.real_like import structural_cone_mode

START = "lr2,creep-log"

# (the effect, the truth's effects, the effect's values, a seed)
CASES = [
    ("bl-eddy", "lr2,creep-log,bl-eddy", {"dBl": 0.1, "f_Bl": 1500.0}, 21),
    ("bl-eddy", "lr2,creep-log,bl-eddy", {"dBl": 0.04, "f_Bl": 600.0}, 22),
    ("air-load", "lr2,creep-log,air-load", {"a_rad": math.sqrt(0.0133 / math.pi)}, 21),
    ("damping-power", "lr2,creep-log,damping-power", {"r_v": 0.8, "n_v": 1.0}, 21),
    ("damping-power", "lr2,creep-log,damping-power", {"r_v": 0.3, "n_v": 0.5}, 22),
    ("closed-box", "lr2,creep-log,closed-box", {"alpha_b": 2.0}, 21),
    ("closed-box", "lr2,creep-log,closed-box", {"alpha_b": 0.7}, 22),
    ("vented-box", "lr2,creep-log,vented-box", {"alpha_b": 1.5, "fb": 50.0, "QL": 7.0}, 21),
    ("vented-box", "lr2,creep-log,vented-box", {"alpha_b": 3.0, "fb": 35.0, "QL": 12.0}, 22),
    # The vented box's loss family (issue 30): Vb with alpha_b 1.5, fb 45 Hz, the losses in the port or the filling.
    ("vented-box-port", "lr2,creep-log,vented-box-port", {"alpha_b": 1.5, "fb": 45.0, "QP": 8.0}, 21),
    ("vented-box-absorption", "lr2,creep-log,vented-box-absorption", {"alpha_b": 2.0, "fb": 40.0, "QA": 10.0}, 22),
    ("creep-kv", "lr2,creep-kv", {"kappa": 1.0, "beta": 0.4}, 21),
    ("creep-kv", "lr2,creep-kv", {"kappa": 0.4, "beta": 0.25}, 22),
    ("creep-zener", "lr2,creep-zener", {"kappa": 0.5, "tau_r": 1 / (2 * math.pi * 10.0), "beta": 0.5}, 21),
    ("breakup-coil", "lr2,creep-log,breakup-coil", {"f_c": 3000.0, "Q_c": 5.0, "mu_c": 0.25}, 21),
    ("breakup-coil", "lr2,creep-log,breakup-coil", {"f_c": 1500.0, "Q_c": 8.0, "mu_c": 0.3}, 22),
]


def _mechanical(v: dict) -> dict:
    return {"RE": v["RE"], "Bl": v["Bl"], "Mms": v["CMES"] * v["Bl"] ** 2, "Kms": v["Bl"] ** 2 / v["LCES"]}


@pytest.mark.parametrize("effect_id, effects, values, seed", CASES,
                         ids=[f"{c[0]}-{'-'.join(f'{v:.3g}' for v in c[2].values())}" for c in CASES])
def test_the_diagnosis_names_the_missing_physics_and_explains_the_recording(pool, mt, effect_id, effects, values,
                                                                            seed):
    truth = {**PAPER.parameters, **values}
    rec = recording(truth, effects, noise=TYPICAL_NOISE, n_periods=8, seed=seed, mt=mt)
    data = FitData.from_spectra(estimate_spectra(rec))
    result = diagnose(data, Model(parse_effects(START)), executor=pool)

    ranked = [(c.effect.id, round(c.delta_bic)) for c in result.first_candidates[:4]]
    assert result.first_candidates[0].effect.id == effect_id, ranked
    assert result.verdict == acceptance.EXPLAINED, (result.verdict, result.final.model.effect_ids)
    final = result.final
    assert set(final.model.effect_ids) == {e.id for e in parse_effects(effects)}
    for channel, chi2_red in final.chi2_red_by_channel().items():
        assert chi2_red <= 2.0, (channel, chi2_red)
    fitted, true = _mechanical(final.values), _mechanical(truth)
    for name, value in true.items():
        assert fitted[name] == pytest.approx(value, rel=0.01), name


def test_a_cone_mode_in_the_impedance_and_at_the_spot_is_explained_by_both_effects(pool, mt):
    """A mode the coil feels (breakup, in Z and Hx) that the laser's spot sees more of (breakup-spot): with
    breakup-spot a category of its own the path takes both (issue 30), and the model reaches the noise."""
    values = {"f2": 1500.0, "Q2": 6.0, "mu2": 0.05, "f2x": 3000.0, "Q2x": 2.0}
    truth = {**PAPER.parameters, **values}
    rec = recording(truth, "lr2,creep-log,breakup,breakup-spot", noise=TYPICAL_NOISE, n_periods=8, seed=23, mt=mt)
    data = FitData.from_spectra(estimate_spectra(rec))
    result = diagnose(data, Model(parse_effects(START)), executor=pool)

    assert set(result.final.model.effect_ids) == {"lr2", "creep-log", "breakup", "breakup-spot"}
    assert result.verdict == acceptance.EXPLAINED
    for channel, chi2_red in result.final.chi2_red_by_channel().items():
        assert chi2_red <= 2.0, (channel, chi2_red)
    fitted, true = _mechanical(result.final.values), _mechanical(truth)
    for name, value in true.items():
        assert fitted[name] == pytest.approx(value, rel=0.01), name


# A cone mode (f2 1.5 kHz, Q2 6, a tenth of Mms) whose outer cone, where the laser's spot is, has its own mode
# above it (4 kHz, Q 3): breakup alone takes Z from a reduced chi^2 of 6.2e4 to 4.1e3 but Hx only from 2.3e5
# to 1.4e5, and the mechanical site's correction (which reshapes Hx through Zm) removes more, so rule 3 refuses
# it; breakup-spot alone leaves Z. Main before the pairs of refused candidates: unexplained, nothing taken.
CONE_AND_SPOT = {"f2": 1500.0, "Q2": 6.0, "mu2": 0.1, "f2x": 4000.0, "Q2x": 3.0}


@pytest.mark.parametrize("seed", [23, 24])
def test_a_cone_mode_the_spot_sees_a_mode_of_its_own_above_is_accepted_as_a_pair(pool, mt, seed):
    truth = {**PAPER.parameters, **CONE_AND_SPOT}
    rec = recording(truth, "lr2,creep-log,breakup,breakup-spot", noise=TYPICAL_NOISE, n_periods=8, seed=seed, mt=mt)
    result = diagnose(FitData.from_spectra(estimate_spectra(rec)), Model(parse_effects(START)), executor=pool)

    taken = [step.chosen for step in result.steps if step.chosen is not None]
    assert [c.label for c in taken] == ["breakup + breakup-spot"], [c.label for c in taken]
    assert result.verdict == acceptance.EXPLAINED
    for channel, chi2_red in result.final.chi2_red_by_channel().items():
        assert chi2_red <= 2.0, (channel, chi2_red)
    fitted, true = _mechanical(result.final.values), _mechanical(truth)
    for name, value in true.items():
        assert fitted[name] == pytest.approx(value, rel=0.01), name


def test_a_cone_mode_with_structural_damping_is_not_claimed_explained(pool, mt):
    """The same two modes with structural damping (a loss factor, not the catalogue's viscous Q): the pair
    comes close (reduced chi^2 from 6e4 and 2e5 to some 5e2 and 3e3), not to the noise. Honest: partly
    explained, the misfit left placed at a site where the physics acts, and the parameters kept."""
    cone, spot = structural_cone_mode(1500.0, 1 / 6, 0.1, 4000.0, 1 / 3)
    rec = synthesize_recording(Model(parse_effects(START) + (cone, spot)), dict(PAPER.parameters), mt.waveform,
                               mt.excited_bins, mt.sample_rate, 8, 1, TYPICAL_NOISE, seed=23,
                               driver={"name": "synthetic: structural cone mode", "sd_m2": 0.0133})
    result = diagnose(FitData.from_spectra(estimate_spectra(rec)), Model(parse_effects(START)), executor=pool)

    assert result.verdict == acceptance.PARTLY_EXPLAINED, result.verdict
    assert first_site(result) in (Site.MECHANICAL, Site.DISPLACEMENT), first_site(result)
    fitted, true = _mechanical(result.final.values), _mechanical(PAPER.parameters)
    for name, value in true.items():
        assert fitted[name] == pytest.approx(value, rel=0.01), name
