"""The parts of the audio path that need no device: settings, the callback core, the period collector."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from instruments.audio.config import AudioDeviceChoice, Calibration, ChannelMap
from instruments.audio.periods import PeriodCollector
from instruments.audio.stream_core import (
    INPUT_OVERFLOW, OUTPUT_UNDERFLOW, DuplexCore, InputBlock, LoopedExcitation)
from instruments.rig.engine import RIG_CALIBRATION, RigFaults, RigNoise
from tests.pace import paced

CAL = Calibration(volts_per_fs_out=10.0, volts_per_fs_voltage_sense=20.0, volts_per_fs_current_sense=1.0,
                  shunt_ohm=0.1, current_amp_gain=5.0, volts_per_fs_laser=5.0, laser_m_per_volt=1e-3)


# --- settings ----------------------------------------------------------------

def test_settings_round_trip_through_json():
    for value in (AudioDeviceChoice("system", "JACK Audio Connection Kit"), ChannelMap(1, 2, 3, 0), CAL):
        again = type(value).from_dict(json.loads(json.dumps(value.to_dict())))
        assert again == value


def test_calibration_turns_full_scale_into_si_units():
    assert CAL.to_si("voltage", np.array([0.5]))[0] == pytest.approx(10.0)
    assert CAL.to_si("current", np.array([0.5]))[0] == pytest.approx(1.0)        # 1 V / (0.1 ohm * 5)
    assert CAL.to_si("displacement", np.array([0.5]))[0] == pytest.approx(2.5e-3)
    assert CAL.volts_to_output(np.array([5.0]))[0] == pytest.approx(0.5)


@pytest.mark.parametrize("bad, match", [
    (lambda: ChannelMap(voltage=1, current=1), "two signals on one input"),
    (lambda: ChannelMap(output=-1), "output"),
    (lambda: Calibration(0, 1, 1, 1, 1), "volts_per_fs_out"),
    (lambda: Calibration.from_dict({"volts_per_fs_out": 1.0, "bogus": 2}), "unknown key"),
    (lambda: AudioDeviceChoice.from_dict({"name": "x"}), "hostapi"),
])
def test_bad_settings_are_refused_with_a_message(bad, match):
    with pytest.raises(ValueError, match=match):
        bad()


# --- the callback core -----------------------------------------------------

def test_output_loops_the_period_between_raised_cosine_fades():
    period = np.sin(2 * np.pi * np.arange(100) / 100)
    exc = LoopedExcitation.from_volts(period * 5.0, CAL, fade_samples=250)
    core = DuplexCore(exc, n_inputs=2, n_outputs=2, output_channel=1)
    out = np.zeros((1000, 2), dtype=np.float32)
    core.process(None, out, 0)
    assert np.all(out[:, 0] == 0)
    n = np.arange(1000)
    envelope = np.where(n < 250, 0.5 - 0.5 * np.cos(np.pi * n / 250), 1.0)
    assert np.allclose(out[:, 1], 0.5 * np.sin(2 * np.pi * n / 100) * envelope, atol=1e-6)
    core.request_fade_out()
    tail = np.zeros((300, 2), dtype=np.float32)
    core.process(None, tail, 0)
    m = np.arange(300)
    fade = np.where(m < 250, 0.5 + 0.5 * np.cos(np.pi * m / 250), 0.0)
    assert np.allclose(tail[:, 1], 0.5 * np.sin(2 * np.pi * (1000 + m) / 100) * fade, atol=1e-6)
    assert core.output_finished
    core.process(None, tail, 0)
    assert not tail.any()


def test_the_output_is_the_same_in_blocks_of_any_size_fades_included():
    """The callback fills blocks of whatever size the device asks, a fade-in shorter than a block or longer than
    a period, a fade-out asked in the middle of the fade-in: sample for sample the looped period times the
    raised-cosine envelopes, as one long block would be."""
    rng = np.random.default_rng(7)
    period = rng.uniform(-1.0, 1.0, 37)
    exc = LoopedExcitation.from_volts(period * 10.0, CAL, fade_samples=90)
    core = DuplexCore(exc, n_inputs=1, n_outputs=3, output_channel=2)
    blocks, written, fade_from = [], 0, None
    while not core.output_finished:
        out = np.full((int(rng.integers(1, 60)), 3), 7.0, dtype=np.float32)
        if fade_from is None and written >= 70:         # during the fade-in (90 samples)
            core.request_fade_out()
            fade_from = written
        core.process(None, out, 0)
        assert np.all(out[:, :2] == 0)
        blocks.append(out[:, 2].copy())
        written += len(out)
    got = np.concatenate(blocks)
    n = np.arange(got.size)
    envelope = np.where(n < 90, 0.5 - 0.5 * np.cos(np.pi * n / 90), 1.0)
    into = n - fade_from
    envelope *= np.where(into < 0, 1.0, np.where(into < 90, 0.5 + 0.5 * np.cos(np.pi * into / 90), 0.0))
    expected = period.astype(np.float32)[n % 37] * envelope          # CAL: 10 V -> 1 FS
    assert np.allclose(got, expected, atol=1e-6)
    assert got.size >= fade_from + 90 and not got[fade_from + 90:].any()


def test_output_above_full_scale_is_clipped_and_counted():
    exc = LoopedExcitation.from_volts(np.array([0.0, 15.0, -12.0, 3.0]), CAL, fade_samples=0)
    assert exc.clipped_per_period == 2
    assert exc.requested_peak_fs == pytest.approx(1.5)
    assert np.max(np.abs(exc.period)) == 1.0


def test_input_blocks_are_copied_counted_and_dropped_when_the_queue_is_full():
    exc = LoopedExcitation.from_volts(np.zeros(64), CAL, 0)
    core = DuplexCore(exc, 2, 1, 0, queue_blocks=2)
    buffer = np.ones((16, 2), dtype=np.float32)
    core.process(buffer, np.zeros((16, 1), np.float32), 0)
    buffer[:] = 7          # the driver reuses its buffer: the queued block must not change
    core.process(buffer, np.zeros((16, 1), np.float32), INPUT_OVERFLOW | OUTPUT_UNDERFLOW)
    core.process(buffer, np.zeros((16, 1), np.float32), 0)
    blocks = core.take_blocks(0.1)
    assert [b.start for b in blocks] == [0, 16]
    assert np.all(blocks[0].samples == 1)
    counters = core.counters()
    assert counters.queue_overflows == 1 and counters.frames_in == 48
    assert counters.input_overflows == 1 and counters.output_underflows == 1 and counters.xruns == 2


# --- the period collector --------------------------------------------------

def periodic_blocks(period, n_samples, block, start_signal=0, flags_at=()):
    t = np.arange(n_samples)
    x = np.stack([np.sin(2 * np.pi * t / period), np.cos(2 * np.pi * t / period)], axis=1).astype(np.float32)
    x[:start_signal] = 0
    for a in range(0, n_samples, block):
        yield InputBlock(a, x[a:a + block], INPUT_OVERFLOW if a in flags_at else 0)


def test_periods_start_on_the_grid_after_the_fade_and_the_settle():
    c = PeriodCollector(period=100, n_inputs=2, n_periods=3, settle=200, fade=50)
    for b in periodic_blocks(100, 1000, 64):
        c.add(b)
    assert c.done and c.kept_start == 300          # ceil((50 + 200) / 100) * 100
    data = c.data()
    assert data.shape == (300, 2)
    assert np.allclose(data[:100], data[100:200]) and np.allclose(data[:100, 0], np.sin(2 * np.pi * np.arange(100) / 100),
                                                                atol=1e-6)


def test_settle_counts_from_the_first_signal_when_the_inputs_start_silent():
    c = PeriodCollector(100, 2, 2, settle=200, fade=10)
    for b in periodic_blocks(100, 1000, 50, start_signal=130):
        c.add(b)
    assert c.first_signal == 130 and c.kept_start == 400


def test_a_gap_drops_only_the_period_it_falls_in():
    c = PeriodCollector(100, 2, 3, settle=0)
    blocks = list(periodic_blocks(100, 1000, 50))
    for b in blocks[:5] + blocks[6:]:        # samples 250..299 lost
        c.add(b)
    assert c.done and c.gaps == 1 and c.samples_lost == 50
    assert c.kept_start == 0 and c.restarts == 0
    assert np.allclose(c.data()[100:200], c.data()[:100])    # period 2 (200..299) was skipped, 300.. kept


def test_an_xrun_discards_the_kept_periods_and_settles_again():
    c = PeriodCollector(100, 2, 3, settle=200)
    for b in periodic_blocks(100, 2000, 50, flags_at=(250,)):
        c.add(b)
    assert c.restarts == 1 and c.xrun_blocks == 1
    assert c.kept_start == 500                # ceil((300 + 200) / 100) * 100


# --- rig settings ----------------------------------------------------------

def test_rig_faults_and_noise_parse_and_describe():
    faults = RigFaults.parse(["disconnect=current,clip=5", "noise=10"])
    assert faults.disconnected == {"current"} and faults.amp_clip_volts == 5 and faults.noise_factor == 10
    assert RigFaults.parse([",".join(faults.describe())]) == faults
    assert RigNoise.parse("current=1e-6").current == 1e-6
    with pytest.raises(ValueError, match="unknown fault"):
        RigFaults.parse(["explode=1"])
    with pytest.raises(ValueError, match="cannot disconnect"):
        RigFaults.parse(["disconnect=amplifier"])
    assert RIG_CALIBRATION.amperes_per_fs == pytest.approx(2.0)


# --- PortAudio missing -------------------------------------------------------

def test_without_portaudio_the_error_is_clear_and_the_simulator_still_works(tmp_path):
    # A stand-in sounddevice that fails as the real one does when libportaudio2 is missing.
    (tmp_path / "sounddevice.py").write_text("raise OSError('PortAudio library not found')\n")
    script = textwrap.dedent("""
        import numpy as np
        from instruments.audio import AudioDeviceChoice, AudioUnavailable, SimulatedAudio, SoundDeviceAudio, capture
        from instruments.audio import list_devices
        from instruments.rig.engine import RIG_CALIBRATION
        try:
            list_devices()
        except AudioUnavailable as exc:
            print("LIST:", exc)
        try:
            SoundDeviceAudio(None, RIG_CALIBRATION).start(None)
        except AudioUnavailable as exc:
            print("START:", exc)
        wave = np.sin(2 * np.pi * 3 * np.arange(1024) / 1024)
        got = capture(SimulatedAudio(realtime=False), wave, 2, 1, fade_s=0.0)
        print("SIMULATED:", got.n_periods)
    """)
    # The project is installed (pip -e), so the stand-in only needs to come first on the path.
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=paced(120),
                            env={**os.environ, "PYTHONPATH": str(tmp_path)})
    assert result.returncode == 0, result.stderr
    assert "LIST: PortAudio is not available (PortAudio library not found): install the Debian package " \
           "libportaudio2" in result.stdout
    assert "START: PortAudio is not available" in result.stdout
    assert "SIMULATED: 2" in result.stdout
