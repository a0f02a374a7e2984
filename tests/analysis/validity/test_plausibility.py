"""Plausibility (issue 31, class 2): a result no loudspeaker can have is red with its likely cause, not green.

The recordings are a driver with physics outside the catalogue's exact forms (tests/odd_physics.py: a bump
at the electrical site and one at the mechanical site at once) and realistic noise, written to disk; each
mistake is then made as a technician makes it, in the files: a laser in mm declared as m, a 10:1 current
probe left out of the sidecar, an Sd typed wrong, a WAV header rewritten to another rate, the laser's sign
flipped. The same recordings without the mistake stay free of plausibility findings.
"""
import json
import struct

import pytest

from analysis.validity import plausibility as pl
from analysis.effects import parse_effects
from analysis.pipeline import analyze_recording
from analysis.recording import read_recording, write_recording
from tests.builders import DRIVERS, TYPICAL_NOISE, multitone
from tests.odd_physics import ODD

PLAUSIBILITY_CODES = {pl.EFFICIENCY, pl.MASS_PER_AREA, pl.EXCURSION, pl.RE_NOMINAL, pl.SAMPLE_RATE, pl.LASER_SIGN}
NOMINAL_OHM = 4.0         # the paper driver's RE is 3.02 ohm: a 4-ohm driver


def _odd_recording(values, seed=4):
    from analysis.model import Model
    from analysis.synthesis import synthesize_recording
    model = Model(parse_effects("lr2,creep-log") + (ODD["electrical"], ODD["mechanical"]))
    mt = multitone()
    return synthesize_recording(model, values, mt.waveform, mt.excited_bins, mt.sample_rate, 8, 1, TYPICAL_NOISE,
                                seed=seed, driver={"name": "odd", "sd_m2": 0.0133,
                                                   "nominal_impedance_ohm": NOMINAL_OHM})


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """The paper driver (odd physics, realistic noise) on disk, as the measurement wrote it: its sidecar names
    the sound card and its rate."""
    folder = tmp_path_factory.mktemp("plausible")
    wav, sidecar = write_recording(folder / "driver", _odd_recording(DRIVERS["paper"]))
    doc = json.loads(sidecar.read_text())
    doc["measurement"] = {"audio": "SoundDeviceAudio(default device, 48000 Hz)"}
    sidecar.write_text(json.dumps(doc))
    return wav


def _variant(tmp_path, wav, edit=None, rate=None):
    """A copy of the recording with its sidecar edited by `edit(doc)` and, given `rate`, its WAV header's rate."""
    blob = bytearray(wav.read_bytes())
    if rate is not None:          # the 'fmt ' chunk of linpar's own WAV: sample rate at 24, byte rate at 28
        frame = struct.unpack_from("<H", blob, 32)[0]
        struct.pack_into("<II", blob, 24, rate, rate * frame)
    (tmp_path / "copy.wav").write_bytes(bytes(blob))
    doc = json.loads(wav.with_suffix(".json").read_text())
    if edit is not None:
        edit(doc)
    (tmp_path / "copy.json").write_text(json.dumps(doc))
    return read_recording(tmp_path / "copy.wav")


def _scale(signal, factor):
    def edit(doc):
        for channel in doc["channels"]:
            if channel["signal"] == signal:
                channel["scale"] *= factor
    return edit


def _red_codes(result):
    return {f["code"]: f for ch in result.validity.as_json()["channels"].values() for f in ch.get("findings", ())
            if f["severity"] == "red"}


def _plausibility(result):
    return {f["code"] for ch in result.validity.as_json()["channels"].values() for f in ch.get("findings", ())} \
        & PLAUSIBILITY_CODES


def test_the_recording_as_written_is_plausible(written):
    result = analyze_recording(read_recording(written))
    assert result.validity.overall != "red" and not _plausibility(result), result.validity


@pytest.mark.parametrize("name", ["fullrange-2in", "midwoofer-6in", "woofer-12in", "woofer-18in"])
def test_real_drivers_from_2_to_18_inch_are_plausible(name):
    sd = {"fullrange-2in": 0.0015, "midwoofer-6in": 0.0104, "woofer-12in": 0.053, "woofer-18in": 0.12}[name]
    recording = _odd_recording(DRIVERS[name])
    result = analyze_recording(recording, sd_m2=sd)
    assert not _plausibility(result), result.validity


def test_a_laser_in_mm_declared_as_m_is_red_with_its_scale_named(written, tmp_path):
    result = analyze_recording(_variant(tmp_path, written, _scale("displacement", 1000.0)))
    red = _red_codes(result)
    assert result.validity.overall == "red"
    assert {pl.EFFICIENCY, pl.MASS_PER_AREA, pl.EXCURSION} <= set(red)
    assert all("looks like mm, not m" in red[c]["remedy"] for c in (pl.EFFICIENCY, pl.MASS_PER_AREA, pl.EXCURSION))


def test_an_undeclared_10_to_1_current_probe_is_red_with_the_probe_named(written, tmp_path):
    result = analyze_recording(_variant(tmp_path, written, _scale("current", 0.1)))
    red = _red_codes(result)
    assert pl.RE_NOMINAL in red and "current probe's ratio is not in the sidecar" in red[pl.RE_NOMINAL]["remedy"]
    assert red[pl.RE_NOMINAL]["value"] == pytest.approx(10 * 3.02 / NOMINAL_OHM, rel=0.02)


def test_an_sd_of_half_a_square_metre_on_a_paper_cone_is_red_with_sd_named(written):
    result = analyze_recording(read_recording(written), sd_m2=0.5)
    red = _red_codes(result)
    assert pl.EFFICIENCY in red          # 11.8 g on 0.5 m^2 is 0.024 kg/m^2: light, but a ribbon is lighter
    assert "Sd looks wrong" in red[pl.EFFICIENCY]["remedy"] and "mm, not m" not in red[pl.EFFICIENCY]["remedy"]


def test_a_wav_rate_that_contradicts_the_capture_is_red(written, tmp_path):
    result = analyze_recording(_variant(tmp_path, written, rate=44100))
    red = _red_codes(result)
    assert pl.SAMPLE_RATE in red and "44100 Hz" in red[pl.SAMPLE_RATE]["message"]
    assert "48000 Hz" in red[pl.SAMPLE_RATE]["message"]


def test_an_inverted_laser_is_red_with_the_sign_named_not_the_model_lab(written, tmp_path):
    result = analyze_recording(_variant(tmp_path, written, _scale("displacement", -1.0)))
    red = _red_codes(result)
    assert pl.LASER_SIGN in red and "laser's sign is inverted" in red[pl.LASER_SIGN]["remedy"]
    from analysis.validity.fit import qa_blocker
    verdict, why = qa_blocker(result.validity)
    assert "sign is inverted" in why


def test_a_low_q_driver_with_a_right_laser_is_not_judged_inverted():
    """A 6-inch driver damped hard (Rms 15 kg/s, Qms 0.28 < Qes 0.50): its resonance peak stays below 2 RE, so
    the first lines with |Z| > 2 RE are the coil's inductive rise, where Z - RE is j w Le and Bl line by line
    reads -w^2 Le Mms / Bl: the old check called the right laser inverted (152 degrees, red)."""
    from tests.builders import electrical
    values = electrical(5.7, 0.4e-3, 15e-3, 0.84e-3, 15.0, 7.0, L2=0.6e-3, R2=8.0, **{"lambda": 0.12})
    assert values["RES"] < values["RE"]                 # peak |Z| = RE + RES < 2 RE
    result = analyze_recording(_odd_recording(values), sd_m2=0.0104)
    assert result.parameters["Qms"].value < result.parameters["Qes"].value
    assert pl.LASER_SIGN not in _plausibility(result), result.validity
    assert result.validity.overall != "red", result.validity
