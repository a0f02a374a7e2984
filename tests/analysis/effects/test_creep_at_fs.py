"""The causal log creep with its loss at fs in RES (analysis.effects.creep_at_fs): the same curves as
creep-log-causal, with RES holding every loss at fs and the compliance at fs real."""
import numpy as np
import pytest

from analysis.effects import CATALOGUE, get_effect, parse_effects
from analysis.model.composed import Model
from analysis.model.lumped import resonance_frequency

VALUES = {"RE": 3.0, "LE": 0.13e-3, "L2": 0.26e-3, "R2": 3.5, "CMES": 433e-6, "LCES": 11.75e-3, "RES": 12.0,
          "Bl": 5.2, "lambda": 0.25}


def test_at_fs_the_compliance_is_real_and_unchanged():
    ws = 2 * np.pi * resonance_frequency(VALUES)
    c = get_effect("creep-log-causal-fs").response(np.array([1j * ws]), VALUES)
    assert c[0] == pytest.approx(1.0 + 0.0j, abs=1e-12)


def test_it_is_the_causal_law_with_the_loss_at_fs_moved_into_res():
    """Z and Hx of creep-log-causal equal this law's with RES' = the total resistance at fs and LCES' the real
    compliance at fs (written out from the causal law, not from the module's formula)."""
    lam, ws = VALUES["lambda"], 2 * np.pi * resonance_frequency(VALUES)
    k_fs = 1.0 / (1.0 - lam * np.log10(1j))              # the causal law's relative stiffness at fs
    a, b = k_fs.real, k_fs.imag
    # Zm = K k(s)/s + Rms; k(s)/s = a k'(s)/s + b/ws: Kms' = a Kms, Rms' = Rms + Kms b / ws.
    bl2 = VALUES["Bl"] ** 2
    kms, rms = bl2 / VALUES["LCES"], bl2 / VALUES["RES"]
    moved = {**VALUES, "LCES": bl2 / (a * kms), "RES": bl2 / (rms + kms * b / ws)}
    # ws inside the law follows LCES: hold it by keeping fs, i.e. CMES scaled the other way.
    moved["CMES"] = VALUES["CMES"] * VALUES["LCES"] / moved["LCES"]
    f = np.logspace(0, 4, 200)
    s = 2j * np.pi * f
    causal = Model(parse_effects("lr2,creep-log-causal"))
    at_fs = Model(parse_effects("lr2,creep-log-causal-fs"))
    # The mass is CMES Bl^2 in both: scale the reference's mass term to the same Mms by comparing Zm directly.
    zm_causal = bl2 / (causal.impedance(s, VALUES) - _ze(s, VALUES))
    zm_at_fs = bl2 / (at_fs.impedance(s, moved) - _ze(s, moved))
    mass = s * (VALUES["CMES"] - moved["CMES"]) * bl2
    np.testing.assert_allclose(zm_at_fs + mass, zm_causal, rtol=1e-9)


def _ze(s, p):
    return p["RE"] + s * p["LE"] + s * p["L2"] * p["R2"] / (s * p["L2"] + p["R2"])


def test_it_is_found_by_id_but_left_out_of_the_catalogue():
    assert get_effect("creep-log-causal-fs").category == "creep"
    assert "creep-log-causal-fs" not in CATALOGUE         # the diagnosis would find it equal to creep-log-causal
