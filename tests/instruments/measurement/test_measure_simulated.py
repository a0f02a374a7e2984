"""run_measurement in-process: SimulatedAudio (real time) and SimulatedLaser, no JACK, no pty.

The simulated laser measures the simulated rig's cone through the same
DisplacementFeed the virtual rig uses (instruments/rig/laser_feed.py), on its
own clock (off by ppm, starting late): so the alignment meets a real clock
problem. The emulation keeps one clock, the sound card's frame counter
(instruments/rig/frame_clock.py), so where the laser's samples really sat is
known (InProcessRig.truth) and the tests hold the alignment to it. A FIR of
one period (8,192 taps) settles in two periods and keeps each run near a
second of sound.
"""
from __future__ import annotations

import json
import threading
import time

import numpy as np
import pytest

from analysis.derived import derived_from_values
from analysis.drivers import load_driver
from instruments.laser import LaserSpec, open_laser
from instruments.laser.ild1420 import ErrorPlan
from instruments.measurement import (
    MeasurementCancelled, MeasurementError, MeasurementFailed, MeasurementPlan, run_measurement)
from instruments.measurement.raw_stream import read_raw_capture
from instruments.rig.engine import RIG_CALIBRATION
from instruments.rig.in_process import InProcessRig
from instruments.simulation.linear_driver import LinearBlockDriver
from tests.pace import paced

# The in-process simulator runs in real time and its laser's link is judged against its own deadlines: in the
# rig's unit of the suite (tests/scheduling.py), not beside another real-time rig.
pytestmark = pytest.mark.rig

PAPER = load_driver("paper")
TRUTH = {**PAPER.parameters, **derived_from_values(PAPER.parameters)}
PERIOD = 8192
# How closely the delay found from the data (delay-x) matches where the emulation really put the laser's
# samples against the alignment (InProcessRig.truth), whatever the host's threads did: measured within
# 0.2 us at link latencies 0 - 20 ms with 2 ms of jitter; the bound the issue asks for.
FIT_TAU_S = 20e-6


def plan(**changes) -> MeasurementPlan:
    base = dict(period_samples=PERIOD, n_periods=4, settle_periods=2, f_min_hz=5.0,
                driver={"name": PAPER.name, "sd_m2": PAPER.sd_m2})
    return MeasurementPlan.from_template("woofer", **{**base, **changes})


def simulated(ppm=0.0, latency_s=0.0, error_plan=None, serial=True, link_latency_s=0.0, link_jitter_s=0.0):
    """The paper driver on a one-period FIR and, with ``serial``, a SimulatedLaser measuring its cone."""
    driver = LinearBlockDriver(PAPER.model(), dict(PAPER.parameters), 48000, fir_length=PERIOD)
    return InProcessRig(driver, "simulated" if serial else "analog", ppm=ppm, start_latency_s=latency_s,
                        link_latency_s=link_latency_s, link_jitter_s=link_jitter_s, error_plan=error_plan,
                        realtime=True)


def assert_recovers(result, names=("RE", "fs", "Bl", "Mms", "Qts"), rel=0.005):
    for name in names:
        assert result.parameters[name].value == pytest.approx(TRUTH[name], rel=rel), name
    assert result.parameters["lambda"].value == pytest.approx(TRUTH["lambda"], abs=0.01)


def test_the_serial_laser_is_aligned_and_the_driver_recovered_with_everything_on_disk_first(tmp_path):
    rig = simulated(ppm=150.0, latency_s=0.05)
    audio, laser = rig.audio, rig.laser
    frames, on_disk = [], {}

    def progress(p):
        if p.stage == "analysing":       # the analysis has not started: every file must be there already
            on_disk.update({name: (tmp_path / name).is_file() for name in ("m.wav", "m.json", "m.laser.npz")})

    def broken_panel(frame):
        raise RuntimeError("a panel that fails")

    outcome = run_measurement(plan(), audio, laser, tmp_path, name="m", listeners=[frames.append, broken_panel],
                              progress=progress)
    assert on_disk == {"m.wav": True, "m.json": True, "m.laser.npz": True}
    assert outcome.ended_by == "complete" and not outcome.partial and outcome.periods == 4
    # The live view averages the periods in order; one it could not reach in time (the measurement thread
    # behind, or the laser's stream not yet past the last period when the capture ended) is left out,
    # so how many frames came depends on the host's scheduling, not on the product.
    counts = [f.n_periods for f in frames]
    assert counts and counts == list(range(1, len(counts) + 1)) and len(counts) <= 4
    assert "displacement" in frames[-1].channels and frames[-1].peak_displacement_m > 1e-4
    assert_recovers(outcome.result)
    assert "delay-x" in outcome.result.model.effect_ids
    # What the 50 ms start latency and the host's threads leave, wherever the host put it, is found from the
    # data (see the link-latency test).
    offset_error = rig.truth().delay_s(outcome.alignment["offset_audio_samples"], 48000)
    assert outcome.result.fit.values["tau_x"] == pytest.approx(offset_error, abs=FIT_TAU_S)
    assert outcome.alignment["clock_ppm"] == pytest.approx(150.0, abs=0.5)
    sidecar = json.loads(outcome.sidecar_path.read_text())
    assert sidecar["displacement_max_hz"] == pytest.approx(0.44 * 4000, rel=1e-3)
    assert sidecar["measurement"]["partial"] is False
    assert sidecar["capture"]["laser_samples"] > 4 * PERIOD / 12 and sidecar["capture"]["laser_error_counts"] == {}
    arrays, info = read_raw_capture(outcome.raw_path)
    assert arrays["distance_m"].size > sidecar["capture"]["laser_samples"]
    assert info["laser"]["alignment"]["clock_ppm"] == outcome.alignment["clock_ppm"]


@pytest.mark.parametrize("latency_ms", [0.0, 3.0, 8.0, 15.0, 20.0])
def test_a_usb_links_latency_with_jitter_is_found_from_the_data(tmp_path, record_property, latency_ms):
    """A laser behind a USB serial adapter: its samples come in packets, late by a latency the host times
    cannot see plus up to 2 ms of jitter. The delay the alignment leaves (the truth: where the emulation put
    the samples) is found from Hx against the model, with no start from the host, and the driver recovered."""
    rig = simulated(ppm=-30.0, link_latency_s=latency_ms * 1e-3, link_jitter_s=2e-3)
    outcome = run_measurement(plan(), rig.audio, rig.laser, tmp_path, name="m")
    injected = rig.truth().delay_s(outcome.alignment["offset_audio_samples"], 48000)
    result = outcome.result
    found = result.fit.values["tau_x"]
    record_property("delay_error_s", found - injected)      # for the spread over runs (--junitxml)
    assert found == pytest.approx(injected, abs=FIT_TAU_S)
    assert result.validity.laser_delay["placed"] is True and result.validity.overall == "green"
    for name in ("Bl", "Mms", "Kms"):
        assert result.parameters[name].value == pytest.approx(TRUTH[name], rel=0.005), name
    assert result.parameters["tau_x"].std < FIT_TAU_S       # reported with its uncertainty


def test_laser_error_codes_are_counted_not_averaged_and_judged(tmp_path):
    rig = simulated(ppm=-60.0, error_plan=ErrorPlan(error_share=0.02, seed=4))
    audio, laser = rig.audio, rig.laser
    outcome = run_measurement(plan(), audio, laser, tmp_path, name="m")
    capture = json.loads(outcome.sidecar_path.read_text())["capture"]
    share = capture["laser_error_counts"]["262076"] / capture["laser_samples"]
    assert share == pytest.approx(0.02, abs=0.006)
    findings = outcome.result.validity.as_json()["channels"]["displacement"]["findings"]
    assert "laser-errors" in {f["code"] for f in findings}
    assert outcome.result.parameters["Bl"].value == pytest.approx(TRUTH["Bl"], rel=0.005)


def test_a_pulled_laser_cable_ends_the_measurement_within_2_s_and_keeps_the_periods(tmp_path):
    rig = simulated(ppm=20.0)
    audio, laser = rig.audio, rig.laser
    pulled = {}

    def progress(p):
        if p.periods_kept >= 3 and not pulled:
            pulled["at"] = time.monotonic()
            laser.disconnect()

    with pytest.raises(MeasurementFailed, match="laser link lost") as info:
        run_measurement(plan(n_periods=20), audio, laser, tmp_path, name="m", progress=progress)
    assert time.monotonic() - pulled["at"] < paced(2.0)
    outcome = info.value.outcome
    assert outcome.ended_by == "laser" and outcome.partial and outcome.result is None
    assert 2 <= outcome.periods <= 4
    sidecar = json.loads(outcome.sidecar_path.read_text())
    assert sidecar["measurement"]["partial"] is True and sidecar["measurement"]["ended_by"] == "laser"
    assert outcome.recording.n_periods == outcome.periods and outcome.raw_path.is_file()
    assert str(outcome.recording_path) in str(info.value)


def test_an_xrun_ends_the_measurement_keeping_the_periods_before_it(tmp_path):
    rig = simulated()
    audio, laser = rig.audio, rig.laser
    injected = {}

    def progress(p):
        if p.periods_kept >= 2 and not injected:
            injected["at"] = time.monotonic()
            audio.inject_xrun()

    with pytest.raises(MeasurementFailed, match="xrun") as info:
        run_measurement(plan(n_periods=20), audio, laser, tmp_path, name="m", progress=progress)
    assert time.monotonic() - injected["at"] < paced(2.0)
    outcome = info.value.outcome
    assert outcome.ended_by == "xrun" and outcome.periods >= 2
    assert json.loads(outcome.sidecar_path.read_text())["capture"]["xruns"] == 0     # none inside the periods


def test_with_on_xrun_restart_the_serial_laser_measurement_averages_again_after_an_xrun(tmp_path):
    rig = simulated(ppm=90.0)
    audio, laser = rig.audio, rig.laser
    injected = {}

    def progress(p):
        if p.periods_kept >= 2 and not injected:
            injected["at"] = p.periods_kept
            audio.inject_xrun()

    outcome = run_measurement(plan(on_xrun="restart"), audio, laser, tmp_path, name="m", progress=progress)
    stats = json.loads(outcome.sidecar_path.read_text())["audio_capture"]
    assert injected and stats["restarts"] >= 1 and outcome.periods == 4
    assert outcome.alignment["clock_ppm"] == pytest.approx(90.0, abs=0.5)
    assert_recovers(outcome.result)


def test_after_an_xrun_restart_the_live_frames_average_again_from_the_new_periods(tmp_path):
    """capture() discards its periods after an xrun and averages again; the live panels must follow (they
    stopped at one frame: the new periods were looked for at the old periods' places)."""
    rig = simulated(serial=False)
    frames, injected = [], {}

    def progress(p):
        if p.periods_kept >= 2 and not injected:
            injected["at"] = p.periods_kept
            rig.audio.inject_xrun()

    outcome = run_measurement(plan(on_xrun="restart"), rig.audio, None, tmp_path, name="m",
                              listeners=[frames.append], progress=progress)
    counts = [f.n_periods for f in frames]
    assert outcome.periods == 4 and injected
    restart = counts.index(1, 1)                  # the second time a frame rests on one period
    assert counts[:restart] == list(range(1, restart + 1)) and counts[restart:] == [1, 2, 3, 4]


def test_cancel_keeps_what_was_captured(tmp_path):
    rig = simulated()
    audio, laser = rig.audio, rig.laser
    cancel = threading.Event()

    def progress(p):
        if p.periods_kept >= 2:
            cancel.set()

    with pytest.raises(MeasurementCancelled) as info:
        run_measurement(plan(n_periods=20), audio, laser, tmp_path, name="m", cancel=cancel, progress=progress)
    assert info.value.outcome.ended_by == "cancelled" and info.value.outcome.periods >= 2


def test_without_a_serial_laser_the_analog_input_is_the_displacement(tmp_path):
    audio = simulated(serial=False).audio
    corrections = {"current_gain": 1.02, "current_delay_s": 3e-6, "source": "4 ohm"}
    outcome = run_measurement(plan(calibration={"corrections": corrections}), audio, None, tmp_path, name="m")
    assert outcome.raw_path is None and not (tmp_path / "m.laser.npz").exists()
    sidecar = json.loads(outcome.sidecar_path.read_text())
    # The calibration the measurement used is in the recording itself, not only in the program's settings.
    assert sidecar["calibration"]["corrections"] == corrections
    assert sidecar["calibration"]["sound_card"]["shunt_ohm"] == RIG_CALIBRATION.shunt_ohm
    assert "displacement_max_hz" not in sidecar
    assert sidecar["measurement"]["displacement_source"] == "sound card (laser analog)"
    assert outcome.result.model.effect_ids == ("lr2", "creep-log")
    assert_recovers(outcome.result)


def test_a_laser_that_does_not_answer_stops_it_before_anything_plays(tmp_path):
    audio = simulated(serial=False).audio
    with pytest.raises(MeasurementError, match="not connected"):
        run_measurement(plan(), audio, open_laser(LaserSpec(simulated=True, options={"connected": False})), tmp_path, name="m")
    assert list(tmp_path.iterdir()) == []
    assert not audio.running


def test_plans_come_from_templates_and_refuse_what_cannot_work():
    assert MeasurementPlan.from_template("woofer").settle == 2          # 65,536-sample periods
    assert MeasurementPlan.from_template("midrange").settle == 5        # 16,384: the rig's FIR + round trip
    assert MeasurementPlan.from_template("tweeter").f_min_hz >= 200
    assert MeasurementPlan.from_template("woofer", level_v_rms=2.0).level_v_rms == 2.0
    for bad in ({"period_samples": 10000}, {"n_periods": 1}, {"level_v_rms": 0.0}, {"on_xrun": "ignore"}):
        with pytest.raises(ValueError):
            MeasurementPlan.from_template("woofer", **bad)
    with pytest.raises(ValueError, match="unknown template"):
        MeasurementPlan.from_template("subwoofer")
    assert MeasurementPlan().end_on_xrun(serial_laser=True) and not MeasurementPlan().end_on_xrun(False)
    assert not MeasurementPlan(on_xrun="restart").end_on_xrun(serial_laser=True)
    excitation = plan().excitation(48000)
    assert excitation.rms == pytest.approx(1.0) and excitation.period_samples == PERIOD
