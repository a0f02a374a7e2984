"""The large-signal plan and the identification through the virtual rig's nonlinear model, with the serial laser.

In-process (instruments.rig.in_process): SimulatedAudio in real time drives
the nonlinear simulator with the issue's known polynomials, and the cone is
read by the byte-level laser emulator on a pseudo-terminal through the real
ILD1420 driver, on a clock of its own: the identification meets the serial
laser's band (1.76 kHz), its alignment and its leftover delay. The JACK rig
runs the plan end to end from the command line in test_cli_large_signal_rig.
"""
from __future__ import annotations

import dataclasses
import json
import time
from types import SimpleNamespace

import pytest

from analysis.large_signal import large_signal
from analysis.large_signal.stepping import StepLimits
from instruments.measurement import MeasurementPlan, run_measurement, timed_audio
from instruments.measurement.large_signal_plan import LargeSignalPlan, run_large_signal
from instruments.rig.engine import RIG_CALIBRATION
from instruments.rig.in_process import InProcessRig
from tests.large_signal_truth import KNOWN_LEVEL_V, KNOWN_OFFSET_M, KNOWN_X_BL_M, known_driver, relative_errors

# Real time, like the rig's tests: in their unit of the suite (tests/scheduling.py).
pytestmark = [pytest.mark.timeout(240), pytest.mark.rig]
# +-4 mm needs ~10.5 V RMS of multitone, 22 V peak, and ~5 A peak: the rig's chain (10 V out, 20 V and 2 A in at
# full scale) would clip. This one has a 30 V amplifier, 40 V and 10 A inputs.
LARGE_SIGNAL_CHAIN = dataclasses.replace(RIG_CALIBRATION, volts_per_fs_out=30.0, volts_per_fs_voltage_sense=40.0,
                                         current_amp_gain=1.0)


def plan(period=16384, periods=4, **changes) -> MeasurementPlan:
    # The driver's FIR spans one period: two settle it, one more for the audio's round trip.
    return MeasurementPlan.from_template("large-signal", period_samples=period, n_periods=periods,
                                         settle_periods=3, driver={"name": "known polynomials"}, **changes)


def test_the_known_polynomials_come_back_through_the_rig_with_the_serial_laser(tmp_path, record_property):
    rig = InProcessRig(known_driver(16384), "serial", ppm=40.0, start_latency_s=0.02, calibration=LARGE_SIGNAL_CHAIN)
    try:
        outcome = run_measurement(plan(level_v_rms=KNOWN_LEVEL_V), rig.audio, rig.laser, tmp_path, name="m",
                                  analyse=False)
    finally:
        rig.close()
    truth = known_driver(16384)
    result = large_signal([outcome.recording_path])
    lo, hi = result.model.x_range
    assert lo < -3.5e-3 and hi > 3.5e-3
    for name in ("Bl", "Kms"):
        worst, at_rest = relative_errors(result.model, truth, name)
        record_property(f"rig_{name}_worst_error_80_percent", worst)
        record_property(f"rig_{name}_0_error", at_rest)
        assert worst < 0.03 and abs(at_rest) < 0.01, name
    record_property("rig_offset_m", result.derived.offset_m)
    record_property("rig_X_Bl_m", result.derived.limits["X_Bl"].value)
    record_property("rig_laser_delay_s", result.identification.delays[0])
    assert result.derived.offset_m == pytest.approx(KNOWN_OFFSET_M, abs=1e-4)
    assert result.derived.limits["X_Bl"].value == pytest.approx(KNOWN_X_BL_M, abs=1e-4)
    assert result.identification.data[0].laser_delay_possible
    # The laser's delay found (no link latency): the result is not red (analysis/large_signal/trust.py).
    assert result.verdict != "red" and result.as_json()["validity"]["recordings"][0]["laser_delay_found"] is True


def test_a_usb_links_8_ms_with_jitter_is_found_and_the_known_polynomials_come_back(tmp_path, record_property):
    """8 ms between the laser's reading and its arrival, in packets with 2 ms of jitter (a USB serial adapter),
    far beyond the +-1 ms delay search: it is centred where the linear model places the delay (delay_start.py),
    and finds where the emulation really put the samples against the alignment."""
    rig = InProcessRig(known_driver(8192), "serial", ppm=40.0, start_latency_s=0.02, link_latency_s=8e-3,
                       link_jitter_s=2e-3, calibration=LARGE_SIGNAL_CHAIN)
    try:
        outcome = run_measurement(plan(period=8192, level_v_rms=KNOWN_LEVEL_V), rig.audio, rig.laser, tmp_path,
                                  name="m", analyse=False)
        injected = rig.truth().delay_s(outcome.alignment["offset_audio_samples"], 48000)
    finally:
        rig.close()
    result = large_signal([outcome.recording_path])
    found = result.identification.delays[0]
    record_property("rig_laser_delay_error_s", found - injected)
    assert found == pytest.approx(injected, abs=20e-6)
    assert result.verdict != "red" and result.as_json()["validity"]["recordings"][0]["laser_delay_found"] is True
    for name in ("Bl", "Kms"):
        _, at_rest = relative_errors(result.model, known_driver(8192), name)
        assert abs(at_rest) < 0.01, name


def test_the_plan_steps_up_to_the_excursion_limit_and_keeps_every_step(tmp_path):
    rig = InProcessRig(known_driver(8192), "simulated", calibration=LARGE_SIGNAL_CHAIN)
    limits = StepLimits(max_excursion_m=2.0e-3, max_voltage_v=20.0)
    steps_seen = []
    try:
        outcome = run_large_signal(LargeSignalPlan(plan(8192, 2), 1.0, step=2.0, limits=limits), rig.audio,
                                   rig.laser, tmp_path, name="ls", on_step=steps_seen.append,
                                   measure=run_measurement)
    finally:
        rig.close()
    assert outcome.stopped_by == "excursion", outcome.message
    levels = [s.level_v for s in outcome.steps if s.usable]    # a step measured again is kept, not usable
    assert levels[0] == 1.0 and all(b > a for a, b in zip(levels, levels[1:]))
    last = outcome.steps[-1].measures
    assert 0.98 * 2.0e-3 <= last.peak_m <= 2.3e-3          # shortened near the limit, not overshot
    assert [s.index for s in steps_seen] == [s.index for s in outcome.steps]
    assert len(outcome.recordings) == len(levels) and all(p.is_file() for p in outcome.recordings)
    summary = json.loads(outcome.summary_path.read_text())
    assert summary["stopped_by"] == "excursion"
    assert [s["recording"] for s in summary["steps"] if s["usable"]] == [p.name for p in outcome.recordings]
    assert all(len(s["measures"]["re_ohm_per_period"]) == 2 for s in summary["steps"])


def _plan_with_late_audio(tmp_path, monkeypatch, late_measurements: int, max_steps: int = 24):
    """The plan from 2 V on the in-process rig, the audio's blocks of the first ``late_measurements``
    measurements at 4 V noted 0.3 s late (injected in the time stamps, so the same whatever the load)."""
    lateness = {"s": 0.0}
    monkeypatch.setattr(timed_audio, "time", SimpleNamespace(monotonic=lambda: time.monotonic() + lateness["s"]))
    at_4_v = [0]

    def measure(step_plan, *args, **kwargs):
        at_4_v[0] += step_plan.level_v_rms == 4.0
        lateness["s"] = 0.3 if step_plan.level_v_rms == 4.0 and at_4_v[0] <= late_measurements else 0.0
        return run_measurement(step_plan, *args, **kwargs)

    rig = InProcessRig(known_driver(8192), "simulated", calibration=LARGE_SIGNAL_CHAIN)
    limits = StepLimits(max_excursion_m=2.0e-3, max_voltage_v=20.0)
    try:
        return run_large_signal(LargeSignalPlan(plan(8192, 2), 2.0, step=2.0, limits=limits, max_steps=max_steps),
                                rig.audio, rig.laser, tmp_path, name="ls", measure=measure)
    finally:
        rig.close()


def test_a_step_whose_audio_was_timed_late_twice_is_not_trusted_and_the_plan_stops_below_the_limit(
        tmp_path, monkeypatch):
    """A starved host notes the audio's blocks late: the laser's stream is placed 0.3 s off, one period of the
    coherent mean is the cone after the drive stopped, and the peak comes out about half the truth. The plan
    used to step from that to 8 V and 3.1 mm, past the 2 mm limit; the displacement not repeating while the
    voltage did says the peak cannot be trusted. The step is measured again; late again, the plan stops."""
    outcome = _plan_with_late_audio(tmp_path, monkeypatch, late_measurements=2)
    assert [s.level_v for s in outcome.steps] == [2.0, 4.0, 4.0], outcome.message
    assert outcome.stopped_by == "fault" and "displacement" in outcome.message
    assert "and so it did when measured again; the plan stops" in outcome.message
    first, again = outcome.steps[1:]
    assert first.message.startswith("measured again at the same level: the displacement at 4 V")
    assert "the plan stops" not in first.message and again.message == ""
    for late in (first, again):
        assert late.measures.displacement_change > 0.2 and not late.usable
        assert late.recording_path.is_file() and late.recording_path not in outcome.recordings
    assert outcome.steps[0].measures.displacement_change < 0.01
    assert [s["usable"] for s in json.loads(outcome.summary_path.read_text())["steps"]] == [True, False, False]


def test_a_step_timed_late_once_is_measured_again_and_the_plan_goes_on_to_its_limit(tmp_path, monkeypatch):
    """The host's moment passes: the step measured again repeats, and the plan steps on from it."""
    outcome = _plan_with_late_audio(tmp_path, monkeypatch, late_measurements=1)
    levels = [s.level_v for s in outcome.steps]
    assert levels[:3] == [2.0, 4.0, 4.0] and len(levels) >= 4, outcome.message
    assert outcome.stopped_by == "excursion", outcome.message
    late = outcome.steps[1]
    assert not late.usable and late.measures.displacement_change > 0.2 and "measured again" in late.message
    assert late.recording_path not in outcome.recordings
    assert all(s.usable and not s.message for s in outcome.steps[2:])
    assert 0.98 * 2.0e-3 <= outcome.steps[-1].measures.peak_m <= 2.3e-3      # not stepped past the limit


def test_the_plan_stops_at_the_voltage_limit(tmp_path):
    rig = InProcessRig(known_driver(8192), "analog", realtime=False, calibration=LARGE_SIGNAL_CHAIN)
    limits = StepLimits(max_excursion_m=10e-3, max_voltage_v=2.0)
    try:
        outcome = run_large_signal(LargeSignalPlan(plan(8192, 2), 1.0, step=1.5, limits=limits), rig.audio,
                                   None, tmp_path, name="ls", measure=run_measurement)
    finally:
        rig.close()
    assert outcome.stopped_by == "voltage" and [s.level_v for s in outcome.steps] == [1.0, 1.5, 2.0]


def test_an_input_at_full_scale_stops_the_plan(tmp_path):
    """The rig's own chain: its current input reads 2 A at full scale, which the driver passes near 5 V."""
    rig = InProcessRig(known_driver(8192), "analog", realtime=False)
    try:
        outcome = run_large_signal(LargeSignalPlan(plan(8192, 2), 2.0, step=2.0), rig.audio, None, tmp_path,
                                   name="ls", measure=run_measurement)
    finally:
        rig.close()
    assert outcome.stopped_by == "clipping" and "current" in outcome.message
    assert outcome.steps[-1].measures.clipped == ("current",)
    assert all(not s.measures.clipped for s in outcome.steps[:-1])
    # Kept on disk, left out of what is identified.
    assert outcome.steps[-1].recording_path.is_file() and outcome.steps[-1].recording_path not in outcome.recordings
    assert json.loads(outcome.summary_path.read_text())["steps"][-1]["usable"] is False


def test_a_fault_mid_plan_stops_it_safely_keeping_what_it_has(tmp_path):
    """The laser's cable pulled during the second step: the first step stays complete, the second's whole
    periods stay as a partial recording, and the summary says what happened."""
    rig = InProcessRig(known_driver(8192), "simulated")
    pulled = {}

    def progress(p):
        if "step 2" in p.message and p.periods_kept >= 1 and not pulled:
            pulled["at"] = p.periods_kept
            rig.laser.disconnect()

    try:
        outcome = run_large_signal(LargeSignalPlan(plan(8192, 4), 1.0, step=1.5), rig.audio, rig.laser, tmp_path,
                                   name="ls", progress=progress, measure=run_measurement)
    finally:
        rig.close()
    assert pulled and outcome.stopped_by == "fault" and "laser" in outcome.message
    first, second = outcome.steps
    assert not first.partial and first.recording_path.is_file()
    assert second.partial and second.measures is None
    assert outcome.recordings == [first.recording_path]
    summary = json.loads(outcome.summary_path.read_text())
    assert summary["stopped_by"] == "fault" and summary["steps"][1]["partial"] is True


def test_a_step_timed_late_as_the_plans_last_stops_it_rather_than_pass_for_all_steps_measured(tmp_path,
                                                                                              monkeypatch):
    outcome = _plan_with_late_audio(tmp_path, monkeypatch, late_measurements=1, max_steps=2)
    assert [s.level_v for s in outcome.steps] == [2.0, 4.0]
    assert outcome.stopped_by == "fault" and "measured again" not in outcome.message
    assert outcome.steps[-1].message == "" and not outcome.steps[-1].usable
