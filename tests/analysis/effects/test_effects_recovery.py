"""Every effect is recoverable: simulate the paper's driver with it, fit the same model, get the truth back.

Each case is the paper's driver (Table I) with the effect swapped in for its
category's (lr3 instead of lr2, creep-rs instead of creep-log) or added (a
channel effect, breakup), at a physically typical value that stands well
above the noise. The fit starts from the data-driven start values, as in use.
"""
import numpy as np
import pytest

from analysis.effects import CATALOGUE, get_effect
from analysis.fit.least_squares import FitData, fit_model
from analysis.fit.startvalues import start_context
from analysis.model.composed import Model
from analysis.spectra import estimate_spectra
from tests.builders import PAPER, TYPICAL_NOISE, recording

CASES = {
    "lr2": {},
    "lr3": {"L3": 0.5e-3, "R3": 0.8},
    "leach": {"K": 0.008, "n": 0.65},
    "wright": {"Rw": 0.45, "Er": 0.7, "Xw": 0.6, "Ei": 0.65},
    "creep-log": {},
    "creep-log-causal": {"lambda": 0.2},
    "creep-3p": {"kappa": 0.4, "tau_r": 1 / (2 * np.pi * 15.0)},
    "creep-fractional": {"beta": 0.1},
    "creep-rs": {"lambda": 0.3},
    "delay-current": {"tau_i": 10e-6},
    "lowpass-current": {"fc_i": 20e3},
    "delay-x": {"tau_x": 40e-6},
    "lowpass-x": {"fc_x": 2000.0},
    "lowpass2-x": {"fc_x": 3000.0, "Q_x": 0.8},
    "breakup": {"f2": 1000.0, "Q2": 5.0, "mu2": 0.2},
    "breakup-spot": {"f2x": 2000.0, "Q2x": 5.0},
    "breakup-coil": {"f_c": 3000.0, "Q_c": 5.0, "mu_c": 0.25},
    "creep-kv": {"kappa": 1.0, "beta": 0.4},
    "creep-zener": {"kappa": 0.5, "tau_r": 1 / (2 * np.pi * 10.0), "beta": 0.5},
    "bl-eddy": {"dBl": 0.1, "f_Bl": 1500.0},
    "air-load": {"a_rad": 0.065},
    "damping-power": {"r_v": 0.8, "n_v": 1.0},
    "closed-box": {"alpha_b": 2.0},
    "vented-box": {"alpha_b": 1.5, "fb": 50.0, "QL": 7.0},
    "vented-box-port": {"alpha_b": 1.5, "fb": 45.0, "QP": 8.0},
    "vented-box-absorption": {"alpha_b": 2.0, "fb": 40.0, "QA": 10.0},
}
# What Z alone must identify: everything that acts on the impedance directly.
# (breakup too: its parameterisation is meant to be identifiable from Z alone.)
IMPEDANCE_ONLY = ("lr2", "lr3", "leach", "wright", "delay-current", "lowpass-current", "breakup", "damping-power")
SEED = 7
MAX_Z = 4.0
MAX_CHI2_RED = 1.5


def _case(effect_id, with_displacement):
    """The paper's model with `effect_id` in its category, and the true values."""
    effect = get_effect(effect_id)
    paper = [get_effect(i) for i in PAPER.effects]
    effects = tuple(e for e in paper if e.category != effect.category) + (effect,)
    model = Model(effects, with_displacement)
    values = {**PAPER.parameters, **CASES[effect_id]}
    return model, {p.name: values[p.name] for p in model.param_specs}


def _data(model, truth, mt):
    rec = recording(truth, model.describe(), mt=mt, noise=TYPICAL_NOISE, seed=SEED,
                    displacement=model.with_displacement)
    return FitData.from_spectra(estimate_spectra(rec))


def _assert_recovered(result, truth):
    for name, value in truth.items():
        err = result.stderr[name]
        assert err is not None and err > 0, f"{name}: no standard error"
        z = (result.values[name] - value) / err
        assert abs(z) < MAX_Z, f"{name}: {result.values[name]:.6g} vs {value:.6g} ({z:+.1f} sigma)"
    for channel, chi2_red in result.chi2_red_by_channel().items():
        assert chi2_red < MAX_CHI2_RED, f"{channel}: reduced chi^2 {chi2_red:.3g}"


def test_every_effect_has_a_recovery_case():
    assert set(CASES) == set(CATALOGUE)


def _fit(model, data):
    """Fit from the data-driven start; for an effect with several starts (a narrow mode), try each, keep the best."""
    ctx = start_context(data.impedance)
    starts = [s for e in model.effects for s in e.starts(ctx)] if any(len(e.starts(ctx)) > 1 for e in model.effects) \
        else [None]
    # From the single default start (f2 = 10*fs = 705 Hz) the fit finds the 1 kHz mode only for
    # about half of the noise realisations: the mode is narrow, and a start must be within about
    # a factor 1.5 of it. Breakup.starts steps f2 by 1.4 across the band.
    return min((fit_model(data, model, start=start) for start in starts), key=lambda r: r.chi2)


@pytest.mark.parametrize("effect_id", sorted(CASES))
def test_fit_recovers_the_effect_from_z_and_hx(effect_id, mt):
    model, truth = _case(effect_id, with_displacement=True)
    _assert_recovered(_fit(model, _data(model, truth, mt)), truth)


@pytest.mark.parametrize("effect_id", IMPEDANCE_ONLY)
def test_fit_recovers_the_effect_from_z_alone(effect_id, mt):
    model, truth = _case(effect_id, with_displacement=False)
    _assert_recovered(_fit(model, _data(model, truth, mt)), truth)


@pytest.mark.parametrize("effect_id", ["lowpass-x", "lowpass2-x"])
def test_a_sensor_low_pass_the_recording_lacks_fits_no_worse_than_leaving_it_out(effect_id, mt):
    """Its corner can go beyond the band until it vanishes: at 1 MHz, its bound then, a low-pass still turned the
    phase 0.6 degrees at 10 kHz, and the fit ended there with a reduced chi^2 of 43 (Z) and 101 (Hx) against 1,
    and Mms 6 sigma off."""
    base = Model(tuple(get_effect(e) for e in ("lr2", "creep-log")))
    truth = {p.name: PAPER.parameters[p.name] for p in base.param_specs}
    data = _data(base, truth, mt)
    without = fit_model(data, base)
    with_it = _fit(base.with_effects(base.effects + (get_effect(effect_id),)), data)
    assert with_it.chi2 <= without.chi2 * 1.02
    for name in ("Bl", "CMES", "RE"):          # CMES = Mms / Bl^2
        assert abs(with_it.values[name] - truth[name]) < MAX_Z * without.stderr[name], name
