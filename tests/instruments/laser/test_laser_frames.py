"""The byte codec: values and ASCII replies sharing one line, split anywhere,
with garbage in between."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from instruments.laser.ild1420.frames import (
    FrameParser, RawMeasurements, Reply, encode_measurements, value_slots)

ALL = ("distance", "counter", "timestamp")
SLOTS = value_slots(ALL)


def rows(m, start=0, seed=1):
    """m measurements of (distance, counter, ts_lo, ts_hi) with a known counter."""
    rng = np.random.default_rng(seed)
    k = np.arange(start, start + m)
    return np.stack([rng.integers(0, 65536, m), k % 2**18, (25 * k) & 0xFFFF, (25 * k) >> 16], axis=1)


def parse(parser, *chunks):
    events = []
    for chunk in chunks:
        events += list(parser.feed(chunk))
    return events


def measured(events):
    blocks = [e.words for e in events if isinstance(e, RawMeasurements)]
    return np.concatenate(blocks) if blocks else np.empty((0, 4), np.int64)


def replies(events):
    return [e.text for e in events if isinstance(e, Reply)]


def test_value_bytes_follow_the_spec_layout():
    words = np.array([[0b11_0101_0110_0111_1000, 5]])  # an 18-bit distance word, then a counter
    out = encode_measurements(words)[0]
    assert out.tolist()[:3] == [0b00_111000, 0b01_011001, 0b10_110101]  # L, M, H, first value
    assert out[3] >> 6 == 0 and out[4] >> 6 == 1
    assert out[5] >> 6 == 0b11  # H of a further value has its second bit set
    with pytest.raises(ValueError):
        encode_measurements(np.array([[1 << 18]]))


@pytest.mark.parametrize("outputs", [("distance",), ("distance", "counter"), ("distance", "timestamp"), ALL])
def test_measurements_round_trip_for_every_output_list(outputs):
    slots = value_slots(outputs)
    words = rows(50)[:, [SLOTS.index(s) for s in slots]]
    parser = FrameParser(outputs)
    events = parse(parser, encode_measurements(words).tobytes())
    got = np.concatenate([e.words for e in events])
    assert got.tolist() == words.tolist()
    assert all(e.slots == slots for e in events)
    assert parser.stats.discarded_bytes == 0 and parser.stats.measurements == 50


def test_output_list_is_validated_and_put_in_sensor_order():
    assert value_slots(("timestamp", "distance")) == ("distance", "timestamp_lo", "timestamp_hi")
    with pytest.raises(ValueError):
        value_slots(("counter",))
    with pytest.raises(ValueError):
        value_slots(("distance", "speed"))


def test_byte_by_byte_feeding_gives_the_same_measurements():
    words = rows(30)
    parser = FrameParser(ALL)
    data = encode_measurements(words).tobytes()
    events = parse(parser, *[data[i:i + 1] for i in range(len(data))])
    assert measured(events).tolist() == words.tolist()


def test_a_reply_interleaved_byte_by_byte_with_values_is_recognised_and_no_value_suffers():
    words = rows(40)
    reply = b"GETINFO\r\nName:  ILD1420-10\r\nMAC-Address: 00-0C-12\r\n->"
    values = encode_measurements(words).reshape(-1, 3)  # one value per row
    stream = bytearray()
    for i, value in enumerate(values):  # one reply byte after every value, even mid-measurement
        stream += value.tobytes()
        if i < len(reply):
            stream += reply[i:i + 1]
    parser = FrameParser(ALL)
    parser.expect_reply()
    events = parse(parser, bytes(stream))
    assert replies(events) == [reply.decode()]
    assert measured(events).tolist() == words.tolist()
    assert parser.stats.discarded_bytes == 0


def test_a_dash_before_a_value_whose_l_byte_is_a_prompt_character_does_not_end_the_reply():
    # '-' then a value whose L byte is 0x3E ('>'): looks like the prompt, is not
    word = np.array([[0x3E | (5 << 6)]])
    value = encode_measurements(word).tobytes()
    assert value[0:1] == b">"
    parser = FrameParser(("distance",))
    parser.expect_reply()
    events = parse(parser, b"X-", value, b"Y\r\n->") + parser.flush_idle()
    assert replies(events) == ["X-Y\r\n->"]
    assert measured(events).ravel().tolist() == [int(word[0, 0])]


def test_the_prompt_on_a_quiet_line_is_closed_by_flush_idle():
    parser = FrameParser(ALL)
    parser.expect_reply()
    assert replies(parse(parser, b"RESETCNT\r\n->")) == []  # '>' could still be an L byte
    assert parser.held_bytes == 1
    assert [r.text for r in parser.flush_idle()] == ["RESETCNT\r\n->"]
    assert not parser.expecting_reply


def test_the_prompt_followed_by_values_closes_at_once():
    parser = FrameParser(ALL)
    parser.expect_reply()
    events = parse(parser, b"RESETCNT\r\n->" + encode_measurements(rows(2)).tobytes())
    assert replies(events) == ["RESETCNT\r\n->"]
    assert len(measured(events)) == 2
    assert isinstance(events[0], Reply)  # stream order kept


def test_text_nobody_asked_for_is_garbage():
    parser = FrameParser(ALL)
    events = parse(parser, b"hello\r\n->" + encode_measurements(rows(3)).tobytes())
    assert replies(events) == []
    assert parser.stats.discarded_bytes == len(b"hello\r\n->")
    assert len(measured(events)) == 3


def test_resynchronises_after_garbage_that_cannot_forge_values_and_counts_every_byte():
    words = rows(60)
    data = encode_measurements(words)
    garbage = bytes(range(0x80, 0x100)) * 2  # H-class bytes only: no L, M to complete a value
    stream = data[:20].tobytes() + garbage + data[20:].tobytes()
    parser = FrameParser(ALL)
    events = parse(parser, stream)
    assert measured(events).tolist() == words.tolist()
    assert parser.stats.discarded_bytes == len(garbage)


def test_random_garbage_between_measurements_loses_no_measurement():
    words = rows(300)
    data = encode_measurements(words)
    rng = np.random.default_rng(7)
    stream = bytearray()
    for i, row in enumerate(data):
        stream += row.tobytes()
        if i % 10 == 9:
            stream += rng.integers(0, 256, 24, dtype=np.uint8).tobytes()
    parser = FrameParser(ALL)
    got = measured(parse(parser, bytes(stream)))
    # a forged measurement needs four forged values in a row: with this seed there is none
    assert got.tolist() == words.tolist()
    stats = parser.stats
    assert stats.discarded_bytes > 0
    assert stats.values >= 4 * 300  # forged single values do occur, and are dropped
    assert stats.incomplete_measurements + stats.orphan_values > 0


def test_a_truncated_measurement_is_dropped_and_counted_the_next_one_is_intact():
    words = rows(10)
    data = encode_measurements(words)
    stream = b"".join(row.tobytes() if i != 4 else row.tobytes()[:-1] for i, row in enumerate(data))
    parser = FrameParser(ALL)
    got = measured(parse(parser, stream))
    assert got[:, 1].tolist() == [0, 1, 2, 3, 5, 6, 7, 8, 9]
    assert parser.stats.incomplete_measurements == 1
    assert parser.stats.discarded_bytes == 2  # the lone L and M of the cut value


def test_joining_mid_measurement_drops_the_orphan_values():
    data = encode_measurements(rows(5)).tobytes()
    parser = FrameParser(ALL)
    got = measured(parse(parser, data[5:]))  # starts inside the counter value
    assert got[:, 1].tolist() == [1, 2, 3, 4]
    assert parser.stats.orphan_values == 2  # ts_lo, ts_hi of measurement 0


def test_the_consumer_can_change_the_layout_at_the_reply_that_changed_it():
    before = encode_measurements(rows(3)[:, :1]).tobytes()  # distance only
    after = encode_measurements(rows(3)).tobytes()  # distance, counter, time stamp
    parser = FrameParser(("distance",))
    parser.expect_reply()
    seen = []
    for event in parser.feed(before + b"OUTADD_RS422 COUNTER TIMESTAMP\r\n->" + after):
        seen.append(event)
        if isinstance(event, Reply):
            parser.set_outputs(ALL)
    assert [len(e) for e in seen if isinstance(e, RawMeasurements)] == [3, 3]
    assert measured(seen[-1:]).tolist() == rows(3).tolist()


def test_reply_lines_errors_warnings_and_echo():
    reply = Reply("xyMEASRATE 3\r\nW100 rounded\r\nE210 Parameter out of range\r\n->")
    start, own = reply.from_echo("MEASRATE 3")
    assert start == 2
    assert own.lines == ("MEASRATE 3", "W100 rounded", "E210 Parameter out of range")
    assert own.body == ("W100 rounded", "E210 Parameter out of range")
    assert own.errors == ("E210 Parameter out of range",)
    assert own.warnings == ("W100 rounded",)
    assert reply.from_echo("GETINFO") is None


def test_runaway_text_is_capped_and_counted():
    parser = FrameParser(ALL, max_text_bytes=100)
    parser.expect_reply()
    parse(parser, b"a" * 250)
    assert parser.stats.discarded_bytes == 150


def _stream_with_everything(seed):
    """Values, replies and garbage: the reference stream for the split test."""
    rng = np.random.default_rng(seed)
    data = encode_measurements(rows(80, start=262100, seed=seed))
    stream = bytearray()
    for i, row in enumerate(data):
        stream += row.tobytes()
        if i % 17 == 3:
            stream += b"GETINFO\r\nName: ILD1420-10\r\n->"
        if i % 23 == 11:
            stream += rng.integers(0, 256, 9, dtype=np.uint8).tobytes()
    return bytes(stream)


def _run(chunks):
    parser = FrameParser(ALL, always_collect_text=True)
    events = parse(parser, *chunks)
    return measured(events).tolist(), replies(events), parser.stats


@settings(max_examples=80, deadline=None)
@given(seed=st.integers(0, 3), cuts=st.lists(st.integers(0, 10_000), max_size=40))
def test_chunk_boundaries_anywhere_decode_to_the_same_result(seed, cuts):
    stream = _stream_with_everything(seed)
    bounds = [0, *sorted(c % (len(stream) + 1) for c in cuts), len(stream)]
    chunks = [stream[a:b] for a, b in zip(bounds[:-1], bounds[1:])]
    assert _run(chunks) == _run([stream])


def test_the_reference_stream_decodes_completely():
    words, texts, stats = _run([_stream_with_everything(0)])
    assert [w[1] for w in words] == [(262100 + k) % 2**18 for k in range(80)]
    assert len(texts) == 5 and all(t.endswith("Name: ILD1420-10\r\n->") for t in texts)
