"""analysis.bounds: one range per kind of number, one message per check, and docs/bounds.md made from it."""
from __future__ import annotations

import math
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from analysis.bounds import (BOUNDS, SAMPLE_RATE, SD, BoundsError, GiB, MiB, markdown_table, parse_size_limit,
                             size_limit, size_limits_set)
from tests.reliability.fuzzing import FUZZ

DOC = Path(__file__).resolve().parents[2] / "docs" / "bounds.md"
EXTREMES = [0, -0.0, 5e-324, -5e-324, 1e-310, 1e-300, -1e-300, 1e300, -1e300, 1.7976931348623157e308,
            math.inf, -math.inf, math.nan, 10**400, -(10**400), True, "1", None]


def test_the_doc_table_is_the_module_s():
    text = DOC.read_text(encoding="utf-8")
    generated = text.split("<!-- generated: begin -->\n")[1].split("<!-- generated: end -->")[0]
    assert generated == markdown_table()


@pytest.mark.parametrize("bound", BOUNDS, ids=[b.what for b in BOUNDS])
def test_every_bound_refuses_every_extreme_outside_it_with_one_line(bound):
    for value in EXTREMES:
        inside = (isinstance(value, (int, float)) and not isinstance(value, bool) and bound.low <= value <= bound.high
                  and (not bound.integer or float(value).is_integer()))
        if inside:
            assert bound.check(value, "x") == value
            continue
        with pytest.raises(BoundsError) as err:
            bound.check(value, "somewhere")
        message = str(err.value)
        assert message.startswith("somewhere: found ") and "\n" not in message and bound.what in message


@FUZZ
@given(text=st.one_of(st.text(max_size=30), st.sampled_from(["nan", "-inf", "1e999", "0x10", "1_000", " 48000 "])))
def test_parsing_typed_text_gives_a_number_in_range_or_one_line(text):
    for bound in (SAMPLE_RATE, SD):
        try:
            value = bound.parse(text, "--x")
        except BoundsError as exc:
            assert "\n" not in str(exc) and str(exc).startswith("--x: found ")
        else:
            assert math.isfinite(value) and bound.low <= value <= bound.high


def test_size_limits_are_raised_for_the_code_inside_only():
    assert size_limit("wav") == 2 * GiB and size_limit("sidecar") == 10 * MiB
    kind, value = parse_size_limit("laser-stream=4G")
    with size_limits_set(**{kind: value}):
        assert size_limit("laser-stream") == 4 * GiB
    assert size_limit("laser-stream") == 2 * GiB
    for bad in ("wav", "wav=", "wav=-1", "wav=1Q", "nothing=1G", "wav=0"):
        with pytest.raises(BoundsError, match="--size-limit"):
            parse_size_limit(bad)


@pytest.mark.parametrize("range_text, accepted", [("10 mm", True), ("0 mm", False), ("99999999 mm", False),
                                                  ("0.00001 mm", False), ("500 mm", True)])
def test_a_laser_reply_with_a_measuring_range_no_sensor_has_is_a_laser_error(range_text, accepted):
    from instruments.laser.ild1420.commands import parse_info
    from instruments.laser.ild1420.frames import Reply
    from instruments.laser.sensor import LaserError
    reply = Reply(f"GETINFO\r\nName: ILD1420-10\r\nMeasuring range: {range_text}\r\n->")
    if accepted:
        assert parse_info(reply).measuring_range_m > 0
        return
    with pytest.raises(LaserError, match="measuring range: found .* expected a laser measuring range"):
        parse_info(reply)
