"""LogBuckets: a few hundred log-spaced buckets keep the power of their bins."""
import numpy as np

from analysis.log_buckets import LogBuckets


def test_buckets_keep_the_power_of_the_bins():
    freqs = np.geomspace(10, 10000, 3000)
    buckets = LogBuckets(freqs, 100)
    power = np.full(freqs.size, 1e-10)                  # -100 dB
    assert np.allclose(buckets.power_mean_db(power), -100.0)
    power[1500] = 1e-6                                  # one product 40 dB over the floor in its bucket
    peak = buckets.power_mean_db(power)
    assert peak.max() > -100.0 + 20.0
    assert buckets.freqs.size <= 100 and np.all(np.diff(buckets.freqs) > 0)


def test_nothing_and_unknown_are_left_out_of_a_bucket_and_a_bucket_of_neither_is_nan():
    freqs = np.geomspace(10, 10000, 3000)
    buckets = LogBuckets(freqs, 100)
    power = np.full((2, freqs.size), 1e-10)
    power[0, : buckets.starts[1]] = 0.0                 # the first bucket holds exact zeros only
    power[0, buckets.starts[1]] = np.nan                # one unknown bin in the second
    power[1, buckets.starts[2]] = 0.0                   # one exact zero in the third
    db = buckets.power_mean_db(power)                   # rows at once, as a frame's channels
    assert db.shape == (2, buckets.starts.size)
    assert np.isnan(db[0, 0])
    assert np.allclose(db[0, 1:], -100.0) and np.allclose(db[1], -100.0)


def test_a_frame_where_every_bin_counts_gives_each_bucket_s_power_mean_as_one_with_a_gap():
    freqs = np.geomspace(10, 10000, 3000)
    buckets = LogBuckets(freqs, 100)
    power = np.random.default_rng(5).uniform(1e-12, 1e-6, size=(3, freqs.size))
    every = buckets.power_mean_db(power)                # the short path: all bins above nothing
    gapped = power.copy()
    gapped[:, -1] = 0.0                                 # one exact zero in the last bucket: the general path
    general = buckets.power_mean_db(gapped)
    np.testing.assert_array_equal(every[:, :-1], general[:, :-1])
    sizes = np.diff(np.r_[buckets.starts, freqs.size])
    expected = [10 * np.log10(power[:, s:s + k].mean(axis=-1)) for s, k in zip(buckets.starts, sizes)]
    np.testing.assert_allclose(every, np.transpose(expected), rtol=1e-12)
