"""What the ILD1420's 18-bit values mean: distances, error codes, reserves,
time stamps and the wrapping counter."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from instruments.laser.ild1420.values import (
    COUNTER_MODULUS, X_MAX, X_MIN, CounterUnwrapper, LaserErrorCode, decode_distance,
    describe_error, distance_to_x, timestamp_ms, timestamp_words, x_to_distance_m)

MR = 0.025  # a 25 mm sensor


def test_the_ends_of_the_measuring_range_are_zero_and_full_range():
    d = x_to_distance_m(np.array([X_MIN, X_MAX]), MR)
    # x = 643 and 64877 are the manual's limits: 0 and MR to within one step
    step = MR * 1.02 / 65520
    assert abs(d[0]) < step
    assert abs(d[1] - MR) < step


def test_distance_formula_matches_the_manual():
    x = 32768
    assert x_to_distance_m(np.array([x]), MR)[0] == pytest.approx((x * 1.02 / 65520 - 0.01) * MR)


def test_distance_to_x_inverts_within_half_a_step():
    d = np.linspace(0, MR, 1001)
    back = x_to_distance_m(distance_to_x(d, MR), MR)
    assert np.max(np.abs(back - d)) <= MR * 1.02 / 65520 / 2 + 1e-15


@pytest.mark.parametrize("code", list(LaserErrorCode))
def test_every_error_code_decodes_to_nan_with_its_code(code):
    distance, error_code, in_range = decode_distance(np.array([1000, int(code), 2000]), MR)
    assert np.isnan(distance[1]) and np.isfinite(distance[[0, 2]]).all()
    assert error_code.tolist() == [0, int(code), 0]
    assert in_range.tolist() == [True, False, True]
    assert LaserErrorCode(int(code)).description == describe_error(int(code))


def test_error_codes_are_the_manuals():
    assert sorted(int(c) for c in LaserErrorCode) == [262075, 262076, 262077, 262078, 262080, 262081, 262082]
    assert "baud" in LaserErrorCode.TOO_MUCH_DATA.description
    assert "laser is off" in describe_error(262082)


def test_an_unknown_code_is_still_an_error_not_a_distance():
    distance, error_code, in_range = decode_distance(np.array([262079]), MR)
    assert np.isnan(distance[0]) and error_code[0] == 262079 and not in_range[0]
    assert "unknown" in describe_error(262079)


def test_reserves_are_distances_flagged_out_of_range():
    x = np.array([0, X_MIN - 1, X_MIN, X_MAX, X_MAX + 1, 65535])
    distance, error_code, in_range = decode_distance(x, MR)
    assert np.isfinite(distance).all()
    assert (error_code == 0).all()
    assert in_range.tolist() == [False, False, True, True, False, False]
    assert distance[0] < 0 and distance[-1] > MR


def test_timestamp_words_combine_hi_and_lo():
    assert timestamp_ms(np.array([0]), np.array([1]))[0] == pytest.approx(655.36)
    assert timestamp_ms(np.array([250]), np.array([0]))[0] == pytest.approx(2.5)
    ticks = np.array([0, 1, 65535, 65536, 123456789, 2**32 - 1])
    lo, hi = timestamp_words(ticks)
    assert (lo < 65536).all() and (hi < 65536).all()
    assert np.allclose(timestamp_ms(lo, hi), ticks / 100)


def test_counter_unwraps_across_the_18_bit_wrap_in_any_chunking():
    raw = (262140 + np.arange(20)) % COUNTER_MODULUS
    unwrapper = CounterUnwrapper()
    out = np.concatenate([unwrapper.unwrap(raw[:3]), unwrapper.unwrap(raw[3:4]),
                          unwrapper.unwrap(raw[4:4]), unwrapper.unwrap(raw[4:])])
    assert raw.min() == 0  # the raw counter did wrap
    assert out.tolist() == list(range(262140, 262160))


def test_counter_unwrap_keeps_gaps_and_heals_after_a_forged_value():
    unwrapper = CounterUnwrapper()
    assert unwrapper.unwrap(np.array([10, 11, 15])).tolist() == [10, 11, 15]
    # one forged counter from line garbage, then the stream goes on
    assert unwrapper.unwrap(np.array([200000, 16, 17])).tolist()[1:] == [16, 17]


def test_counter_unwrap_reset_forgets_history():
    unwrapper = CounterUnwrapper()
    unwrapper.unwrap(np.array([5, 6, 7]))
    unwrapper.reset()
    assert unwrapper.unwrap(np.array([0, 1])).tolist() == [0, 1]


@settings(max_examples=60, deadline=None)
@given(start=st.integers(0, COUNTER_MODULUS - 1),
       steps=st.lists(st.integers(1, 5000), min_size=1, max_size=200),
       cuts=st.lists(st.integers(0, 200), max_size=8))
def test_counter_unwrap_recovers_the_running_count(start, steps, cuts):
    truth = start + np.concatenate(([0], np.cumsum(steps)))
    raw = truth % COUNTER_MODULUS
    unwrapper = CounterUnwrapper()
    bounds = [0, *sorted(c % (len(raw) + 1) for c in cuts), len(raw)]
    out = np.concatenate([unwrapper.unwrap(raw[a:b]) for a, b in zip(bounds[:-1], bounds[1:])])
    assert out.tolist() == truth.tolist()
    assert (np.diff(out) > 0).all()
