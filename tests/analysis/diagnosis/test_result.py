"""The diagnosis's text and JSON: one move marked taken, the columns apart, every step's candidates, the stop.

The paper driver with a laser delay of 300 us (no effect of the default model has it), diagnosed from the
default model: the path adds delay-x and ends at the noise floor.
"""
import pytest

from analysis.diagnosis.candidates import diagnose
from analysis.diagnosis.result import diagnosis_json, format_diagnosis
from analysis.diagnosis.words import STOP_NOISE_FLOOR
from analysis.effects import parse_effects
from analysis.fit.least_squares import FitData
from analysis.model.composed import Model
from analysis.spectra import estimate_spectra
from tests.builders import PAPER, TYPICAL_NOISE, recording


@pytest.fixture(scope="module")
def delayed(pool, mt):
    effects = "lr2,creep-log,delay-x"
    rec = recording({**PAPER.parameters, "tau_x": 300e-6}, effects, noise=TYPICAL_NOISE, n_periods=8, seed=3,
                    mt=mt)
    return diagnose(FitData.from_spectra(estimate_spectra(rec)), Model(parse_effects("lr2,creep-log")),
                    executor=pool)


def _move(c) -> str:
    return f"{c.action} {c.label}" + (f" (for {c.replaces.id})" if c.replaces else "")


def test_the_table_marks_the_one_move_taken_and_keeps_its_columns_apart(delayed):
    assert delayed.steps[0].chosen.effect.id == "delay-x"
    assert sum(c.accepted for c in delayed.first_candidates) > 1     # more than one is acceptable
    text = format_diagnosis(delayed)
    header = next(line for line in text.splitlines() if line.startswith("rank"))
    assert "judgement" in header and "taken?" not in header
    rows = [line for line in text.splitlines() if line[:1].isdigit() and "  " in line]
    assert sum(" taken " in row for row in rows) == 1
    taken = next(row for row in rows if " taken " in row)
    assert f" {_move(delayed.steps[0].chosen)} " in taken
    assert not any(" yes " in row for row in rows)
    # Every move is followed by a space: a long one does not run into the delta BIC.
    for c in delayed.first_candidates:
        assert any(f" {_move(c)} " in row for row in rows), _move(c)


def test_each_step_says_what_it_ranked_and_took_and_the_path_why_it_stopped(delayed):
    doc = diagnosis_json(delayed)
    first, last = doc["steps"][0], doc["steps"][-1]
    assert first["chosen"] == "delay-x" and first["chosen_action"] == "add"
    assert [c["effect"] for c in first["candidates"]] == [c["effect"] for c in doc["candidates"]]
    assert last["at_noise_floor"] and last["candidates"] == [] and last["chosen"] is None
    assert doc["stopped"]["reason"] == STOP_NOISE_FLOOR and "noise" in doc["stopped"]["text"]
    text = format_diagnosis(delayed)
    assert f"ranked {len(delayed.first_candidates)} candidates" in text
    assert "stopped: " + doc["stopped"]["text"] in text
    # A path that took a step before meeting the noise: what it took did the explaining.
    assert "no effect, of the catalogue or of your own, has anything to explain" not in doc["verdict_text"]
    assert "nothing is left to explain" in doc["verdict_text"]
