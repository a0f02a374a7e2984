"""The serial laser's alignment to the audio on synthetic streams: known clocks, latencies, errors.

A periodic displacement (the lines of a multitone, on the audio's period
grid) is sampled by a "laser" whose clock runs off by some ppm and starts
late; both streams arrive in blocks at host times that are never early and
late by random amounts. What the alignment estimates is compared with the
truth: the clock to well below a ppm, the offset to the difference of the two
streams' smallest latencies, the displacement itself to 1e-4 below the
laser's band edge.
"""
from __future__ import annotations

import numpy as np
import pytest

from instruments.laser.sensor import LaserBlock
from instruments.measurement.alignment import PLAUSIBLE_PPM, align_laser, stream_of_blocks
from instruments.measurement.clocks import LaserClock, lower_envelope, period_phase_drift
from instruments.measurement.raw_stream import blocks_of, read_raw_capture, write_raw_capture
from instruments.measurement.resample import PASSBAND, interpolate

FS, P, RATE = 48000, 16384, 4000.0
BINS = np.array([b for b in range(5, 1500) if b % 6 in (1, 5)])[::2]
AUDIO_BLOCK, LASER_BLOCK = 1024, 9
START = 6 * P
N_PERIODS = 6


class Scene:
    """Audio index m is taken at host time T0 + m / FS; laser sample k at T0 - lead + latency + k / rate."""

    def __init__(self, ppm=0.0, latency_s=0.0, audio_floor_s=50e-6, laser_floor_s=50e-6, seed=1,
                 error_every=0, lose_blocks=()):
        rng = np.random.default_rng(seed)
        self.amplitude = 1e-4 / (1 + (BINS * FS / P / 70.0) ** 2)
        self.phase = rng.uniform(0, 2 * np.pi, BINS.size)
        self.T0 = 1000.0
        self.stops = np.arange(AUDIO_BLOCK, START + (N_PERIODS + 2) * P, AUDIO_BLOCK)
        self.audio_times = self.T0 + self.stops / FS + audio_floor_s + rng.exponential(300e-6, self.stops.size)
        self.host_rate = RATE * (1 + ppm * 1e-6)
        self.laser_t0 = self.T0 - 0.2 + latency_s
        n = int((self.stops[-1] / FS + 0.4) * self.host_rate)
        k = np.arange(n)
        t = self.laser_t0 + k / self.host_rate
        distance = 5e-3 - self.x((t - self.T0) * FS) + rng.normal(0, 40e-9, n)
        code = np.zeros(n, np.int32)
        if error_every:
            code[::error_every] = 262076
            distance[::error_every] = np.nan
        self.blocks = []
        for i, a in enumerate(range(0, n, LASER_BLOCK)):
            if i in lose_blocks:
                continue
            s = slice(a, a + LASER_BLOCK)
            arrival = t[s][-1] + laser_floor_s + rng.exponential(200e-6)
            self.blocks.append(LaserBlock(k[s].astype(np.int64), np.full(k[s].size, np.nan), distance[s], code[s],
                                          code[s] == 0, arrival))
        self.true_clock = LaserClock((self.laser_t0 - self.T0) * FS, FS / self.host_rate)

    def x(self, m):
        """The true displacement (m, outward) at audio indices m."""
        m = np.asarray(m, dtype=np.float64)
        return np.sum(self.amplitude[:, None] * np.cos(2 * np.pi * BINS[:, None] * m[None, :] / P
                                                       + self.phase[:, None]), axis=0)

    def align(self, **options):
        starts = START + P * np.arange(N_PERIODS)
        return align_laser(stream_of_blocks(self.blocks), self.stops, self.audio_times, starts, P, FS, RATE, BINS,
                           **options)

    def line_ratio(self, aligned):
        """Measured over true displacement at the excited lines the laser covers (periods averaged)."""
        grid = (START + P * np.arange(aligned.periods)[:, None] + np.arange(P)[None, :]).ravel()
        truth = self.x(grid)
        got = np.fft.rfft(aligned.displacement.reshape(-1, P), axis=1).mean(axis=0)[BINS]
        want = np.fft.rfft((truth - truth.mean()).reshape(-1, P), axis=1).mean(axis=0)[BINS]
        keep = BINS * FS / P <= aligned.max_hz
        return BINS[keep] * FS / P, got[keep] / want[keep]


def test_the_lower_envelope_finds_the_line_under_late_arrivals():
    rng = np.random.default_rng(3)
    index = np.arange(0, 200000, 1024)
    arrival = 5.0 + index * 1.00003 / FS + rng.exponential(500e-6, index.size)
    line = lower_envelope(index, arrival)
    assert line.slope * FS == pytest.approx(1.00003, abs=1e-6)
    assert line.time_of(index).max() == pytest.approx(5.0 + index[-1] * 1.00003 / FS, abs=30e-6)
    assert np.all(arrival >= line.time_of(index) - 1e-12)      # nothing arrives before it was taken


def test_the_interpolator_is_flat_to_its_passband_and_silent_just_below_nyquist():
    """Flat to 1e-5 up to PASSBAND of the rate; at 0.495 of it (a tone the samples barely resolve, whose
    images crowd the band) nothing is left."""
    k = np.arange(20000)
    positions = np.linspace(200, 19800, 40001)
    for f_rel, wanted in ((0.01, 1.0), (0.25, 1.0), (PASSBAND, 1.0), (0.495, 0.0)):
        got = interpolate(np.cos(2 * np.pi * f_rel * k), positions)
        error = got - wanted * np.cos(2 * np.pi * f_rel * positions)
        assert np.sqrt(np.mean(error ** 2)) < (2e-5 if wanted else 1e-4), f_rel


@pytest.mark.parametrize("ppm, latency_s", [(0.0, 0.0), (200.0, 0.1), (-200.0, 0.1), (37.0, 0.02)])
def test_clock_and_offset_are_estimated_not_assumed(ppm, latency_s):
    scene = Scene(ppm, latency_s)
    aligned = scene.align()
    assert aligned.clock.ppm(FS, RATE) == pytest.approx(ppm, abs=0.05)
    assert abs(aligned.host_clock.ppm(FS, RATE) - ppm) < 2.0     # the host times alone: a ppm or so
    # Same smallest latency on both streams: the offset comes out right to a few microseconds.
    mid = np.mean(scene.blocks[len(scene.blocks) // 2].counter)
    offset_error_s = (aligned.clock.audio_index(mid) - scene.true_clock.audio_index(mid)) / FS
    assert abs(offset_error_s) < 10e-6
    freqs, ratio = scene.line_ratio(aligned)
    assert np.max(np.abs(np.abs(ratio) - 1)[freqs < 300]) < 2e-3      # above, the sensor's noise rules
    assert np.max(np.abs(np.angle(ratio))[freqs < 100]) < np.radians(0.1)
    assert aligned.periods == N_PERIODS and aligned.passes >= 1


def test_the_refinement_finds_the_ratio_from_a_clock_50_ppm_off():
    scene = Scene(ppm=120.0)
    aligned = scene.align(refine=False)
    grid = (START + P * np.arange(N_PERIODS)[:, None] + np.arange(0, P, 8)[None, :]).ravel()
    from instruments.measurement.alignment import _bridged
    filled = _bridged(stream_of_blocks(scene.blocks).distance_m)
    clock = aligned.clock.pivoted(scene.true_clock.ratio * (1 + 50e-6), 20000)
    for _ in range(3):
        drift, lines = period_phase_drift(interpolate(filled, clock.laser_index(grid)).reshape(N_PERIODS, -1),
                                          BINS[BINS * FS / P < 1700], P)
        clock = clock.pivoted(clock.ratio * (1 + drift), 20000)
    assert lines > 20
    assert clock.ratio / scene.true_clock.ratio - 1 == pytest.approx(0, abs=0.05e-6)


def test_an_uncorrected_offset_is_a_pure_delay_in_hx():
    """What the excitation cannot tell: a latency of the laser the host times do not see (here 1 ms
    left out of latency_s) leaves |Hx| right and turns its phase by -w * 1 ms."""
    scene = Scene(ppm=50.0, laser_floor_s=1.05e-3, audio_floor_s=50e-6)
    freqs, ratio = scene.line_ratio(scene.align())
    assert np.max(np.abs(np.abs(ratio) - 1)[freqs < 300]) < 2e-3
    low = freqs < 500
    delay = -np.polyfit(2 * np.pi * freqs[low], np.unwrap(np.angle(ratio[low])), 1)[0]
    assert delay == pytest.approx(1e-3, abs=5e-6)       # its samples placed 1 ms late: Hx lags by 1 ms
    corrected = scene.line_ratio(scene.align(latency_s=1e-3))[1]
    assert np.max(np.abs(np.angle(corrected))[freqs < 100]) < np.radians(0.1)


def test_error_codes_and_lost_measurements_are_missing_data_counted_not_averaged():
    scene = Scene(ppm=-80.0, error_every=97, lose_blocks=(1200, 1201, 1700))    # within the kept periods
    aligned = scene.align()
    counts = aligned.counts
    assert counts.lost == 3 * LASER_BLOCK
    assert counts.errors_by_code == {262076: pytest.approx(counts.samples / 97, abs=3)}
    doc = counts.capture_json()
    assert doc["laser_error_counts"] == {"262076": counts.errors_by_code[262076]}
    gaps = doc["laser_gaps"]
    assert gaps["lost"] == 3 * LASER_BLOCK and gaps["samples"] == counts.errors_by_code[262076] + 3 * LASER_BLOCK
    assert gaps["periods"] == N_PERIODS and gaps["longest_run"] == 2 * LASER_BLOCK and gaps["unseen_s"] == 0
    # About 1 % of each period missing: the noise grows by about that much, not more.
    assert 1.0 < gaps["noise_factor"] < 1.05
    freqs, ratio = scene.line_ratio(aligned)
    assert np.all(np.isfinite(aligned.displacement))
    # Two lost blocks in a row are 4.5 ms with no distance: filled from the other periods, not bridged by a
    # straight line, the lines come out as well as without them (a bridge left 1e-2 at the low lines).
    assert np.max(np.abs(np.abs(ratio) - 1)[freqs < 300]) < 3e-3
    only_errors = Scene(ppm=-80.0, error_every=97)
    freqs, ratio = only_errors.line_ratio(only_errors.align())
    assert np.max(np.abs(np.abs(ratio) - 1)[freqs < 300]) < 3e-3


def test_the_displacement_is_zero_above_the_laser_band_and_signed_outward():
    scene = Scene()
    aligned = scene.align()
    spectra = np.fft.rfft(aligned.displacement.reshape(-1, P), axis=1)
    top = int(aligned.max_hz * P / FS)
    assert np.max(np.abs(spectra[:, top + 1:])) < 1e-12 * np.max(np.abs(spectra))
    assert aligned.max_hz == pytest.approx(PASSBAND * RATE, rel=1e-3)
    flipped = scene.line_ratio(scene.align(sign=+1.0))[1]     # the wrong mounting: every line inverted
    assert np.allclose(flipped[:20], -1, atol=5e-3)


def test_periods_the_laser_does_not_cover_are_left_out():
    scene = Scene()
    cut = [b for b in scene.blocks if b.host_time < scene.T0 + (START + 3.5 * P) / FS]
    aligned = align_laser(stream_of_blocks(cut), scene.stops, scene.audio_times, START + P * np.arange(N_PERIODS),
                          P, FS, RATE, BINS)
    assert aligned.periods == 3
    assert aligned.displacement.size == 3 * P


def test_the_raw_capture_file_round_trips_without_pickle(tmp_path):
    scene = Scene(ppm=200.0, latency_s=0.1, error_every=500)
    arrivals = (scene.stops - AUDIO_BLOCK, scene.stops, scene.audio_times)
    path = write_raw_capture(tmp_path / "m.laser.npz", scene.blocks, arrivals, [START], {"note": "test"})
    arrays, info = read_raw_capture(path)
    assert info == {"note": "test"}
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]
    with np.load(path, allow_pickle=False) as data:     # plain arrays only: loads without pickle
        assert data["distance_m"].dtype == np.float64 and data["error_code"].dtype == np.int32
    again = align_laser(stream_of_blocks(blocks_of(arrays)), arrays["audio_block_stop"],
                        arrays["audio_block_host_time"], START + P * np.arange(N_PERIODS), P, FS, RATE, BINS)
    assert np.array_equal(again.displacement, scene.align().displacement)
    with pytest.raises(ValueError, match="format"):
        np.savez(tmp_path / "other.npz", format=np.array("something/1"), info=np.array("{}"))
        read_raw_capture(tmp_path / "other.npz")


def test_host_times_off_by_thousands_of_ppm_do_not_keep_the_refinement_from_the_laser_clock():
    """A loaded machine (or a USB adapter's bursts) can make the audio's arrival times say the laser runs
    9,300 ppm off (seen on a JACK plan); the refinement then starts from the nominal rate and still finds the
    laser's 37 ppm."""
    scene = Scene(ppm=37.0)
    scene.audio_times = scene.T0 + (scene.audio_times - scene.T0) * (1.0 + 9.3e-3)
    aligned = scene.align()
    assert abs(aligned.host_clock.ppm(FS, RATE) - 37.0) > 5000
    assert aligned.clock.ppm(FS, RATE) == pytest.approx(37.0, abs=0.05) and aligned.passes >= 1
    freqs, ratio = scene.line_ratio(aligned)
    assert np.max(np.abs(np.abs(ratio) - 1)[freqs < 300]) < 2e-3


def test_audio_arrivals_ever_later_from_a_starved_host_do_not_misplace_the_laser():
    """A starved host takes the audio's blocks later and later (here from a third of the way in, up to 0.25 s
    by the end): the envelope's edge at the centre runs along the late arrivals, its ratio ~100,000 ppm off,
    and its line at the centre is as late as they were there. Placed by the most timely blocks at the nominal
    rates instead, the laser lands where it was (the rig measured a 4 V step placed 0.25 s late before)."""
    scene = Scene(ppm=37.0)
    since = scene.audio_times[scene.audio_times.size // 3]
    scene.audio_times = scene.audio_times + np.clip(scene.audio_times - since, 0.0, None) * 0.25 / (
        scene.audio_times[-1] - since)
    aligned = scene.align()
    assert abs(aligned.host_clock.ppm(FS, RATE)) > 10 * PLAUSIBLE_PPM
    k = np.array([0.0, 1e4, 3e4])
    assert np.max(np.abs(aligned.clock.audio_index(k) - scene.true_clock.audio_index(k))) < 0.1 * FS * 1e-3
    assert aligned.clock.ppm(FS, RATE) == pytest.approx(37.0, abs=0.05)
    freqs, ratio = scene.line_ratio(aligned)
    assert np.max(np.abs(ratio - 1)[freqs < 300]) < 0.01          # magnitude and phase: no period misplaced
