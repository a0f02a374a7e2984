"""The effects catalogue: every effect's equation and its limits (the bookkeeping: test_catalogue.py)."""
import math
import warnings

import numpy as np
import pytest

from analysis.effects import CATALOGUE, get_effect
from analysis.effects.breakup import breakup
from analysis.fit.startvalues import StartContext

# The paper's driver (docs/physics.md section 7): fs = 70.5 Hz.
BASE = {"RE": 3.02, "LE": 0.132e-3, "CMES": 433e-6, "LCES": 11.75e-3, "RES": 12.08, "Bl": 5.23}
FS = 1.0 / (2 * math.pi * math.sqrt(BASE["CMES"] * BASE["LCES"]))
FREQS = np.array([3.0, 20.0, 70.0, 400.0, 2500.0, 15000.0])


def _eddy(L, R, w):
    """j*w*L in parallel with R, by the textbook rule Z1*Z2/(Z1 + Z2)."""
    return (1j * w * L) * R / (1j * w * L + R)


def _breakup_from_the_network(p, w):
    """Z2 - s*m2 from the masses, spring and damper themselves, in the model's admittance units."""
    Mms = p["CMES"] * p["Bl"] ** 2
    m2 = p["mu2"] * Mms
    w2 = 2 * math.pi * p["f2"]
    k2 = w2**2 * m2
    r2 = w2 * m2 / p["Q2"]
    s = 1j * w
    Z2 = 1.0 / (1.0 / (r2 + k2 / s) + 1.0 / (s * m2))
    return (Z2 - s * m2) / p["Bl"] ** 2


def _coil_decoupling_from_the_network(p, w):
    """Zm - (s*Mms + Rms + Kms/s) from the coil's and the cone's masses, the joint and the suspension themselves."""
    Bl2 = p["Bl"] ** 2
    Mms, Rms, Kms = p["CMES"] * Bl2, Bl2 / p["RES"], Bl2 / p["LCES"]
    m_c = p["mu_c"] * Mms
    w_c = 2 * math.pi * p["f_c"]
    k_j, r_j = w_c**2 * m_c, w_c * m_c / p["Q_c"]
    s = 1j * w
    cone = s * (Mms - m_c) + Rms + Kms / s
    Zm = s * m_c + 1.0 / (1.0 / (r_j + k_j / s) + 1.0 / cone)
    return (Zm - (s * Mms + Rms + Kms / s)) / Bl2


def _shorted_turn_force_factor(p, w):
    """Bl - s*M*Bl_f/(R_f + s*L_f), divided by Bl: a turn with M, L_f, R_f, Bl_f chosen to give dBl and f_Bl."""
    L_f, M = 2e-6, 1.5e-5
    R_f = 2 * math.pi * p["f_Bl"] * L_f
    Bl_f = p["dBl"] * p["Bl"] * L_f / M
    s = 1j * w
    return (p["Bl"] - s * M * Bl_f / (R_f + s * L_f)) / p["Bl"]


def _air_load_from_bessel_and_struve(p, w):
    from scipy.special import j1, struve
    a, rho, c = p["a_rad"], 1.18, 343.0
    x = 2 * w * a / c
    zr = rho * c * math.pi * a * a * ((1 - 2 * j1(x) / x) + 1j * 2 * struve(1, x) / x)
    return (zr - 1j * w * 8 * rho * a**3 / 3) / p["Bl"] ** 2


SD, RHO_C2 = 0.0133, 1.18 * 343.0**2


def _box_from_its_volume(p, w):
    """A sealed box of Vb = Vas/alpha_b: Kb = rho*c^2*Sd^2/Vb, added to Zm as Kb/s."""
    cms = p["LCES"] / p["Bl"] ** 2
    vb = RHO_C2 * SD**2 * cms / p["alpha_b"]
    return RHO_C2 * SD**2 / vb / (1j * w) / p["Bl"] ** 2


def _vented_box_from_the_acoustic_network(p, w):
    """Box compliance Cab = Vb/(rho*c^2), port mass Map and leakage RAL = QL/(wb*Cab) in parallel, seen through Sd."""
    cms = p["LCES"] / p["Bl"] ** 2
    vb = RHO_C2 * SD**2 * cms / p["alpha_b"]
    cab = vb / RHO_C2
    wb = 2 * math.pi * p["fb"]
    map_ = 1 / (wb**2 * cab)
    ral = p["QL"] / (wb * cab)
    s = 1j * w
    zab = 1 / (s * cab + 1 / (s * map_) + 1 / ral)
    return SD**2 * zab / p["Bl"] ** 2


def _lossy_vented_box_from_the_acoustic_network(p, w, where):
    """Small 1973: the absorption RAB in series with Cab (QA = 1/(wb*Cab*RAB)), or the port's RAP in series with
    Map (QP = 1/(wb*Cab*RAP)); box branch and port branch in parallel, seen through Sd."""
    cms = p["LCES"] / p["Bl"] ** 2
    cab = SD**2 * cms / p["alpha_b"]
    wb = 2 * math.pi * p["fb"]
    map_ = 1 / (wb**2 * cab)
    s = 1j * w
    box = 1 / (s * cab) + (1 / (wb * cab * p["QA"]) if where == "absorption" else 0.0)
    port = s * map_ + (1 / (wb * cab * p["QP"]) if where == "port" else 0.0)
    zab = 1 / (1 / box + 1 / port)
    return SD**2 * zab / p["Bl"] ** 2


# (effect id, parameter values, the documented equation as a function of w), written out independently.
EQUATIONS = {
    "lr2": ({"L2": 0.264e-3, "R2": 3.52}, lambda p, w: _eddy(p["L2"], p["R2"], w)),
    "lr3": ({"L2": 0.264e-3, "R2": 3.52, "L3": 0.5e-3, "R3": 0.8},
            lambda p, w: _eddy(p["L2"], p["R2"], w) + _eddy(p["L3"], p["R3"], w)),
    "leach": ({"K": 0.008, "n": 0.65},
              lambda p, w: p["K"] * w ** p["n"] * (math.cos(p["n"] * math.pi / 2) + 1j * math.sin(p["n"] * math.pi / 2))),
    "wright": ({"Rw": 0.45, "Er": 0.7, "Xw": 0.6, "Ei": 0.65},
               lambda p, w: p["Rw"] * (w / (2 * np.pi * 1000)) ** p["Er"] + 1j * p["Xw"] * (w / (2 * np.pi * 1000)) ** p["Ei"]),
    "creep-log": ({"lambda": 0.376}, lambda p, w: 1 - p["lambda"] * np.log10(w / (2 * math.pi * FS))),
    "creep-log-causal": ({"lambda": 0.2},
                         lambda p, w: 1 - p["lambda"] * (np.log10(w / (2 * math.pi * FS)) + 1j * math.pi / 2 / math.log(10))),
    "creep-3p": ({"kappa": 0.4, "tau_r": 0.01},
                 lambda p, w: 1 + p["kappa"] * (1 - 1j * w * p["tau_r"]) / (1 + (w * p["tau_r"]) ** 2)),
    "creep-fractional": ({"beta": 0.1},
                         lambda p, w: (w / (2 * math.pi * FS)) ** -p["beta"] * np.exp(-1j * p["beta"] * math.pi / 2)),
    "creep-rs": ({"lambda": 0.3},
                 lambda p, w: 1 + p["lambda"] * (np.log10(np.abs(1 - 1.5j * 2 * math.pi * FS / w))
                                                 + 1j * np.angle(1 - 1.5j * 2 * math.pi * FS / w) / math.log(10))),
    "delay-current": ({"tau_i": 20e-6}, lambda p, w: np.cos(w * p["tau_i"]) + 1j * np.sin(w * p["tau_i"])),
    "delay-x": ({"tau_x": 250e-6}, lambda p, w: np.cos(w * p["tau_x"]) - 1j * np.sin(w * p["tau_x"])),
    "lowpass-current": ({"fc_i": 5000.0}, lambda p, w: 1 + 1j * w / (2 * math.pi * p["fc_i"])),
    "breakup-spot": ({"f2x": 1500.0, "Q2x": 5.0},
                     lambda p, w: ((2 * math.pi * p["f2x"]) ** 2 + 1j * w * 2 * math.pi * p["f2x"] / p["Q2x"])
                     / ((2 * math.pi * p["f2x"]) ** 2 - w**2 + 1j * w * 2 * math.pi * p["f2x"] / p["Q2x"])),
    "lowpass-x": ({"fc_x": 2000.0}, lambda p, w: 1 / (1 + 1j * w / (2 * math.pi * p["fc_x"]))),
    "lowpass2-x": ({"fc_x": 3000.0, "Q_x": 0.8},
                   lambda p, w: 1 / (1 - (w / (2 * math.pi * p["fc_x"])) ** 2 + 1j * w / (2 * math.pi * p["fc_x"]) / p["Q_x"])),
    "breakup": ({"f2": 1000.0, "Q2": 5.0, "mu2": 0.2}, _breakup_from_the_network),
    "breakup-coil": ({"f_c": 3000.0, "Q_c": 5.0, "mu_c": 0.25}, _coil_decoupling_from_the_network),
    "creep-kv": ({"kappa": 1.0, "beta": 0.4},
                 lambda p, w: (1 + p["kappa"]) / (1 + p["kappa"] * (w / (2 * math.pi * FS)) ** p["beta"]
                                                  * np.exp(1j * p["beta"] * math.pi / 2))),
    "creep-zener": ({"kappa": 0.5, "tau_r": 0.016, "beta": 0.5},
                    lambda p, w: 1 + p["kappa"] / (1 + (w * p["tau_r"]) ** p["beta"] * np.exp(1j * p["beta"] * math.pi / 2))),
    "bl-eddy": ({"dBl": 0.1, "f_Bl": 1500.0}, _shorted_turn_force_factor),
    "air-load": ({"a_rad": 0.065}, _air_load_from_bessel_and_struve),
    "damping-power": ({"r_v": 0.8, "n_v": 0.7},
                      lambda p, w: p["r_v"] * ((w / (2 * math.pi * FS)) ** p["n_v"] - 1) * (p["Bl"] ** 2 / p["RES"])
                      / p["Bl"] ** 2),
    "closed-box": ({"alpha_b": 2.0}, _box_from_its_volume),
    "vented-box": ({"alpha_b": 1.5, "fb": 50.0, "QL": 7.0}, _vented_box_from_the_acoustic_network),
    "vented-box-absorption": ({"alpha_b": 1.5, "fb": 50.0, "QA": 10.0},
                              lambda p, w: _lossy_vented_box_from_the_acoustic_network(p, w, "absorption")),
    "vented-box-port": ({"alpha_b": 1.5, "fb": 45.0, "QP": 8.0},
                        lambda p, w: _lossy_vented_box_from_the_acoustic_network(p, w, "port")),
}
# The air load's Struve function is tabulated (analysis.effects.mechanical): to 1e-6 of itself.
EQUATION_RTOL = {"air-load": 1e-6}


def _response(effect_id, values, f):
    return get_effect(effect_id).response(2j * np.pi * np.asarray(f, dtype=float), {**BASE, **values})


def test_every_effect_has_an_equation_test():
    assert set(EQUATIONS) == set(CATALOGUE)


@pytest.mark.parametrize("effect_id", sorted(EQUATIONS))
def test_response_is_the_documented_equation(effect_id):
    values, equation = EQUATIONS[effect_id]
    got = _response(effect_id, values, FREQS)
    want = np.array([equation({**BASE, **values}, 2 * math.pi * f) for f in FREQS])
    np.testing.assert_allclose(got, want, rtol=EQUATION_RTOL.get(effect_id, 1e-10), atol=0)


@pytest.mark.parametrize("effect_id", ["lr2", "lr3", "leach", "wright"])
def test_blocked_impedance_terms_vanish_at_dc(effect_id):
    values, _ = EQUATIONS[effect_id]
    assert np.all(np.abs(_response(effect_id, values, [1e-6])) < 1e-4)
    # ... and above DC they only add: a resistance growing with frequency, and a positive reactance.
    z = _response(effect_id, values, FREQS)
    assert np.all(np.diff(z.real) > 0) and np.all(z.imag > 0)


def test_lr3_contains_lr2():
    values = {"L2": 0.264e-3, "R2": 3.52, "L3": 0.0, "R3": 1.0}
    np.testing.assert_allclose(_response("lr3", values, FREQS), _response("lr2", values, FREQS), rtol=1e-12)


@pytest.mark.parametrize("stage", [{"L3": 0.0, "R3": 0.0}, {"L3": 0.5e-3, "R3": 0.0}])
def test_a_shunted_stage_at_its_bounds_adds_nothing_and_warns_of_nothing(stage):
    """Both of a stage's bounds admit 0: at L = R = 0 the fraction was 0/0, a NaN in the fit and a RuntimeWarning
    on the user's terminal. Its limit is 0, as at either alone (no inductance; a short)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lr3 = _response("lr3", {"L2": 0.264e-3, "R2": 3.52, **stage}, FREQS)
        assert np.all(_response("lr2", {"L2": 0.0, "R2": 0.0}, FREQS) == 0)
    np.testing.assert_allclose(lr3, _response("lr2", {"L2": 0.264e-3, "R2": 3.52}, FREQS), rtol=1e-12)


def test_leach_has_a_constant_phase_of_n_times_90_degrees():
    z = _response("leach", {"K": 0.01, "n": 0.6}, FREQS)
    np.testing.assert_allclose(np.angle(z), 0.6 * np.pi / 2, rtol=1e-12)


@pytest.mark.parametrize("effect_id", ["creep-log", "creep-log-causal"])
def test_log_creep_laws_leave_the_compliance_unchanged_at_fs(effect_id):
    c = _response(effect_id, {"lambda": 0.3}, [FS])
    assert c.real == pytest.approx([1.0], abs=1e-12)


def test_creep_log_is_real_and_rises_by_lambda_per_decade_below_fs():
    c = _response("creep-log", {"lambda": 0.3}, [FS / 10, FS, FS * 10])
    np.testing.assert_allclose(c, [1.3, 1.0, 0.7], rtol=1e-12)


@pytest.mark.parametrize("effect_id, values", [
    ("creep-log-causal", {"lambda": 0.2}), ("creep-3p", {"kappa": 0.4, "tau_r": 0.01}),
    ("creep-fractional", {"beta": 0.1}), ("creep-rs", {"lambda": 0.3}),
])
def test_causal_creep_laws_are_lossy_and_softer_below_fs(effect_id, values):
    c = _response(effect_id, values, FREQS)
    assert np.all(c.imag < 0)                   # stiffness 1/c with a positive imaginary part: a loss
    assert np.all(np.diff(c.real) < 0)          # more compliant towards low frequencies


def test_creep_fractional_has_unit_magnitude_at_fs():
    assert abs(_response("creep-fractional", {"beta": 0.1}, [FS])[0]) == pytest.approx(1.0, abs=1e-12)


def test_creep_3p_goes_from_one_plus_kappa_at_dc_to_one_at_high_frequencies():
    c = _response("creep-3p", {"kappa": 0.4, "tau_r": 0.01}, [1e-6, 1e7])
    np.testing.assert_allclose(c, [1.4, 1.0], atol=1e-6)


def test_creep_rs_tends_to_one_above_fs_and_to_the_log_law_well_below():
    values = {"lambda": 0.3}
    assert abs(_response("creep-rs", values, [1e9])[0] - 1) < 1e-6
    f = np.array([FS / 1e3, FS / 1e4])
    rs = _response("creep-rs", values, f)
    causal = _response("creep-log-causal", values, f)
    # Well below w0 = 1.5*ws: the same slope as the causal log law, offset by lambda*log10(1.5).
    np.testing.assert_allclose(rs - causal, 0.3 * math.log10(1.5), atol=1e-3)


@pytest.mark.parametrize("effect_id, values", [("delay-current", {"tau_i": -30e-6}), ("delay-x", {"tau_x": 300e-6})])
def test_delays_only_turn_the_phase(effect_id, values):
    np.testing.assert_allclose(np.abs(_response(effect_id, values, FREQS)), 1.0, rtol=1e-12)


def test_delay_signs_positive_tau_means_that_channel_lags():
    f = 1000.0
    # Current lags -> the measured current's phase is late -> U/I_measured leads: phase + w*tau.
    assert np.angle(_response("delay-current", {"tau_i": 10e-6}, [f])[0]) == pytest.approx(2 * math.pi * f * 10e-6)
    # Displacement lags -> X_measured/U is late: phase - w*tau.
    assert np.angle(_response("delay-x", {"tau_x": 10e-6}, [f])[0]) == pytest.approx(-2 * math.pi * f * 10e-6)


def test_first_order_lowpass_is_one_at_dc_and_minus_3_db_at_fc():
    h = _response("lowpass-x", {"fc_x": 2000.0}, [1e-6, 2000.0])
    assert h[0] == pytest.approx(1.0, abs=1e-9)
    assert 20 * np.log10(abs(h[1])) == pytest.approx(-3.0103, abs=1e-4)
    assert np.angle(h[1]) == pytest.approx(-math.pi / 4)


def test_second_order_lowpass_is_one_at_dc_and_q_at_fc():
    h = _response("lowpass2-x", {"fc_x": 3000.0, "Q_x": 0.8}, [1e-6, 3000.0])
    assert h[0] == pytest.approx(1.0, abs=1e-9)
    assert abs(h[1]) == pytest.approx(0.8)
    assert np.angle(h[1]) == pytest.approx(-math.pi / 2)


def test_breakup_is_negligible_far_below_f2_and_takes_mu2_of_the_mass_far_above():
    values = {**BASE, "f2": 1000.0, "Q2": 5.0, "mu2": 0.2}
    s = 2j * np.pi * np.array([10.0, 1e6])
    y2 = breakup.response(s, values)
    mass_term = s * values["CMES"]
    assert abs(y2[0] / mass_term[0]) < 1e-3                          # ~ mu2 * (f/f2)^2
    assert abs(y2[1] / mass_term[1] - (-0.2)) < 1e-4                # the cone is lighter by m2


def test_breakup_blocks_the_cone_at_f2_and_resonates_at_f2_over_sqrt_1_minus_mu2():
    values = {**BASE, "f2": 1000.0, "Q2": 1e6, "mu2": 0.2}
    mass_and_mode = lambda f: 2j * np.pi * f * values["CMES"] + breakup.response(np.array([2j * np.pi * f]), values)[0]
    reference = abs(2j * np.pi * 1000.0 * values["CMES"])
    assert abs(mass_and_mode(1000.0 * (1 + 1e-7))) > 1e5 * reference      # Zm -> infinity: the coil stands still
    assert abs(mass_and_mode(1000.0 / math.sqrt(0.8))) < 1e-5 * reference  # Zm -> 0: cone and m2 in anti-phase


def test_coil_decoupling_blocks_the_coil_then_frees_it_and_leaves_the_coil_alone_far_above():
    values = {**BASE, "f_c": 3000.0, "Q_c": 50.0, "mu_c": 0.25}
    coil = get_effect("breakup-coil")
    f = np.geomspace(500.0, 10e3, 20001)
    s = 2j * np.pi * f
    rigid = s * values["CMES"] + 1 / values["RES"] + 1 / (s * values["LCES"])
    zm = np.abs(rigid + coil.response(s, values))
    # The cone on the joint, the coil held: Zm peaks; coil against cone: Zm falls to its losses.
    assert f[np.argmax(zm)] == pytest.approx(3000.0 * math.sqrt(0.25 / 0.75), rel=2e-3)
    assert f[np.argmin(zm)] == pytest.approx(3000.0 / math.sqrt(0.75), rel=2e-3)
    far = np.array([2j * np.pi * 3e6])
    ratio = (far * values["CMES"] + coil.response(far, values)) / (far * values["CMES"])
    assert ratio[0] == pytest.approx(0.25, rel=1e-3)                                  # the coil's mass alone
    # Far below, rigid but for the joint's spring in series with the suspension: Kms/k_j of the stiffness.
    low = np.array([2j * np.pi * 10.0])
    rigid_low = low * values["CMES"] + 1 / values["RES"] + 1 / (low * values["LCES"])
    k_ratio = (1 / values["LCES"]) / ((2 * np.pi * 3000.0) ** 2 * 0.25 * values["CMES"])
    assert abs(coil.response(low, values)[0] / rigid_low[0]) == pytest.approx(k_ratio, rel=0.05)


def test_the_eddy_force_factor_goes_from_one_to_one_minus_dbl():
    g = _response("bl-eddy", {"dBl": 0.1, "f_Bl": 1500.0}, [1e-3, 1e8])
    np.testing.assert_allclose(g, [1.0, 0.9], atol=1e-5)


def test_air_load_adds_nothing_at_low_frequencies_and_takes_its_mass_away_far_above():
    a = 0.065
    y = _response("air-load", {"a_rad": a}, [1.0, 1e5])
    mass = 8 * 1.18 * a**3 / 3
    assert abs(y[0]) * BASE["Bl"] ** 2 < 1e-3 * 2 * math.pi * 1.0 * mass            # negligible at 1 Hz
    far = 2 * math.pi * 1e5
    assert y[1].imag * BASE["Bl"] ** 2 == pytest.approx(-far * mass, rel=1e-2)       # the air mass is gone
    assert y[1].real * BASE["Bl"] ** 2 == pytest.approx(1.18 * 343 * math.pi * a * a, rel=1e-2)   # rho*c*S


def test_the_damping_law_leaves_rms_at_fs_and_doubles_it_where_the_power_is_two():
    values = {"r_v": 1.0, "n_v": 1.0}
    y = _response("damping-power", values, [FS, 2 * FS])
    np.testing.assert_allclose(y, [0.0, 1 / BASE["RES"]], atol=1e-12)


def test_fractional_creep_laws_have_a_finite_static_compliance():
    kv = _response("creep-kv", {"kappa": 1.0, "beta": 0.4}, [1e-9])
    zener = _response("creep-zener", {"kappa": 0.5, "tau_r": 0.016, "beta": 0.5}, [1e-9, 1e9])
    np.testing.assert_allclose(kv, [2.0], atol=1e-3)
    np.testing.assert_allclose(zener, [1.5, 1.0], atol=1e-3)
    # With beta = 1 the fractional Zener is the three-parameter law.
    np.testing.assert_allclose(_response("creep-zener", {"kappa": 0.4, "tau_r": 0.01, "beta": 1.0}, FREQS),
                               _response("creep-3p", {"kappa": 0.4, "tau_r": 0.01}, FREQS), rtol=1e-12)


def test_a_vented_box_holds_the_cone_at_fb_and_is_the_closed_box_far_above():
    box = {"alpha_b": 1.5, "fb": 50.0, "QL": 7.0}
    at_fb = _response("vented-box", box, [50.0])[0]
    assert at_fb.imag == pytest.approx(0, abs=1e-9) and at_fb.real > 0              # a pure resistance: QL*Kb/wb
    far = np.array([5e4])
    np.testing.assert_allclose(_response("vented-box", box, far), _response("closed-box", {"alpha_b": 1.5}, far),
                               rtol=1e-3)


def test_the_vented_box_reads_its_start_from_the_two_impedance_peaks():
    from analysis.effects.enclosure import vented_box
    from analysis.fit.least_squares import FitData
    from analysis.spectra import estimate_spectra
    from analysis.fit.startvalues import start_context
    from tests.builders import PAPER, TYPICAL_NOISE, recording
    truth = {**PAPER.parameters, "alpha_b": 1.5, "fb": 50.0, "QL": 7.0}
    data = FitData.from_spectra(estimate_spectra(recording(truth, "lr2,creep-log,vented-box", noise=TYPICAL_NOISE,
                                                           n_periods=4, seed=1)))
    start = vented_box.guess(start_context(data.impedance))
    fs = 1 / (2 * math.pi * math.sqrt(start["CMES"] * start["LCES"]))
    assert start["fb"] == pytest.approx(50.0, rel=0.1)
    assert start["alpha_b"] == pytest.approx(1.5, rel=0.35)
    assert fs == pytest.approx(70.5, rel=0.15)


def test_breakup_start_grid_covers_the_band_in_steps_of_1_4():
    ctx = StartContext(RE=3.0, fs=70.0, RES=12.0, Qms=3.0, LE_high=2e-4, f_min=5.0, f_max=10000.0)
    f2 = np.array([s["f2"] for s in breakup.starts(ctx)])
    assert f2[0] == pytest.approx(140.0) and f2[-1] < 10000.0
    assert np.all(f2[1:] / f2[:-1] <= 1.4 + 1e-12)
