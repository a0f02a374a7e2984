"""The laser's byte stream as hostile input: any bytes, split anywhere, never a crash, a hang or a lost byte.

tests/instruments/laser/test_laser_frames.py splits one clean reference stream
anywhere. Here the bytes themselves are random or a real stream damaged
(garbage, cut frames, error-code floods, text where none is awaited), and
what is checked are the parser's promises for ANY input: every byte is
accounted for (in a value, discarded, held back, or in reply text); the
result does not depend on how the bytes were split; what comes out decodes
into LaserBlocks; replies, however mangled, give a SensorInfo or a
LaserError, nothing else.
"""
from __future__ import annotations

import math
import time

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from instruments.laser.ild1420.commands import parse_info, parse_output_info
from instruments.laser.ild1420.frames import FrameParser, RawMeasurements, Reply, encode_measurements, value_slots
from instruments.laser.ild1420.values import COUNTER_MODULUS, CounterUnwrapper, LaserErrorCode, block_from_raw
from instruments.laser.sensor import LaserError
from tests.pace import paced
from tests.reliability.fuzzing import FUZZ, FUZZ_MANY

pytestmark = pytest.mark.timeout(60)

OUTPUTS = [("distance",), ("distance", "counter"), ("distance", "timestamp"), ("distance", "counter", "timestamp")]


def feed_all(parser: FrameParser, blob: bytes, cuts) -> list:
    events, at = [], 0
    for cut in sorted(set(c % (len(blob) + 1) for c in cuts)) + [len(blob)]:
        events += list(parser.feed(blob[at:cut]))
        at = cut
    return events


def words_of(events) -> list:
    return [row for e in events if isinstance(e, RawMeasurements) for row in e.words.tolist()]


def clean_stream(outputs, n: int, seed: int) -> bytes:
    rng = np.random.default_rng(seed)
    slots = value_slots(outputs)
    k = np.arange(n)
    columns = {"distance": rng.integers(0, 2**18, n), "counter": k % COUNTER_MODULUS,
               "timestamp_lo": (25 * k) & 0xFFFF, "timestamp_hi": (25 * k) >> 16}
    return encode_measurements(np.stack([columns[s] for s in slots], axis=1)).tobytes()


@st.composite
def damaged_streams(draw) -> tuple[tuple[str, ...], bytes]:
    """A real stream with bursts of garbage, cut frames and floods of error codes spliced in."""
    outputs = draw(st.sampled_from(OUTPUTS))
    n_slots = len(value_slots(outputs))
    blob = bytearray(clean_stream(outputs, draw(st.integers(0, 300)), draw(st.integers(0, 9))))
    for _ in range(draw(st.integers(0, 6))):
        at = draw(st.integers(0, len(blob)))
        kind = draw(st.sampled_from(["garbage", "cut", "errors", "text", "hbytes"]))
        if kind == "garbage":
            blob[at:at] = draw(st.binary(min_size=1, max_size=40))
        elif kind == "cut":
            del blob[at:at + draw(st.integers(1, 3 * n_slots))]
        elif kind == "errors":
            codes = draw(st.lists(st.sampled_from([int(c) for c in LaserErrorCode] + [2**18 - 1]), min_size=1,
                                  max_size=200))
            words = np.zeros((len(codes), n_slots), dtype=np.int64)
            words[:, 0] = codes
            blob[at:at] = encode_measurements(words).tobytes()
        elif kind == "text":
            blob[at:at] = draw(st.sampled_from([b"E200 Unknown command\r\n->", b"->", b"GETINFO\r\nName: X\r\n",
                                                b"\r\n\r\n", b">->->"]))
        else:
            blob[at:at] = bytes(draw(st.lists(st.integers(0x80, 0xFF), min_size=1, max_size=12)))
    return outputs, bytes(blob)


def check_accounting(parser: FrameParser, events, fed: int) -> None:
    s = parser.stats
    text = sum(len(e.text) for e in events if isinstance(e, Reply)) + len(parser._text)
    assert 3 * s.values + s.discarded_bytes + parser.held_bytes + text == fed
    for e in events:
        if isinstance(e, RawMeasurements):
            assert e.words.shape[1] == len(e.slots) and e.words.dtype == np.int64
            assert e.words.min(initial=0) >= 0 and e.words.max(initial=0) < 2**18
    assert s.measurements == len(words_of(events))


@FUZZ_MANY
@given(raw=st.binary(max_size=600) | damaged_streams().map(lambda d: d[1]), outputs=st.sampled_from(OUTPUTS),
       cuts=st.lists(st.integers(0, 10_000), max_size=30))
def test_random_bytes_split_anywhere_lose_no_byte_and_decode_alike(raw, outputs, cuts):
    whole = FrameParser(outputs)
    one_chunk = list(whole.feed(raw))
    check_accounting(whole, one_chunk, len(raw))
    split = FrameParser(outputs)
    pieces = feed_all(split, raw, cuts)
    check_accounting(split, pieces, len(raw))
    assert words_of(pieces) == words_of(one_chunk)
    assert split.stats == whole.stats


@FUZZ
@given(stream=damaged_streams(), cuts=st.lists(st.integers(0, 10_000), max_size=20),
       range_m=st.sampled_from([0.01, 0.05, 0.5]))
def test_damaged_streams_decode_into_laser_blocks(stream, cuts, range_m):
    outputs, blob = stream
    parser, unwrapper = FrameParser(outputs), CounterUnwrapper()
    events = feed_all(parser, blob, cuts)
    check_accounting(parser, events, len(blob))
    for raw in (e for e in events if isinstance(e, RawMeasurements)):
        block = block_from_raw(raw, range_m, unwrapper, time.monotonic())
        assert len(block) == len(raw)
        valid = block.error_code == 0
        assert np.all(np.isnan(block.distance_m[~valid])) and np.all(np.isfinite(block.distance_m[valid]))
        if "counter" in outputs:
            steps = np.diff(block.counter)
            assert np.all(np.abs(steps) <= COUNTER_MODULUS // 2)   # a forged counter moves it locally only


@FUZZ_MANY
@given(raw=st.binary(max_size=400), toggles=st.lists(st.integers(0, 400), max_size=6),
       always=st.booleans(), outputs=st.sampled_from(OUTPUTS))
def test_text_collection_on_random_bytes_keeps_replies_readable(raw, toggles, always, outputs):
    parser = FrameParser(outputs, always_collect_text=always, max_text_bytes=64)
    events, at = [], 0
    for cut in sorted(set(t % (len(raw) + 1) for t in toggles)) + [len(raw)]:
        parser.expect_reply()               # as the command thread does before each command
        events += list(parser.feed(raw[at:cut]))
        events += parser.flush_idle()
        at = cut
    for reply in (e for e in events if isinstance(e, Reply)):
        assert reply.text.endswith("->") and reply.text.isascii()
        reply.lines, reply.errors, reply.warnings, reply.from_echo("GETINFO")
    assert len(parser._text) <= 64


info_lines = st.lists(st.one_of(
    st.sampled_from(["Name: ILD1420-10", "Name: ILD1420-", "Name:", "Serial: 123", "Measuring range: 50 mm",
                     "Measuring range: 0 mm", "Range: " + "9" * 400, "Range: 1e999", "Version:", ":", "->",
                     "Name: ILD1420-" + "9" * 400]),
    st.text(alphabet=st.characters(min_codepoint=0x20, max_codepoint=0x7e), max_size=30)), max_size=6)


@FUZZ_MANY
@given(lines=info_lines)
@example(lines=["Name: ILD1420-10"])
def test_mangled_info_and_output_replies_give_sensor_info_or_laser_error(lines):
    reply = Reply("GETINFO\r\n" + "\r\n".join(lines) + "\r\n->")
    try:
        info = parse_info(reply)
    except LaserError as exc:
        assert str(exc)
    else:
        assert info.name and isinstance(info.measuring_range_m, float) and not math.isnan(info.measuring_range_m)
    try:
        assert "distance" in parse_output_info(reply)
    except LaserError as exc:
        assert str(exc)


@pytest.mark.parametrize("fill", [b"\x00", b"\x7f", b"\xff", b"\x00\x40", bytes(range(256))])
def test_a_megabyte_of_one_pattern_is_parsed_in_well_under_a_second(fill):
    blob = (fill * (1_000_000 // len(fill) + 1))[:1_000_000]
    for collecting in (False, True):
        parser = FrameParser(always_collect_text=collecting)
        started = time.perf_counter()
        events = feed_all(parser, blob, range(0, 1_000_000, 4096))
        check_accounting(parser, events, len(blob))
        assert time.perf_counter() - started < paced(5.0)   # a per-byte slip would take minutes
