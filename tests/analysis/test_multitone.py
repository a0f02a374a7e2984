"""Multitone design: bin grid, exact spectrum, levels, crest factor, input checks."""

import math

import numpy as np
import pytest

from analysis.multitone import (
    Multitone,
    design_multitone,
    excitable_bins,
    schroeder_phases,
    synthesize,
    unexcited_bins,
)

# (sample_rate, period_samples, f_min, f_max): the two reference designs of the brief.
LONG = (48000, 65536, 5.0, 10000.0)
SHORT = (48000, 16384, 20.0, 20000.0)


@pytest.fixture(scope="module")
def long_mt() -> Multitone:
    return design_multitone(*LONG)


@pytest.fixture(scope="module")
def short_mt() -> Multitone:
    return design_multitone(*SHORT)


@pytest.fixture(scope="module", params=["long", "short"])
def mt(request, long_mt, short_mt) -> Multitone:
    return long_mt if request.param == "long" else short_mt


def crest(x: np.ndarray) -> float:
    return float(np.max(np.abs(x)) / np.sqrt(np.mean(x**2)))


def analogue_crest(mt: Multitone, oversampling: int = 16) -> float:
    """Crest factor of the reconstructed signal: the waveform between samples too."""
    fine = synthesize(oversampling * mt.period_samples, mt.excited_bins, mt.amplitudes, mt.phases)
    return float(np.max(np.abs(fine)) / mt.rms)


def line_spectrum(mt: Multitone) -> np.ndarray:
    """Complex peak amplitude of each bin of one period."""
    return np.fft.rfft(mt.waveform) * 2 / mt.period_samples


# --- which bins ------------------------------------------------------------------

def test_excited_bins_follow_the_detection_grid(mt):
    bins = mt.excited_bins
    assert bins.dtype == np.int64
    assert np.all(np.diff(bins) > 0), "sorted and unique"
    assert np.all(bins % 2 == 1), "odd only: even-order products fall on free even bins"
    assert np.all(bins % 3 != 0), "no multiple of 3: 3rd harmonics fall on free bins"
    assert np.all(np.diff(bins) >= 2), "never two adjacent bins"
    assert bins[0] >= 1 and bins[-1] <= mt.period_samples // 2 - 1


@pytest.mark.parametrize("design", [LONG, SHORT])
def test_excited_lines_lie_in_the_band(design):
    sample_rate, period, f_min, f_max = design
    mt = design_multitone(*design, crest_iterations=0)
    assert mt.frequencies.min() >= f_min
    assert mt.frequencies.max() <= f_max
    # The band is used: the ends are within one grid step (6 bins) of f_min / f_max.
    step = 6 * sample_rate / period
    assert mt.frequencies.min() < f_min + step
    assert mt.frequencies.max() > f_max * 2 ** (-1 / 12) - step


def test_low_end_takes_every_excitable_bin(long_mt):
    allowed = excitable_bins(*LONG)
    # Below bin 30 the 12-per-octave log step (6 %) is under 2 bins, finer than the grid.
    low = allowed[allowed < 30]
    assert len(low) > 5
    np.testing.assert_array_equal(long_mt.excited_bins[: len(low)], low)


def test_every_pair_of_neighbouring_lines_has_free_bins_between(mt):
    free = set(unexcited_bins(mt).tolist())
    for a, b in zip(mt.excited_bins[:-1], mt.excited_bins[1:]):
        assert free & set(range(a + 1, b)), f"no unexcited bin between {a} and {b}"


def test_low_end_keeps_free_odd_bins_for_odd_order_distortion(long_mt):
    free = unexcited_bins(long_mt)
    lowest = long_mt.excited_bins[:10]
    free_odd = free[(free % 2 == 1) & (free < lowest[-1])]
    # Every 6 bins of the dense low end hold one free odd bin (3 mod 6).
    assert len(free_odd) >= (lowest[-1] - lowest[0]) // 6
    assert np.all(free_odd % 6 == 3)


def test_second_and_third_harmonics_fall_on_unexcited_bins(mt):
    excited = set(mt.excited_bins.tolist())
    for order in (2, 3):
        harmonics = order * mt.excited_bins
        assert not excited & set(harmonics.tolist()), f"a {order}nd/rd harmonic hits an excited bin"


def test_high_frequencies_have_the_requested_lines_per_octave():
    mt = design_multitone(*LONG, lines_per_octave=24, crest_iterations=0)
    f = mt.frequencies
    for top in (10000.0, 5000.0, 2500.0):
        in_octave = np.count_nonzero((f > top / 2) & (f <= top))
        assert 23 <= in_octave <= 25, f"{in_octave} lines in the octave below {top} Hz"
    ratios = f[1:] / f[:-1]
    high = ratios[f[1:] > 1000]
    assert np.allclose(high, 2 ** (1 / 24), rtol=0.01)


@pytest.mark.parametrize("n_lines", [1, 40, 150, 400])
def test_n_lines_gives_exactly_that_many_lines(n_lines):
    mt = design_multitone(*SHORT, n_lines=n_lines, crest_iterations=0)
    assert mt.excited_bins.size == n_lines


def test_unexcited_bins_span_and_range(long_mt):
    free = unexcited_bins(long_mt)
    bins = long_mt.excited_bins
    assert free[0] > bins[0] and free[-1] < bins[-1]
    assert free.size + bins.size == bins[-1] - bins[0] + 1
    wide = unexcited_bins(long_mt, f_min=1.0, f_max=20000.0)
    to_bin = long_mt.period_samples / long_mt.sample_rate
    assert wide[0] == 2 and wide[-1] == math.floor(20000.0 * to_bin)
    assert not np.isin(wide, bins).any()
    assert 0 not in wide


# --- exact spectrum and levels --------------------------------------------------

def test_spectrum_is_exactly_the_requested_lines(mt):
    spectrum = line_spectrum(mt)
    np.testing.assert_allclose(np.abs(spectrum[mt.excited_bins]), mt.amplitudes, rtol=1e-9)
    rotation = spectrum[mt.excited_bins] / np.exp(1j * mt.phases)
    np.testing.assert_allclose(rotation, mt.amplitudes, rtol=1e-9)
    others = np.delete(spectrum, mt.excited_bins)
    assert np.max(np.abs(others)) < 1e-9 * mt.amplitudes.min()


def test_default_level_is_one_volt_rms_with_flat_lines(long_mt):
    assert long_mt.rms == pytest.approx(1.0, rel=1e-12)
    np.testing.assert_allclose(long_mt.amplitudes, long_mt.amplitudes[0], rtol=1e-12)


def test_design_level_is_exact():
    assert design_multitone(*SHORT, rms=0.3, crest_iterations=5).rms == pytest.approx(0.3, rel=1e-12)
    assert design_multitone(*SHORT, peak=2.5, crest_iterations=5).peak == pytest.approx(2.5, rel=1e-12)


def test_scaled_is_exact_and_keeps_the_spectrum_shape(short_mt):
    by_rms = short_mt.scaled(rms=2.83)
    by_peak = short_mt.scaled(peak=0.1)
    assert by_rms.rms == pytest.approx(2.83, rel=1e-12)
    assert by_peak.peak == pytest.approx(0.1, rel=1e-12)
    for scaled in (by_rms, by_peak):
        np.testing.assert_array_equal(scaled.excited_bins, short_mt.excited_bins)
        np.testing.assert_array_equal(scaled.phases, short_mt.phases)
        np.testing.assert_allclose(np.abs(line_spectrum(scaled)[scaled.excited_bins]),
                                   scaled.amplitudes, rtol=1e-9)
        assert scaled.crest_factor == pytest.approx(short_mt.crest_factor, rel=1e-12)


def test_amplitude_shape_sets_relative_line_amplitudes():
    def falling(freqs):
        return 1.0 / np.sqrt(freqs)

    mt = design_multitone(*SHORT, amplitude_shape=falling, rms=1.0, crest_iterations=10)
    expected = falling(mt.frequencies)
    np.testing.assert_allclose(mt.amplitudes / mt.amplitudes[0], expected / expected[0], rtol=1e-12)
    np.testing.assert_allclose(np.abs(line_spectrum(mt)[mt.excited_bins]), mt.amplitudes, rtol=1e-9)


# --- crest factor -----------------------------------------------------------------

def schroeder_crest(mt: Multitone) -> float:
    start = schroeder_phases(mt.excited_bins, mt.amplitudes)
    return crest(synthesize(mt.period_samples, mt.excited_bins, mt.amplitudes, start))


def test_crest_factor_is_reported_and_below_schroeder(mt):
    assert mt.crest_factor == pytest.approx(crest(mt.waveform), rel=1e-12)
    assert mt.crest_factor < 2.5
    assert mt.crest_factor < 0.75 * schroeder_crest(mt)


def test_a_few_hundred_lines_reach_a_crest_factor_near_two():
    mt = design_multitone(*SHORT, lines_per_octave=36)
    assert mt.excited_bins.size > 200
    assert mt.crest_factor < 2.1
    assert analogue_crest(mt) < 2.15


@pytest.mark.parametrize("first, spacing", [(1, 1), (1, 2), (3, 6)])
def test_schroeder_phases_are_the_classic_ones_on_an_even_grid(first, spacing):
    count = 100
    bins = first + spacing * np.arange(count)
    index = np.arange(count)
    expected = -np.pi * index**2 / count  # Schroeder's formula, by line index
    phases = schroeder_phases(bins, np.ones(count))
    # Equal up to a linear phase (a delay), which leaves the crest factor alone.
    np.testing.assert_allclose(np.diff(phases - expected, 2), 0.0, atol=1e-9)
    x = synthesize(4096, bins, np.ones(count), phases)
    assert crest(x) < 1.8


def test_zero_iterations_keep_the_start_and_any_descent_improves_it():
    start = design_multitone(*SHORT, crest_iterations=0)
    assert start.crest_factor > 3.0  # Schroeder's phases alone, on log-spaced lines
    for iterations in (6, 60):
        assert design_multitone(*SHORT, crest_iterations=iterations).crest_factor < start.crest_factor - 0.5


def test_peaks_do_not_hide_between_samples(short_mt):
    # Lines up to 20 kHz at 48 kHz: 2.4 samples per cycle, room for inter-sample peaks.
    assert analogue_crest(short_mt) < 1.03 * short_mt.crest_factor


def test_same_seed_same_waveform_other_seed_other_waveform(short_mt):
    again = design_multitone(*SHORT)
    np.testing.assert_array_equal(again.waveform, short_mt.waveform)
    other = design_multitone(*SHORT, seed=1)
    np.testing.assert_array_equal(other.excited_bins, short_mt.excited_bins)
    assert not np.allclose(other.phases, short_mt.phases)
    assert abs(other.crest_factor - short_mt.crest_factor) < 0.3


# --- the object ---------------------------------------------------------------

def test_arrays_are_read_only(short_mt):
    for array in (short_mt.excited_bins, short_mt.amplitudes, short_mt.phases, short_mt.waveform):
        with pytest.raises(ValueError):
            array[0] = 0


def test_tile_repeats_the_period(short_mt):
    tiled = short_mt.tile(3)
    assert tiled.shape == (3 * short_mt.period_samples,)
    np.testing.assert_array_equal(tiled.reshape(3, -1), np.broadcast_to(short_mt.waveform, (3, short_mt.period_samples)))
    tiled[0] = 99.0  # a fresh array: the multitone is untouched
    assert short_mt.waveform[0] != 99.0
    with pytest.raises(ValueError, match="n_periods"):
        short_mt.tile(0)


def test_frequencies_follow_the_bins(short_mt):
    np.testing.assert_allclose(short_mt.frequencies,
                               short_mt.excited_bins * 48000 / 16384, rtol=1e-15)


def test_multitone_rejects_inconsistent_fields(short_mt):
    fields = dict(sample_rate=48000, period_samples=16384, excited_bins=short_mt.excited_bins,
                  amplitudes=short_mt.amplitudes, phases=short_mt.phases, waveform=short_mt.waveform)
    with pytest.raises(ValueError, match="one value per excited bin"):
        Multitone(**{**fields, "amplitudes": short_mt.amplitudes[:-1]})
    with pytest.raises(ValueError, match="one period"):
        Multitone(**{**fields, "waveform": short_mt.waveform[:-1]})
    with pytest.raises(ValueError, match="sorted and unique"):
        Multitone(**{**fields, "excited_bins": short_mt.excited_bins[::-1]})
    with pytest.raises(ValueError, match="1 .. period_samples"):
        Multitone(**{**fields, "excited_bins": short_mt.excited_bins + 8192})


# --- bad inputs ---------------------------------------------------------------

@pytest.mark.parametrize(
    "args, kwargs, message",
    [
        ((48000, 16384, 1000.0, 1000.0), {}, "f_min .* must be below f_max"),
        ((48000, 16384, 2000.0, 1000.0), {}, "f_min .* must be below f_max"),
        ((48000, 16384, 20.0, 24000.0), {}, "Nyquist"),
        ((48000, 16384, 20.0, 30000.0), {}, "Nyquist"),
        ((48000, 16384, 0.0, 1000.0), {}, "f_min must be a positive"),
        ((48000, 16384, -5.0, 1000.0), {}, "f_min must be a positive"),
        ((48000, 16384, 20.0, math.inf), {}, "f_max must be finite"),
        ((48000, 8, 20.0, 1000.0), {}, "period_samples must be at least 16"),
        ((0, 16384, 20.0, 1000.0), {}, "sample_rate must be positive"),
        ((48000, 16384, 1000.0, 1002.0), {}, "no excitable bin"),
        ((48000, 16384, 20.0, 1000.0), {"rms": 1.0, "peak": 1.0}, "not both"),
        ((48000, 16384, 20.0, 1000.0), {"rms": 0.0}, "rms must be a positive"),
        ((48000, 16384, 20.0, 1000.0), {"peak": -1.0}, "peak must be a positive"),
        ((48000, 16384, 20.0, 1000.0), {"lines_per_octave": 0.0}, "lines_per_octave"),
        ((48000, 16384, 20.0, 1000.0), {"n_lines": 0}, "n_lines must be at least 1"),
        ((48000, 16384, 20.0, 1000.0), {"n_lines": 10_000}, "more than the .* excitable bins"),
        ((48000, 16384, 20.0, 1000.0), {"crest_iterations": -1}, "crest_iterations"),
        ((48000, 16384, 20.0, 1000.0), {"amplitude_shape": lambda f: -np.ones_like(f)}, "positive"),
        ((48000, 16384, 20.0, 1000.0), {"amplitude_shape": lambda f: np.ones(3)}, "shape"),
    ],
)
def test_bad_inputs_raise_value_error_naming_the_problem(args, kwargs, message):
    with pytest.raises(ValueError, match=message):
        design_multitone(*args, **kwargs)


def test_scaled_rejects_bad_levels(short_mt):
    with pytest.raises(ValueError, match="not both"):
        short_mt.scaled(rms=1.0, peak=1.0)
    with pytest.raises(ValueError, match="needs rms or peak"):
        short_mt.scaled()
    with pytest.raises(ValueError, match="rms must be a positive"):
        short_mt.scaled(rms=-1.0)


def test_a_repeated_design_reuses_the_phases_and_only_rescales():
    first = design_multitone(48000, 4096, 20.0, 2000.0, rms=1.0, seed=7)
    again = design_multitone(48000, 4096, 20.0, 2000.0, rms=2.0, seed=7)
    np.testing.assert_array_equal(first.phases, again.phases)
    np.testing.assert_allclose(again.waveform, 2.0 * first.waveform, rtol=0, atol=1e-12)
    other_seed = design_multitone(48000, 4096, 20.0, 2000.0, rms=1.0, seed=8)
    assert not np.allclose(other_seed.phases, first.phases)
    with pytest.raises(ValueError):
        first.phases[0] = 0.0          # what is remembered cannot be altered through a result
