"""The recording format: what is accepted, what comes back, and what is refused with which message.

Test files are written independently of the module under test (stdlib `wave`,
scipy.io.wavfile, or RIFF chunks packed by hand), so reader and writer cannot
share a mistake.
"""
from __future__ import annotations

import copy
import dataclasses
import json
import struct
import wave
from pathlib import Path

import numpy as np
import pytest
import scipy.io.wavfile
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from analysis.recording.format import (Channel, Recording, RecordingError, make_recording, read_recording,
                                write_recording)

RATE = 8000
PERIOD = 64
SPEC_SIDECAR = """{
  "format": "linpar-recording/1",
  "channels": [
    {"signal": "voltage",      "unit": "V", "scale": 1.0},
    {"signal": "current",      "unit": "A", "scale": 1.0},
    {"signal": "displacement", "unit": "m", "scale": 1.0}
  ],
  "excitation": {"period_samples": 16384, "settle_periods": 1},
  "driver": {"name": "Paper driver", "sd_m2": 0.0133}
}
"""
KSDATAFORMAT_TAIL = bytes.fromhex("000010008000" "00aa00389b71")


# --- building test files without the module under test -------------------------

def good_doc(**excitation) -> dict:
    return {
        "format": "linpar-recording/1",
        "channels": [{"signal": "voltage", "unit": "V", "scale": 1.0},
                     {"signal": "current", "unit": "A", "scale": 1.0},
                     {"signal": "displacement", "unit": "m", "scale": 1.0}],
        "excitation": {"period_samples": PERIOD, "settle_periods": 0, **excitation},
        "driver": {"name": "Test driver", "sd_m2": 0.0133},
    }


def signals(n_samples: int, n_channels: int = 3) -> np.ndarray:
    t = np.arange(n_samples)
    rows = [0.5 * np.sin(2 * np.pi * 3 * t / PERIOD), 0.1 * np.cos(2 * np.pi * 5 * t / PERIOD),
            1e-3 * np.sin(2 * np.pi * 7 * t / PERIOD), 0.25 * np.cos(2 * np.pi * t / PERIOD)]
    return np.array(rows[:n_channels], dtype=np.float32)


def put_sidecar(stem: Path, doc) -> Path:
    path = stem.with_name(stem.name + ".json")
    if isinstance(doc, bytes):
        path.write_bytes(doc)
    else:
        path.write_text(doc if isinstance(doc, str) else json.dumps(doc, indent=2), encoding="utf-8")
    return path


def put_float_wav(stem: Path, samples: np.ndarray, rate: int = RATE) -> Path:
    path = stem.with_name(stem.name + ".wav")
    scipy.io.wavfile.write(path, rate, np.ascontiguousarray(samples.T))
    return path


def put_pcm_wav(stem: Path, ints: np.ndarray, width: int, rate: int = RATE) -> Path:
    """Integer PCM through the stdlib `wave` module; ints shape (n_channels, n_frames)."""
    path = stem.with_name(stem.name + ".wav")
    frames = b"".join(int(v).to_bytes(width, "little", signed=width > 1) for v in ints.T.reshape(-1))
    with wave.open(str(path), "wb") as f:
        f.setnchannels(ints.shape[0])
        f.setsampwidth(width)
        f.setframerate(rate)
        f.writeframes(frames)
    return path


def riff(fmt: bytes | None, data: bytes | None, before_data: bytes = b"") -> bytes:
    """A RIFF/WAVE file packed by hand; None leaves a chunk out."""
    def chunk(cid, payload):
        return cid + struct.pack("<I", len(payload)) + payload + (b"\0" if len(payload) % 2 else b"")
    body = b"WAVE" + (chunk(b"fmt ", fmt) if fmt is not None else b"") + before_data
    body += chunk(b"data", data) if data is not None else b""
    return b"RIFF" + struct.pack("<I", len(body)) + body


def fmt_chunk(tag: int, channels: int, bits: int, rate: int = RATE, block_align: int | None = None) -> bytes:
    align = channels * bits // 8 if block_align is None else block_align
    return struct.pack("<HHIIHH", tag, channels, rate, rate * align, align, bits)


def extensible_fmt(code: int, channels: int, bits: int, tail: bytes = KSDATAFORMAT_TAIL) -> bytes:
    return fmt_chunk(0xFFFE, channels, bits) + struct.pack("<HHI", 22, bits, 0) + struct.pack("<I", code) + tail


def good_recording_files(tmp_path: Path, n_periods: int = 3, **excitation) -> Path:
    stem = tmp_path / "rec"
    put_float_wav(stem, signals(n_periods * PERIOD))
    put_sidecar(stem, good_doc(**excitation))
    return stem


def refused(path, *fragments: str) -> str:
    """The message of the RecordingError that reading `path` raises; it must hold every fragment."""
    with pytest.raises(RecordingError) as info:
        read_recording(path)
    message = str(info.value)
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, f"{fragment!r} not in {message!r}"
    return message


# --- accepted files ---------------------------------------------------------------

def test_the_spec_example_sidecar_is_read_as_written(tmp_path):
    stem = tmp_path / "paper"
    put_sidecar(stem, SPEC_SIDECAR)
    samples = np.zeros((3, 3 * 16384 + 100), dtype=np.float32)
    samples[0, 16384:] = 1.0           # the settle period is zero, the analysed part one
    put_float_wav(stem, samples, rate=48000)

    rec = read_recording(stem)

    assert [(c.signal, c.unit, c.scale) for c in rec.channels] == [
        ("voltage", "V", 1.0), ("current", "A", 1.0), ("displacement", "m", 1.0)]
    assert (rec.sample_rate, rec.period_samples, rec.settle_periods) == (48000, 16384, 1)
    assert rec.excited_bins is None
    assert dict(rec.driver) == {"name": "Paper driver", "sd_m2": 0.0133}
    assert dict(rec.extra) == {}
    assert rec.n_periods == 2          # 3 whole periods, 1 to settle, 100 samples left over
    assert rec.periods("voltage").shape == (2, 16384)
    assert np.all(rec.periods("voltage") == 1.0)
    assert rec.duration_s == pytest.approx((3 * 16384 + 100) / 48000)


@pytest.mark.parametrize("width, full_scale", [(2, 2**15), (3, 2**23), (4, 2**31)])
def test_integer_pcm_is_read_as_a_fraction_of_full_scale_times_scale(tmp_path, width, full_scale):
    stem = tmp_path / "pcm"
    ints = np.array([[-full_scale, full_scale // 2, full_scale - 1, 0, 1, -1],
                     [full_scale // 4, -full_scale // 2, 3, -3, 0, full_scale - 1],
                     [7, -7, full_scale // 8, 0, -full_scale, 2]])
    put_pcm_wav(stem, ints, width)
    doc = good_doc(period_samples=3)
    for channel, scale in zip(doc["channels"], (2.0, 0.5, -1e-3)):
        channel["scale"] = scale
    put_sidecar(stem, doc)

    rec = read_recording(stem)

    expected = ints / full_scale * np.array([[2.0], [0.5], [-1e-3]])
    np.testing.assert_array_equal(rec.data, expected)
    assert rec.data[0, 0] == -2.0          # the most negative code is exactly -1 before scale


@pytest.mark.parametrize("code, bits, dtype", [(1, 24, None), (1, 16, "<i2"), (3, 32, "<f4")])
def test_wave_format_extensible_is_accepted(tmp_path, code, bits, dtype):
    stem = tmp_path / "ext"
    if bits == 24:
        values = [-2**23, 2**22, 5, -5, 0, 2**23 - 1] * 3      # 6 frames x 3 channels
        data = b"".join(v.to_bytes(3, "little", signed=True) for v in values)
        expected = np.array(values, dtype=float).reshape(-1, 3).T / 2**23
    else:
        values = np.arange(18, dtype=dtype) * (1 if code == 1 else 0.125)
        data = values.tobytes()
        expected = values.astype(float).reshape(-1, 3).T / (2**15 if code == 1 else 1)
    (tmp_path / "ext.wav").write_bytes(riff(extensible_fmt(code, 3, bits), data))
    put_sidecar(stem, good_doc(period_samples=3))

    np.testing.assert_array_equal(read_recording(stem).data, expected)


def test_chunks_an_audio_editor_adds_are_skipped(tmp_path):
    stem = tmp_path / "edited"
    samples = signals(2 * PERIOD)
    odd_list = b"LIST" + struct.pack("<I", 5) + b"INFOx" + b"\0"    # odd size, padded
    (tmp_path / "edited.wav").write_bytes(riff(fmt_chunk(3, 3, 32), samples.T.tobytes(), before_data=odd_list))
    put_sidecar(stem, good_doc())

    np.testing.assert_array_equal(read_recording(stem).data, samples)


@pytest.mark.parametrize("form", ["stem", "stem.wav", "stem.json", "str"])
def test_a_recording_is_found_from_its_stem_wav_or_json(tmp_path, form):
    stem = good_recording_files(tmp_path)
    path = {"stem": stem, "stem.wav": tmp_path / "rec.wav", "stem.json": tmp_path / "rec.json",
            "str": str(stem)}[form]

    rec = read_recording(path)

    assert rec.source == tmp_path / "rec.wav"
    np.testing.assert_array_equal(rec.data, signals(3 * PERIOD))


def test_a_stem_with_dots_keeps_them(tmp_path):
    stem = tmp_path / "sweep.2024-05-01"
    put_float_wav(stem, signals(2 * PERIOD))
    put_sidecar(stem, good_doc())

    assert read_recording(stem).source == tmp_path / "sweep.2024-05-01.wav"


def test_the_data_are_read_only_float64_and_periods_are_views_after_settling(tmp_path):
    stem = tmp_path / "p"
    samples = np.tile(np.arange(PERIOD, dtype=np.float32), (3, 1))
    samples = np.concatenate([samples * 0 - 1, samples, samples * 2, samples[:, :10]], axis=1)
    put_float_wav(stem, samples)
    put_sidecar(stem, good_doc(settle_periods=1))

    rec = read_recording(stem)

    assert rec.data.dtype == np.float64 and rec.data.flags.c_contiguous and not rec.data.flags.writeable
    assert rec.n_periods == 2
    periods = rec.periods("current")
    np.testing.assert_array_equal(periods, [np.arange(PERIOD), 2 * np.arange(PERIOD)])
    assert np.shares_memory(periods, rec.data)
    assert rec.signal("microphone") is None
    with pytest.raises(KeyError, match="microphone"):
        rec.periods("microphone")


# --- writing ----------------------------------------------------------------------

def test_round_trip_is_exact_to_float32_and_keeps_every_key(tmp_path):
    t = np.arange(5 * PERIOD)
    rec = make_recording(
        RATE, {"voltage": 2.83 * np.sin(t / 3), "current": 0.3 * np.cos(t / 5),
               "displacement": 1e-4 * np.sin(t / 7), "microphone": 0.01 * np.sin(t / 11)},
        period_samples=PERIOD, settle_periods=1, excited_bins=np.array([9, 3, 5]),
        driver={"name": "Wöofer", "sd_m2": 0.0133, "serial": "A-17"},
        extra={"operator": "ana", "level_v": np.float64(2.83), "notes": {"room": 21.5, "tags": [1, 2]}})

    wav, sidecar = write_recording(tmp_path / "rt", rec)
    back = read_recording(wav)

    assert (wav, sidecar) == (tmp_path / "rt.wav", tmp_path / "rt.json")
    np.testing.assert_array_equal(back.data, rec.data.astype(np.float32).astype(np.float64))
    assert np.max(np.abs(back.data - rec.data) / np.max(np.abs(rec.data), axis=1, keepdims=True)) < 2**-23
    assert back.channels == rec.channels
    assert [c.unit for c in back.channels] == ["V", "A", "m", ""]
    assert (back.sample_rate, back.period_samples, back.settle_periods) == (RATE, PERIOD, 1)
    assert back.excited_bins == (3, 5, 9)
    assert dict(back.driver) == {"name": "Wöofer", "sd_m2": 0.0133, "serial": "A-17"}
    assert dict(back.extra) == {"operator": "ana", "level_v": 2.83, "notes": {"room": 21.5, "tags": [1, 2]}}


def test_the_written_wav_is_32_bit_float_that_scipy_reads_alike(tmp_path):
    rec = make_recording(RATE, {"voltage": np.linspace(-1, 1, 2 * PERIOD), "current": np.zeros(2 * PERIOD)},
                         period_samples=PERIOD)
    wav, _ = write_recording(tmp_path / "w", rec)

    blob = wav.read_bytes()
    tag, channels, rate, _, _, bits = struct.unpack_from("<HHIIHH", blob, 20)
    assert (blob[:4], blob[8:16], tag, channels, rate, bits) == (b"RIFF", b"WAVEfmt ", 3, 2, RATE, 32)
    rate, samples = scipy.io.wavfile.read(wav)
    assert samples.dtype == np.float32
    np.testing.assert_array_equal(samples.T, rec.data.astype(np.float32))


def test_unknown_keys_in_channels_and_excitation_survive_a_round_trip(tmp_path):
    stem = tmp_path / "in"
    put_float_wav(stem, signals(2 * PERIOD))
    doc = good_doc(excited_bins=[3, 5, 7], generator={"kind": "multitone", "crest_db": 6.1})
    doc["channels"][2]["sensor"] = {"model": "optoNCDT", "range_m": 0.01}
    doc["channels"][0]["scale"] = 20.0
    doc["room"] = "lab 2"
    put_sidecar(stem, doc)

    wav, sidecar = write_recording(tmp_path / "out", read_recording(stem))

    assert json.loads(sidecar.read_text(encoding="utf-8")) == doc
    rate, samples = scipy.io.wavfile.read(wav)      # samples are written unscaled: data / scale
    np.testing.assert_array_equal(samples.T, signals(2 * PERIOD))


def test_writing_over_a_recording_replaces_it_and_leaves_no_temporary_files(tmp_path):
    def rec(level):
        return make_recording(RATE, {"voltage": np.full(2 * PERIOD, level), "current": np.ones(2 * PERIOD)},
                              period_samples=PERIOD, extra={"level": level})
    write_recording(tmp_path / "r.json", rec(1.0))
    write_recording(tmp_path / "r.json", rec(2.0))

    back = read_recording(tmp_path / "r")
    assert np.all(back.signal("voltage") == 2.0) and back.extra["level"] == 2.0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.json", "r.wav"]


def test_data_that_overflow_float32_are_refused_and_nothing_is_written(tmp_path):
    rec = make_recording(RATE, {"voltage": np.full(2 * PERIOD, 1e10), "current": np.ones(2 * PERIOD)},
                         period_samples=PERIOD)
    tiny = dataclasses.replace(rec, channels=(Channel("voltage", "V", 1e-30), rec.channels[1]))

    with pytest.raises(RecordingError, match=r"o\.wav.*'voltage'.*sample 0 is infinite"):
        write_recording(tmp_path / "o", tiny)
    assert list(tmp_path.iterdir()) == []


# --- built in memory --------------------------------------------------------------

def test_make_recording_uses_si_units_and_scale_one(tmp_path):
    rec = make_recording(RATE, {"current": np.zeros(2 * PERIOD), "voltage": np.ones(2 * PERIOD)}, PERIOD)
    assert [(c.signal, c.unit, c.scale) for c in rec.channels] == [("current", "A", 1.0), ("voltage", "V", 1.0)]
    assert rec.source is None and rec.excited_bins is None


@pytest.mark.parametrize("kwargs, fragments", [
    ({"signals": {"voltage": np.ones(128), "current": np.ones(100)}},
     ["signal 'current': 100 samples", "expected 128 like 'voltage'"]),
    ({"signals": {"voltage": np.ones(128)}}, ["channels: no 'current' channel", "'voltage' and a 'current'"]),
    ({"signals": {"voltage": np.r_[0, 0, 0, np.nan, np.zeros(124)], "current": np.ones(128)}},
     ["channel 'voltage' (channel 1): sample 3 is NaN", "finite"]),
    ({"signals": {"voltage": np.ones((2, 64)), "current": np.ones(128)}}, ["signal 'voltage'", "1-D array"]),
    ({"signals": {"voltage": np.ones(128), "current": np.ones(128) * 1j}}, ["signal 'current'", "real numbers"]),
    ({"signals": {"voltage": np.ones(128), "current": ["1"] * 127 + ["x"]}}, ["signal 'current'", "real numbers"]),
    ({"signals": [np.ones(128)]}, ["signals: found [array", "mapping of name -> samples"]),
    ({"sample_rate": 0}, ["sample rate: found 0", "a sample rate: a whole number from 1000 to 1e+06 Hz"]),
    ({"sample_rate": 48000.0}, ["sample rate: found 48000.0", "a whole number"]),
    ({"sample_rate": 4294967295}, ["sample rate: found 4294967295", "a sample rate"]),
    ({"period_samples": 100}, ["excitation: 128 samples hold 1 whole periods", "at least 2"]),
    ({"excited_bins": [1, 33]}, ["excitation.excited_bins[1]: found 33", "1..32"]),
    ({"driver": {"sd_m2": 0}}, ["driver.sd_m2: found 0", "an effective radiating area Sd"]),
    ({"driver": {"sd_m2": 1e300}}, ["driver.sd_m2: found 1e+300", "from 0.0001 to 1 m^2"]),
    ({"extra": {"format": "x"}}, ["extra: key 'format'", "other than format"]),
    ({"extra": {"gain": float("nan")}}, ["gain: found nan", "JSON value"]),
    ({"extra": {"when": object()}}, ["when: found <object", "JSON value"]),
])
def test_make_recording_refuses_what_a_file_could_not_hold(kwargs, fragments):
    args = {"sample_rate": RATE, "signals": {"voltage": np.ones(128), "current": np.ones(128)},
            "period_samples": PERIOD, **kwargs}
    with pytest.raises(RecordingError) as info:
        make_recording(**args)
    message = str(info.value)
    assert message.startswith("<in memory>: ") and "\n" not in message
    for fragment in fragments:
        assert fragment in message, f"{fragment!r} not in {message!r}"


def test_every_construction_is_checked_not_only_reading(tmp_path):
    rec = read_recording(good_recording_files(tmp_path))
    data = rec.data.copy()
    data[2, 5] = np.inf

    with pytest.raises(RecordingError, match=r"rec\.wav: channel 'displacement' \(channel 3\): sample 5 is infinite"):
        dataclasses.replace(rec, data=data)
    with pytest.raises(RecordingError, match=r"rec\.json: channels\[1\]\.unit: found 'mA'"):
        Recording(RATE, (rec.channels[0], Channel("current", "mA", 1.0)), data[:2], PERIOD, source=rec.source)


# --- refused sidecars -------------------------------------------------------------

def _set(path, value):
    def mutate(doc):
        *parents, last = path
        target = doc
        for key in parents:
            target = target[key]
        if value is _DELETE:
            del target[last]
        else:
            target[last] = value
    return mutate


_DELETE = object()

BAD_SIDECARS = {
    "format missing": (_set(["format"], _DELETE), ["format: missing", "exactly 'linpar-recording/1'"]),
    "format wrong": (_set(["format"], "linpar-recording/2"),
                     ["format: found 'linpar-recording/2'", "exactly 'linpar-recording/1'"]),
    "channels missing": (_set(["channels"], _DELETE), ["channels: missing", "list of {signal, unit, scale}"]),
    "channels empty": (_set(["channels"], []), ["channels: found []", "non-empty list"]),
    "channels an object": (_set(["channels"], {}), ["channels: found a JSON object", "non-empty list"]),
    "channel a string": (_set(["channels", 1], "current"),
                         ["channels[1]: found a JSON string", "signal, unit and scale"]),
    "signal missing": (_set(["channels", 0, "signal"], _DELETE), ["channels[0].signal: missing", "signal name"]),
    "unit missing": (_set(["channels", 1, "unit"], _DELETE), ["channels[1].unit: missing", "'A' for current"]),
    "scale missing": (_set(["channels", 2, "scale"], _DELETE),
                      ["channels[2].scale: missing", "finite nonzero number"]),
    "scale zero": (_set(["channels", 0, "scale"], 0), ["channels[0].scale: found 0 for signal 'voltage'",
                                                       "finite nonzero number"]),
    "scale a string": (_set(["channels", 0, "scale"], "1.0"), ["channels[0].scale: found '1.0'"]),
    "scale a boolean": (_set(["channels", 0, "scale"], True), ["channels[0].scale: found True"]),
    "scale beyond float": (_set(["channels", 0, "scale"], 10**400), ["channels[0].scale: found 1000"]),
    "current in mA": (_set(["channels", 1, "unit"], "mA"),
                      ["channels[1].unit: found 'mA' for signal 'current'", "expected 'A' for current"]),
    "displacement in mm": (_set(["channels", 2, "unit"], "mm"), ["channels[2].unit: found 'mm'", "'m' for"]),
    "signal empty": (_set(["channels", 2, "signal"], ""), ["channels[2].signal: found ''", "non-empty string"]),
    "signal twice": (_set(["channels", 2, "signal"], "voltage"),
                     ["channels[2].signal: 'voltage' again (first in channels[0])", "each signal once"]),
    "no current": (_set(["channels", 1, "signal"], "microphone"),
                   ["channels: no 'current' channel (found 'voltage', 'microphone', 'displacement')"]),
    "no voltage": (_set(["channels", 0, "signal"], "amplifier"), ["channels: no 'voltage' channel"]),
    "excitation missing": (_set(["excitation"], _DELETE), ["excitation: missing", "with period_samples"]),
    "excitation a list": (_set(["excitation"], [64]), ["excitation: found a JSON array"]),
    "period missing": (_set(["excitation", "period_samples"], _DELETE),
                       ["excitation.period_samples: missing", "positive integer"]),
    "period zero": (_set(["excitation", "period_samples"], 0),
                    ["excitation.period_samples: found 0", "a period length: a whole number"]),
    "period a float": (_set(["excitation", "period_samples"], 64.0), ["excitation.period_samples: found 64.0"]),
    "period a boolean": (_set(["excitation", "period_samples"], True), ["excitation.period_samples: found True"]),
    "settle negative": (_set(["excitation", "settle_periods"], -1),
                        ["excitation.settle_periods: found -1", "non-negative integer"]),
    "settle a string": (_set(["excitation", "settle_periods"], "1"), ["excitation.settle_periods: found '1'"]),
    "bin zero": (_set(["excitation", "excited_bins"], [3, 0]), ["excitation.excited_bins[1]: found 0", "1..32"]),
    "bin above nyquist": (_set(["excitation", "excited_bins"], [33]), ["excited_bins[0]: found 33", "1..32"]),
    "bin twice": (_set(["excitation", "excited_bins"], [3, 5, 3]), ["excited_bins[2]: 3 again", "distinct"]),
    "bin a float": (_set(["excitation", "excited_bins"], [3.0]), ["excited_bins[0]: found 3.0", "integers"]),
    "bins not a list": (_set(["excitation", "excited_bins"], 5), ["excitation.excited_bins: found 5"]),
    "bins empty": (_set(["excitation", "excited_bins"], []), ["excitation.excited_bins: found an empty list"]),
    "sd negative": (_set(["driver", "sd_m2"], -0.01), ["driver.sd_m2: found -0.01", "m^2"]),
    "sd a string": (_set(["driver", "sd_m2"], "133 cm2"), ["driver.sd_m2: found '133 cm2'"]),
    "driver a list": (_set(["driver"], ["x"]), ["driver: found ['x']", "an object"]),
    "driver name a number": (_set(["driver", "name"], 3), ["driver.name: found 3", "a string"]),
}


@pytest.mark.parametrize("mutate, fragments", BAD_SIDECARS.values(), ids=BAD_SIDECARS.keys())
def test_a_sidecar_that_breaks_a_rule_is_refused_naming_the_key(tmp_path, mutate, fragments):
    stem = good_recording_files(tmp_path)
    doc = copy.deepcopy(good_doc())
    mutate(doc)
    put_sidecar(stem, doc)

    message = refused(stem, *fragments)
    assert message.startswith(f"{tmp_path / 'rec.json'}: ")


@pytest.mark.parametrize("text, fragments", [
    ('{\n "format": "linpar-recording/1"\n "channels": []\n}', ["invalid JSON at line 3, column 2",
                                                               "Expecting ',' delimiter"]),
    ("", ["invalid JSON at line 1"]),
    (json.dumps(good_doc(), indent=2).replace('"scale": 1.0', '"scale": NaN', 1),
     ["invalid JSON at line 7: NaN is not a JSON number"]),
    ("[1, 2]", ["found a JSON array at the top, expected a JSON object"]),
    ('"linpar-recording/1"', ["found a JSON string at the top"]),
    ("[" * 100_000, ["JSON"]),
], ids=["missing comma", "empty", "NaN", "array", "string", "deeply nested"])
def test_a_sidecar_that_is_not_a_json_object_is_refused_saying_where(tmp_path, text, fragments):
    stem = good_recording_files(tmp_path)
    put_sidecar(stem, text)

    assert refused(stem, *fragments).startswith(f"{tmp_path / 'rec.json'}: ")


def test_a_sidecar_that_is_not_utf8_is_refused(tmp_path):
    stem = good_recording_files(tmp_path)
    put_sidecar(stem, json.dumps(good_doc()).replace("Test", "T\u00e9st").encode("latin-1"))
    refused(stem, "rec.json: not UTF-8", "UTF-8 JSON object")


def test_a_sidecar_with_a_byte_order_mark_is_accepted(tmp_path):
    stem = good_recording_files(tmp_path)
    put_sidecar(stem, b"\xef\xbb\xbf" + json.dumps(good_doc()).encode("utf-8"))
    assert read_recording(stem).driver["name"] == "Test driver"


@pytest.mark.parametrize("present, missing, what", [("wav", "json", "sidecar"), ("json", "wav", "signals")])
def test_a_missing_file_of_the_pair_is_named(tmp_path, present, missing, what):
    stem = good_recording_files(tmp_path)
    (tmp_path / f"rec.{missing}").unlink()
    refused(tmp_path / f"rec.{present}", f"{tmp_path / ('rec.' + missing)}: missing", what)


# --- refused samples ----------------------------------------------------------------

@pytest.mark.parametrize("row, index, value, word", [(1, 70, np.nan, "NaN"), (2, 0, -np.inf, "infinite")])
def test_non_finite_samples_are_refused_naming_the_channel_and_first_index(tmp_path, row, index, value, word):
    stem = tmp_path / "rec"
    samples = signals(3 * PERIOD)
    samples[row, index] = value
    samples[row, index + 9] = value
    put_float_wav(stem, samples)
    put_sidecar(stem, good_doc())

    name = ["voltage", "current", "displacement"][row]
    refused(stem, f"{tmp_path / 'rec.wav'}: channel '{name}' (channel {row + 1}): sample {index} is {word}")


@pytest.mark.parametrize("scale", [1e308, -1e31, 5e-324, 1e-31])
def test_a_scale_no_real_sense_has_is_refused_before_the_samples_are_read(tmp_path, scale):
    """5e-324 made every sample 0 (a silent channel from a damaged sidecar); 1e308 overflowed them."""
    stem = tmp_path / "rec"
    put_float_wav(stem, signals(3 * PERIOD))
    doc = good_doc()
    doc["channels"][0]["scale"] = scale
    put_sidecar(stem, doc)
    refused(stem, "channels[0].scale of signal 'voltage': found", "a channel scale (its magnitude)")


def test_a_wav_cut_inside_the_data_chunk_is_refused_as_truncated(tmp_path):
    stem = good_recording_files(tmp_path)
    wav = tmp_path / "rec.wav"
    wav.write_bytes(wav.read_bytes()[:-10])
    refused(stem, f"{wav}: 'data' chunk: header says {3 * 3 * PERIOD * 4} bytes but the file ends after "
                  f"{3 * 3 * PERIOD * 4 - 10}", "truncated")


def test_a_data_chunk_longer_than_the_file_is_refused_even_if_the_riff_size_agrees(tmp_path):
    stem = tmp_path / "rec"
    put_sidecar(stem, good_doc())
    blob = bytearray(riff(fmt_chunk(3, 3, 32), signals(2 * PERIOD).T.tobytes()))
    data_at = blob.find(b"data")
    struct.pack_into("<I", blob, data_at + 4, 2 * 3 * PERIOD * 4 + 1200)
    struct.pack_into("<I", blob, 4, len(blob) - 8 + 1200)
    (tmp_path / "rec.wav").write_bytes(bytes(blob))
    refused(stem, "'data' chunk: header says", "truncated")


def test_a_wav_cut_inside_a_chunk_header_is_refused_as_truncated(tmp_path):
    stem = good_recording_files(tmp_path)
    wav = tmp_path / "rec.wav"
    blob = wav.read_bytes()
    wav.write_bytes(blob[:blob.find(b"data") + 5])
    refused(stem, "RIFF header: says", f"the file has {blob.find(b'data') + 5}", "truncated")


@pytest.mark.parametrize("blob, fragments", [
    (riff(fmt_chunk(1, 3, 8), bytes(3 * 2 * PERIOD)), ["sample format 8-bit integer PCM",
                                                        "expected 32-bit IEEE float or 16-, 24- or 32-bit integer PCM"]),
    (riff(fmt_chunk(3, 3, 64), bytes(8 * 3 * 2 * PERIOD)), ["sample format 64-bit IEEE float"]),
    (riff(fmt_chunk(6, 3, 8), bytes(3 * 2 * PERIOD)), ["sample format 8-bit A-law"]),
    (riff(fmt_chunk(1, 3, 20), bytes(3 * 2 * PERIOD)), ["sample format 20-bit integer PCM"]),
    (riff(extensible_fmt(1, 3, 16, tail=bytes(12)), bytes(6 * 2 * PERIOD)), ["extensible sub-format GUID"]),
    (riff(extensible_fmt(3, 3, 64), bytes(24 * 2 * PERIOD)), ["sample format 64-bit IEEE float"]),
    (riff(fmt_chunk(3, 3, 32)[:14], bytes(12 * 2 * PERIOD)), ["'fmt ' chunk: 14 bytes", "at least 16"]),
    (riff(fmt_chunk(3, 3, 32, rate=0), bytes(12 * 2 * PERIOD)), ["sample rate 0 Hz", "positive sample rate"]),
    (riff(fmt_chunk(3, 0, 32), bytes(12 * 2 * PERIOD)), ["0 channels", "at least 1"]),
    (riff(fmt_chunk(3, 3, 32, block_align=16), bytes(12 * 2 * PERIOD)), ["block align 16 bytes", "expected 12"]),
    (riff(fmt_chunk(3, 3, 32), bytes(12 * 2 * PERIOD + 5)), ["data chunk: 1541 bytes is not a whole number of "
                                                             "12-byte frames"]),
    (riff(fmt_chunk(3, 3, 32), None), ["no 'data' chunk"]),
    (riff(None, bytes(12 * 2 * PERIOD)), ["no 'fmt' chunk"]),
    (riff(fmt_chunk(3, 3, 32), bytes(12), before_data=b"data" + struct.pack("<I", 12) + bytes(12)),
     ["'data' chunk: found a second one"]),
    (b"", ["starts with b''", "expected a RIFF/WAVE header"]),
    (b"RIFX" + bytes(40), ["starts with b'RIFX", "RIFF/WAVE header"]),
    (b"ID3\x04" + bytes(200), ["RIFF/WAVE header"]),
], ids=["8-bit", "64-bit float", "A-law", "20-bit", "bad GUID", "extensible 64-bit", "short fmt", "rate 0",
        "no channels", "block align", "partial frame", "no data", "no fmt", "two data", "empty", "big-endian",
        "mp3"])
def test_a_wav_the_format_does_not_accept_is_refused_saying_what_was_found(tmp_path, blob, fragments):
    stem = tmp_path / "rec"
    put_sidecar(stem, good_doc())
    (tmp_path / "rec.wav").write_bytes(blob)
    assert refused(stem, *fragments).startswith(f"{tmp_path / 'rec.wav'}: ")


def test_a_wav_with_other_channels_than_the_sidecar_is_refused(tmp_path):
    stem = tmp_path / "rec"
    put_float_wav(stem, signals(3 * PERIOD, n_channels=2))
    put_sidecar(stem, good_doc())
    refused(stem, f"{tmp_path / 'rec.wav'}: 2 channels, expected 3, one per entry of 'channels' in rec.json")


@pytest.mark.parametrize("n_samples, excitation, fragments", [
    (PERIOD - 1, {}, ["excitation.period_samples: 64 samples is longer than the recording (63 samples in",
                      "expected at most 31"]),
    (PERIOD + 40, {}, ["excitation: 104 samples hold 1 whole periods of 64 samples, 0 to settle, which leaves 1",
                       "at least 2 whole periods"]),
    (3 * PERIOD, {"settle_periods": 2}, ["3 whole periods of 64 samples, 2 to settle, which leaves 1"]),
    (3 * PERIOD, {"settle_periods": 10**30}, ["which leaves 0"]),
    (3 * PERIOD, {"period_samples": 10**400}, ["excitation.period_samples: found 1000", "a period length"]),
], ids=["period longer than the file", "single period", "settling leaves one", "settle forever", "huge period"])
def test_too_few_whole_periods_are_refused(tmp_path, n_samples, excitation, fragments):
    stem = tmp_path / "rec"
    put_float_wav(stem, signals(n_samples))
    put_sidecar(stem, good_doc(**excitation))
    assert refused(stem, *fragments).startswith(f"{tmp_path / 'rec.json'}: ")


# --- anything else is refused with RecordingError, never another exception -----------

def _read_or_refuse(stem: Path) -> None:
    try:
        rec = read_recording(stem)
    except RecordingError as err:
        assert "\n" not in str(err) and str(err).startswith(str(stem.parent))
    else:
        assert rec.n_periods >= 2 and np.isfinite(rec.data).all()


_GOOD_WAV = riff(fmt_chunk(3, 3, 32), signals(2 * PERIOD).T.tobytes(),
                 before_data=b"LIST" + struct.pack("<I", 4) + b"INFO")


@settings(max_examples=50, deadline=None)
@given(edits=st.lists(st.tuples(st.integers(0, len(_GOOD_WAV) - 1), st.integers(0, 255)), max_size=6),
       keep=st.integers(0, len(_GOOD_WAV)), header_only=st.booleans())
def test_damaged_wav_bytes_raise_only_recording_error(tmp_path_factory, edits, keep, header_only):
    folder = tmp_path_factory.mktemp("wav")
    blob = bytearray(_GOOD_WAV)
    for at, value in edits:
        blob[at % 80 if header_only else at] = value    # most damage that matters is in the first 80 bytes
    (folder / "rec.wav").write_bytes(bytes(blob[:keep]))
    put_sidecar(folder / "rec", good_doc())
    _read_or_refuse(folder / "rec")


_json_values = st.recursive(
    st.none() | st.booleans() | st.integers() | st.just(10**400) | st.floats(allow_nan=False)
    | st.text(max_size=8) | st.sampled_from(["voltage", "current", "V", "A", "m", "linpar-recording/1"]),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(
        st.sampled_from(["signal", "unit", "scale", "period_samples", "settle_periods", "excited_bins",
                         "sd_m2", "name", "x"]) | st.text(max_size=4), inner, max_size=4),
    max_leaves=12)
_key_paths = st.sampled_from([
    [], ["format"], ["channels"], ["channels", 0], ["channels", 1, "signal"], ["channels", 2, "unit"],
    ["channels", 0, "scale"], ["excitation"], ["excitation", "period_samples"], ["excitation", "settle_periods"],
    ["excitation", "excited_bins"], ["driver"], ["driver", "sd_m2"], ["extra_key"]])


@settings(max_examples=50, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(path=_key_paths, value=_json_values, as_text=st.one_of(st.none(), st.text(max_size=30)))
def test_json_ish_sidecars_raise_only_recording_error(tmp_path_factory, path, value, as_text):
    folder = tmp_path_factory.mktemp("json")
    put_float_wav(folder / "rec", signals(2 * PERIOD))
    doc = good_doc()
    if path:
        _set(path, value)(doc)
    else:
        doc = value
    put_sidecar(folder / "rec", as_text if as_text is not None else json.dumps(doc))
    _read_or_refuse(folder / "rec")
