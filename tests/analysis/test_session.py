"""The recording's "session" (analysis.session): read as one-line strings whatever the file holds, and the
header that reports and exports share."""
from __future__ import annotations

from importlib.metadata import version

from analysis.recording.format import make_recording
from analysis.session import new_session, recording_header, session_of, software
from tests.builders import recording


def with_session(session):
    rec = recording(n_periods=2, seed=5)
    return make_recording(rec.sample_rate, {c.signal: rec.signal(c.signal) for c in rec.channels},
                          rec.period_samples, rec.settle_periods, rec.excited_bins,
                          {"name": "W18", "serial": "0042"}, {"session": session})


def test_a_new_session_is_dated_and_names_the_software():
    session = new_session("ana", "bench 3", "woofer")
    assert session["software"] == software() == f"linpar {version('linpar')}"
    assert session["measured_at"].endswith("Z") and (session["operator"], session["station"]) == ("ana", "bench 3")
    assert "operator" not in new_session(station="bench 3")        # nothing said, nothing written


def test_what_a_sidecar_holds_is_read_as_one_line_text():
    rec = with_session({"operator": "ana\nrm -rf", "station": 42, "template": ["x"], "software": "linpar 0.1.0",
                        "unknown": "kept out"})
    assert session_of(rec) == {"operator": "ana rm -rf", "software": "linpar 0.1.0"}
    assert session_of(with_session("not an object")) == {}
    assert recording_header(rec) == {"driver": "W18", "serial": "0042", "operator": "ana rm -rf",
                                     "software": "linpar 0.1.0"}
