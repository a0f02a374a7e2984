"""Where the added-mass methods disagree beyond their uncertainties (analysis.added_mass_agreement): said beside
their tables, with why, on the real SEAS set (Speakerbench's published numbers come from the model-free method)."""
import pytest

from analysis import added_mass as am
from analysis.added_mass_agreement import disagreements
from analysis.importers import read_curve
from tests.builders import REAL_DATA

SEAS = REAL_DATA / "seas_l16rnx"
SD_M2 = 0.0103869


@pytest.fixture(scope="module")
def seas():
    paths = [SEAS / f"L16RNX_{m}_242_27mV.zma" for m in ("0g", "8_017g", "16_048g")]
    if not all(p.is_file() for p in paths):
        pytest.skip("the real data set (tests.builders.REAL_DATA) is not on this machine")
    free, light, heavy = (read_curve(p, "impedance").transfer for p in paths)
    curves = [am.MassCurve(impedance=free, added_mass_kg=0.0), am.MassCurve(impedance=light, added_mass_kg=8.017e-3),
              am.MassCurve(impedance=heavy, added_mass_kg=16.048e-3)]
    effects = am.parse_effects(am.DEFAULT_EFFECTS)
    primary = am.joint_added_mass(curves, effects, SD_M2)
    model_free = am.model_free_dual_mass(free, light, 8.017e-3, heavy, 16.048e-3, SD_M2)
    return primary, model_free


def test_the_joint_fits_rms_apart_from_the_model_free_ones_is_said_with_the_creeps_loss(seas):
    primary, model_free = seas
    lines = disagreements(primary, [model_free])
    (rms,) = [line for line in lines if line.startswith("Rms ")]
    assert "1.39" in rms and "2.11" in rms and "model-free" in rms
    (why,) = [line for line in lines if line.startswith("Rms") and "creep" in line]
    assert "every loss at fs in Rms" in why
    assert not [line for line in lines if line.startswith("Bl ")]     # Bl agrees within 1 % (7.07 and 7.01)


def test_methods_that_agree_say_nothing(seas):
    primary, _ = seas
    assert disagreements(primary, [primary]) == []
