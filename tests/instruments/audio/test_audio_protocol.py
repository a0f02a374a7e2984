"""One test suite for every AudioInterface: SimulatedAudio, and SoundDeviceAudio on the virtual rig's JACK server.

The rig variant is the real path: python-sounddevice, PortAudio's JACK host
API, a JACK server, and the rig process computing the driver in its JACK
callback. Faults are injected the way each implementation allows (the rig
through its command socket); what is asserted is the same.
"""
from __future__ import annotations

import threading
import time
from contextlib import contextmanager

import numpy as np
import pytest

from analysis.derived import derived_from_values
from analysis.drivers import load_driver
from analysis.multitone import design_multitone
from analysis.pipeline import analyze_recording
from instruments.audio import (
    JACK_HOSTAPI, AudioDeviceChoice, AudioError, AudioInterface, AudioSpec, CaptureCancelled, SimulatedAudio,
    SoundDeviceAudio, capture, open_audio)
from instruments.rig.engine import RigFaults
from tests.pace import paced

PAPER = load_driver("paper")
TRUTH = {**PAPER.parameters, **derived_from_values(PAPER.parameters)}
PERIOD = 16384                      # divides the rig's 65,536-tap FIR: its steady state is exact
SETTLE = 5                          # > the FIR length (4 periods) plus the round-trip latency
MULTITONE = design_multitone(48000, PERIOD, 5.0, 10000.0, rms=1.0)


class SimulatedSetup:
    name = "simulated"

    def __init__(self):
        self.audio = None

    def make_audio(self) -> SimulatedAudio:
        self.audio = open_audio(AudioSpec("simulated", options={"realtime": False, "seed": 2}))
        return self.audio

    @contextmanager
    def faults(self, *specs):
        self.audio.faults = RigFaults.parse(specs)
        yield

    def inject_xrun(self):
        self.audio.inject_xrun()


class RigSetup:
    name = "sounddevice+rig"

    def __init__(self, rig):
        self.rig = rig

    def make_audio(self) -> SoundDeviceAudio:
        state = self.rig.state
        audio = open_audio(AudioSpec("sounddevice", AudioDeviceChoice("system", JACK_HOSTAPI),
                                     state.workstation_calibration, state.sample_rate, state.workstation_channel_map))
        helper = open_audio(AudioSpec("rig", options={"rig": self.rig}))     # the rig's back end builds the same
        assert (helper.device, helper.calibration, helper.channel_map) == (audio.device, audio.calibration,
                                                                            audio.channel_map)
        return audio

    @contextmanager
    def faults(self, *specs):
        self.rig.command("fault", set=list(specs))
        try:
            yield
        finally:
            self.rig.command("fault", clear=True)

    def inject_xrun(self):
        self.rig.command("xrun", seconds=0.1)


@pytest.fixture(scope="session")
def rig_portaudio(virtual_rig):
    """PortAudio pointed at the rig's JACK server (it reads JACK_DEFAULT_SERVER when it initialises)."""
    from instruments.audio import portaudio
    portaudio.use_jack_server(virtual_rig.state.jack_server)
    return virtual_rig


@pytest.fixture(params=["simulated", pytest.param("sounddevice+rig", marks=pytest.mark.rig)])
def setup(request):
    if request.param == "simulated":
        return SimulatedSetup()
    return RigSetup(request.getfixturevalue("rig_portaudio"))


def assert_recovers_the_paper_driver(captured):
    result = analyze_recording(captured.to_recording(MULTITONE.excited_bins, {"name": "paper", "sd_m2": 0.0133}))
    for name in ("RE", "fs", "Bl", "Mms", "Qts"):
        assert result.parameters[name].value == pytest.approx(TRUTH[name], rel=0.005), name
    assert result.parameters["lambda"].value == pytest.approx(TRUTH["lambda"], abs=0.01)
    return result


def test_a_multitone_capture_recovers_the_paper_driver(setup):
    audio = setup.make_audio()
    assert isinstance(audio, AudioInterface)
    captured = capture(audio, MULTITONE.waveform, n_periods=4, settle_periods=SETTLE)
    assert captured.n_periods == 4 and captured.displacement is not None
    stats = captured.stats
    assert stats.problems() == [], stats
    assert stats.discarded_samples >= stats.fade_samples + SETTLE * PERIOD
    assert stats.samples_lost == 0 and stats.restarts == 0
    assert 0.01 < dict(stats.full_scale_fraction)["current"] < 0.999
    assert_recovers_the_paper_driver(captured)


def test_a_disconnected_current_channel_is_silent(setup):
    audio = setup.make_audio()
    with setup.faults("disconnect=current"):
        captured = capture(audio, MULTITONE.waveform, n_periods=2, settle_periods=1)
    assert not captured.current.any()
    assert np.std(captured.voltage) > 0.1
    assert captured.stats.silent_channels == ("current",)
    assert any("current is silent" in p for p in captured.stats.problems())


def test_an_xrun_restarts_the_averaging_and_the_result_stays_right(setup):
    audio = setup.make_audio()
    injected = []

    def progress(kept, wanted):
        if kept >= 1 and not injected:
            injected.append(kept)
            setup.inject_xrun()

    captured = capture(audio, MULTITONE.waveform, n_periods=3, settle_periods=SETTLE, progress=progress)
    assert injected
    assert captured.stats.xruns >= 1 and captured.stats.restarts >= 1
    assert captured.n_periods == 3
    assert_recovers_the_paper_driver(captured)


def test_cancel_ends_the_capture_and_keeps_the_periods(setup):
    audio = setup.make_audio()
    cancel = threading.Event()

    def progress(kept, wanted):
        if kept >= 1:
            cancel.set()

    with pytest.raises(CaptureCancelled) as info:
        capture(audio, MULTITONE.waveform, n_periods=50, settle_periods=1, cancel=cancel, progress=progress)
    partial = info.value.partial
    assert partial is not None and partial.n_periods >= 1
    assert partial.voltage.size == partial.n_periods * PERIOD
    assert not audio.running


def test_inputs_that_turn_silent_mid_capture_end_it_within_2_s_keeping_the_periods(setup):
    audio = setup.make_audio()
    switched = {}
    stack = []

    def progress(kept, wanted):
        if kept >= 1 and not switched:
            switched["at"] = time.monotonic()
            context = setup.faults("disconnect=voltage", "disconnect=current", "disconnect=displacement")
            context.__enter__()
            stack.append(context)

    try:
        with pytest.raises(AudioError, match="exact zeros") as info:
            capture(audio, MULTITONE.waveform, n_periods=50, settle_periods=1, progress=progress)
        assert time.monotonic() - switched["at"] < paced(2.0)
        assert info.value.partial.n_periods >= 1
    finally:
        for context in stack:
            context.__exit__(None, None, None)


def test_the_time_limit_ends_a_capture_with_what_was_kept(setup):
    audio = setup.make_audio()
    if isinstance(audio, SimulatedAudio):
        audio.realtime = True       # as fast as read would finish 50 periods before any limit
    with pytest.raises(AudioError, match="longer than its limit") as info:
        capture(audio, MULTITONE.waveform, n_periods=50, settle_periods=0, timeout_s=1.5)
    assert info.value.partial.n_periods >= 1


def test_a_simulated_device_that_stops_delivering_ends_the_capture_within_2_s():
    audio = SimulatedAudio(realtime=False)
    stopped = {}

    def progress(kept, wanted):
        if kept >= 2 and not stopped:
            stopped["at"] = time.monotonic()
            audio.stop_delivering()

    with pytest.raises(AudioError, match="no samples") as info:
        capture(audio, MULTITONE.waveform, n_periods=50, settle_periods=1, progress=progress)
    assert time.monotonic() - stopped["at"] < paced(2.0)
    assert info.value.partial.n_periods >= 2
