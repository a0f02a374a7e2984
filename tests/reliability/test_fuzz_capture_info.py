"""The sidecar's "capture" object: a CaptureInfo whose findings can be made, or one CaptureInfoError line.

A recording's sidecar may carry any JSON under "capture" (read_recording
keeps unknown keys as they are), so the analysis is where it is judged:
analyze_recording refuses a broken one at once, before the fit, as a
RecordingError naming the sidecar and the key, and `linpar analyze` says so
in one line (it used to fit for seconds, then end in a CaptureInfoError
traceback; an integer beyond the float range was an OverflowError).
"""
from __future__ import annotations

import json
import time

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from analysis.pipeline import analyze_recording
from analysis.recording.format import RecordingError, read_recording, write_recording
from analysis.thresholds import DEFAULT_THRESHOLDS
from analysis.validity.capture import CaptureInfo, CaptureInfoError, capture_findings
from app.cli import main as linpar
from tests.builders import TYPICAL_NOISE, multitone, recording
from tests.pace import paced
from tests.reliability.fuzzing import FUZZ_MANY, one_line

pytestmark = pytest.mark.timeout(60)

KEYS = ["full_scale_fraction", "clipped_samples", "dropouts", "xruns", "laser_samples", "laser_error_counts",
        "laser_out_of_range_share"]
leaves = st.one_of(st.none(), st.booleans(), st.integers(-5, 10**6), st.just(10**400), st.floats(),
                   st.text(max_size=6), st.sampled_from(["262076", "262077", "0x1F", "١", " 7 ", "-1"]))
values = st.recursive(leaves, lambda inner: st.lists(inner, max_size=3) | st.dictionaries(
    st.sampled_from(["voltage", "current", "displacement", "262076", "262078", "abc", ""]) | st.text(max_size=4),
    inner, max_size=3), max_leaves=8)
captures = st.one_of(st.dictionaries(st.sampled_from(KEYS) | st.text(max_size=5), values, max_size=5), values)


@FUZZ_MANY
@given(doc=captures)
@example(doc={"xruns": 10**400})                                  # was OverflowError
@example(doc={"laser_error_counts": {"1" * 5000: 1}})
@example(doc={"full_scale_fraction": {"voltage": float("nan")}})
@example(doc={"laser_error_counts": {"262076": 3, "262078": 10**6}, "laser_samples": 0})
def test_capture_objects_give_capture_info_and_findings_or_one_error_line(doc):
    try:
        info = CaptureInfo.from_json(doc)
    except CaptureInfoError as exc:
        one_line(exc)
        assert str(exc).startswith("capture")
        return
    again = CaptureInfo.from_json(json.loads(json.dumps(info.as_json())))
    assert again == info
    for present in (("voltage", "current"), ("voltage", "current", "displacement")):
        found = capture_findings(info, present, 4096, DEFAULT_THRESHOLDS)
        for findings in found.values():
            for f in findings:
                assert "\n" not in f.message and np.isfinite(f.value)


@pytest.fixture(scope="module")
def short_recording(tmp_path_factory):
    rec = recording(noise=TYPICAL_NOISE, n_periods=3, seed=7, mt=multitone(period_samples=4096, f_min=20.0))
    path = tmp_path_factory.mktemp("rec") / "rec"
    write_recording(path, rec)
    return path


@pytest.mark.parametrize("capture, key", [({"xruns": -3}, "capture.xruns"), ({"xruns": 10**400}, "capture.xruns"),
                                          ({"laser_error_counts": {"x": 1}}, "laser_error_counts"),
                                          ("all fine", "capture"), ({"bogus": 1}, "unknown")])
def test_a_broken_capture_key_is_refused_before_the_fit_naming_the_sidecar(short_recording, tmp_path, capsys,
                                                                        capture, key):
    doc = json.loads(short_recording.with_suffix(".json").read_text())
    doc["capture"] = capture
    (tmp_path / "rec.wav").write_bytes(short_recording.with_suffix(".wav").read_bytes())
    (tmp_path / "rec.json").write_text(json.dumps(doc))
    rec = read_recording(tmp_path / "rec")                 # the recording format itself has no opinion
    started = time.perf_counter()
    with pytest.raises(RecordingError) as info:
        analyze_recording(rec)
    assert time.perf_counter() - started < paced(1.0)            # refused before the spectra and the fit
    one_line(info.value, str(tmp_path / "rec.json"), key)
    assert linpar(["analyze", str(tmp_path / "rec")]) == 2
    out, err = capsys.readouterr()
    assert err.startswith("linpar: error: ") and err.count("\n") == 1 and key in err
