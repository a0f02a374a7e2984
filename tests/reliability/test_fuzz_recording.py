"""Recordings from damaged or hostile files: a Recording or one RecordingError line, never a traceback or a hang.

tests/analysis/recording/test_recording.py already flips bytes of one good WAV and puts
JSON-ish values at the sidecar's known keys. This adds what that does not
reach: WAV files built from random chunk lists (chunk ids, lying sizes, odd
'fmt ' contents, WAVE_FORMAT_EXTENSIBLE GUIDs), byte-level damage to the
sidecar's text, and the round trip: whatever read_recording accepts,
write_recording writes and read_recording reads back unchanged.
"""
from __future__ import annotations

import json
import struct

import numpy as np
import pytest
import scipy.io.wavfile
from hypothesis import example, given
from hypothesis import strategies as st

from analysis.recording.format import RecordingError, read_recording, write_recording
from tests.reliability.fuzzing import FUZZ, FUZZ_MANY, one_line

pytestmark = pytest.mark.timeout(60)

PERIOD = 32
GUID_TAIL = bytes.fromhex("000010008000" "00aa00389b71")


def sidecar(n_channels: int = 3, **extra) -> dict:
    names = [("voltage", "V"), ("current", "A"), ("displacement", "m"), ("aux", "")][:n_channels]
    return {"format": "linpar-recording/1",
            "channels": [{"signal": s, "unit": u, "scale": 1.0} for s, u in names],
            "excitation": {"period_samples": PERIOD, "settle_periods": 0}, **extra}


def chunk(cid: bytes, payload: bytes, declared: int | None = None) -> bytes:
    size = len(payload) if declared is None else declared
    return cid + struct.pack("<I", size & 0xFFFFFFFF) + payload + (b"\0" if len(payload) % 2 else b"")


def read_or_refuse(stem):
    """A Recording that keeps the format's promises, or None after checking the refusal's message."""
    try:
        rec = read_recording(stem)
    except RecordingError as exc:
        one_line(exc)
        return None
    assert rec.data.dtype == np.float64 and not rec.data.flags.writeable
    assert np.all(np.isfinite(rec.data)) and rec.n_periods >= 2
    assert {"voltage", "current"} <= {c.signal for c in rec.channels}
    return rec


# --- the WAV: random chunk lists -----------------------------------------------------------------

fmt_payloads = st.builds(
    lambda tag, channels, rate, bits, align, tail, cut: (
        struct.pack("<HHIIHH", tag, channels, rate, rate * max(align, 1) & 0xFFFFFFFF, align, bits)
        + (struct.pack("<HHI", 22, bits, 0) + struct.pack("<I", tag if tag != 0xFFFE else 3) + tail
           if tag == 0xFFFE else b""))[:cut],
    tag=st.sampled_from([1, 3, 0xFFFE, 2, 6, 0]),
    channels=st.sampled_from([0, 1, 2, 3, 4, 65535]),
    rate=st.sampled_from([0, 1, 8000, 48000, 2**32 - 1]),
    bits=st.sampled_from([0, 8, 16, 24, 32, 64, 7]),
    align=st.integers(0, 16),
    tail=st.sampled_from([GUID_TAIL, bytes(12), b"\xff" * 12]),
    cut=st.sampled_from([100, 40, 16, 15, 0]))
GOOD_FMT = struct.pack("<HHIIHH", 3, 3, 8000, 8000 * 12, 12, 32)
chunk_lists = st.lists(
    st.one_of(
        st.tuples(st.just(b"fmt "), fmt_payloads | st.just(GOOD_FMT), st.none()),
        st.tuples(st.just(b"data"), st.binary(max_size=24 * PERIOD), st.none()),
        st.tuples(st.sampled_from([b"fact", b"LIST", b"\0\0\0\0", b"data", b"fmt "]), st.binary(max_size=16),
                  st.one_of(st.none(), st.integers(0, 2**32 - 1)))),
    max_size=5)


@FUZZ_MANY
@given(chunks=chunk_lists, riff_size=st.one_of(st.none(), st.integers(0, 2**32 - 1)),
       form=st.sampled_from([b"WAVE", b"WAVX"]))
def test_wav_files_of_random_chunks_read_or_are_refused_naming_the_wav(tmp_path_factory, chunks, riff_size, form):
    folder = tmp_path_factory.mktemp("wav")
    body = form + b"".join(chunk(cid, payload, declared) for cid, payload, declared in chunks)
    size = len(body) if riff_size is None else riff_size
    (folder / "rec.wav").write_bytes(b"RIFF" + struct.pack("<I", size) + body)
    (folder / "rec.json").write_text(json.dumps(sidecar()))
    try:
        read_recording(folder / "rec")
    except RecordingError as exc:
        assert "rec.wav" in one_line(exc) or "rec.json" in str(exc)


def test_a_wav_of_many_tiny_chunks_is_read_in_linear_time(tmp_path):
    samples = (0.1 * np.ones((3 * PERIOD, 3))).astype("<f4").tobytes()
    fmt = struct.pack("<HHIIHH", 3, 3, 8000, 8000 * 12, 12, 32)
    body = b"WAVE" + chunk(b"fmt ", fmt) + chunk(b"junk", b"") * 200_000 + chunk(b"data", samples)
    (tmp_path / "rec.wav").write_bytes(b"RIFF" + struct.pack("<I", len(body)) + body)
    (tmp_path / "rec.json").write_text(json.dumps(sidecar()))
    assert read_recording(tmp_path / "rec").n_periods == 3   # and well inside the test's time limit


# --- the sidecar: damage to its bytes ----------------------------------------------------------------

GOOD_TEXT = json.dumps(sidecar(driver={"name": "Wöofer 6\"", "sd_m2": 0.0133}), indent=2).encode()
edits = st.lists(st.tuples(st.sampled_from(["replace", "insert", "delete"]), st.integers(0, len(GOOD_TEXT)),
                           st.sampled_from(list(b'{}[]",:0123456789-.eE \n\\tfnu\x00\xff\xc3') + [0x80])),
                 min_size=1, max_size=8)


def put_signals(folder, n_channels=3, n_periods=3):
    t = np.arange(n_periods * PERIOD)
    rows = [0.5 * np.sin(2 * np.pi * 3 * t / PERIOD + k) for k in range(n_channels)]
    scipy.io.wavfile.write(folder / "rec.wav", 8000, np.array(rows, dtype=np.float32).T.copy())


@FUZZ_MANY
@given(edits=edits)
def test_a_sidecar_with_damaged_bytes_reads_or_is_refused_in_one_line(tmp_path_factory, edits):
    folder = tmp_path_factory.mktemp("json")
    put_signals(folder)
    text = bytearray(GOOD_TEXT)
    for op, at, byte in edits:
        at = min(at, len(text))
        if op == "insert":
            text.insert(at, byte)
        elif op == "delete" and at < len(text):
            del text[at]
        elif at < len(text):
            text[at] = byte
    (folder / "rec.json").write_bytes(bytes(text))
    read_or_refuse(folder / "rec")


@pytest.mark.parametrize("text, words", [
    ('{"format": "linpar-recording/1", "x": ' + "1" * 5000 + "}", ["rec.json", "invalid JSON"]),   # was ValueError
    ('{"format": "linpar-recording/1", "x": "\\ud800"}', ["rec.json", "surrogate"]),   # read, then unwritable
    ('{"format": "linpar-recording/1", "driver": {"name": "\\udfff\\ud800"}}', ["surrogate"]),
    ("[" * 100_000 + "]" * 100_000, ["nested too deeply"]),
    ('{"format": "linpar-recording/1", "x": 1e999}', ["rec.json"]),
    ("\ufeff" * 3, ["rec.json"]),
    ("", ["rec.json"]),
])
def test_sidecars_that_once_escaped_as_other_errors_are_refused(tmp_path, text, words):
    put_signals(tmp_path)
    (tmp_path / "rec.json").write_text(text, encoding="utf-8", errors="surrogatepass")
    with pytest.raises(RecordingError) as info:
        read_recording(tmp_path / "rec")
    one_line(info.value, *words)


def test_a_sidecar_nested_just_below_the_recursion_limit_is_refused_cleanly(tmp_path):
    put_signals(tmp_path)
    for depth in (500, 900, 990, 2000):
        (tmp_path / "rec.json").write_text('{"format": "linpar-recording/1", "x": ' + "[" * depth + "]" * depth + "}")
        read_or_refuse(tmp_path / "rec")


# --- the round trip: what reads, writes and reads back the same ------------------------------------

json_leaves = (st.none() | st.booleans() | st.integers(-(10**30), 10**30) | st.floats(allow_nan=False,
                                                                                        allow_infinity=False)
               | st.text(alphabet=st.characters(codec="utf-8"), max_size=12))
json_values = st.recursive(json_leaves, lambda inner: st.lists(inner, max_size=3)
                           | st.dictionaries(st.text(alphabet=st.characters(codec="utf-8"), max_size=6), inner,
                                             max_size=3), max_leaves=10)
extra_keys = st.dictionaries(st.text(alphabet=st.characters(codec="utf-8"), min_size=1, max_size=10)
                             .filter(lambda k: k not in ("format", "channels", "excitation", "driver")),
                             json_values, max_size=4)


@FUZZ
@given(extra=extra_keys, channel_extra=st.dictionaries(st.sampled_from(["gain", "note", "ü"]), json_values,
                                                       max_size=2),
       driver_name=st.text(alphabet=st.characters(codec="utf-8"), max_size=20),
       scale=st.sampled_from([1.0, 2.5e-3, 1e30, -1.0, 7]))
@example(extra={"x": 10**4000}, channel_extra={}, driver_name="", scale=1.0)
@example(extra={"\U0001f50a": "\u202e\x00"}, channel_extra={"note": "\r\n"}, driver_name="\ud83d\udd0a", scale=1.0)
def test_whatever_reads_is_written_and_read_back_unchanged(tmp_path_factory, extra, channel_extra, driver_name,
                                                           scale):
    folder = tmp_path_factory.mktemp("rt")
    put_signals(folder)
    doc = sidecar(driver={"name": driver_name}, **extra)
    doc["channels"][1].update(channel_extra, scale=scale)
    (folder / "rec.json").write_text(json.dumps(doc), encoding="utf-8", errors="surrogatepass")
    first = read_or_refuse(folder / "rec")
    if first is None:
        return
    write_recording(folder / "copy", first)
    again = read_recording(folder / "copy")
    assert np.array_equal(again.data, first.data)
    assert again.channels == first.channels and [c.extra for c in again.channels] == [c.extra for c in first.channels]
    assert dict(again.extra) == dict(first.extra) and dict(again.driver) == dict(first.driver)
    assert (again.period_samples, again.settle_periods, again.excited_bins) == \
           (first.period_samples, first.settle_periods, first.excited_bins)
    assert sorted(p.name for p in folder.iterdir()) == ["copy.json", "copy.wav", "rec.json", "rec.wav"]
