"""Calibration against a reference resistor: the corrections, their storage, and the stream's delay correction."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from analysis.multitone import design_multitone
from analysis.recording.format import make_recording
from analysis.spectra import estimate_spectra
from app.wizard import MeasureWizard
from app.wizard.calibration import Corrections, check_resistor, measure_resistor
from app.wizard.calibration_page import settings_key
from app.wizard.corrected_audio import DelayCorrectedAudio
from app.wizard.hardware import RIG, HardwareConfig
from instruments.audio.config import ChannelMap
from instruments.audio.stream_core import InputBlock
from instruments.rig.engine import RIG_CALIBRATION

from tests.app.wizard.test_wizard_helpers import choose_simulator, plain, run_job, to_hardware

FS, PERIOD = 48000, 4096


def resistor_recording(r_ohm: float, gain: float, lag_s: float):
    """U across R and the current as a channel with that gain and lag reads it, 4 periods."""
    mt = design_multitone(FS, PERIOD, 20.0, 20000.0, rms=1.0, crest_iterations=0)
    u = np.tile(mt.waveform, 4)
    spectrum = np.fft.rfft(mt.waveform) / r_ohm * gain * np.exp(-2j * np.pi * np.fft.rfftfreq(PERIOD, 1 / FS) * lag_s)
    i = np.tile(np.fft.irfft(spectrum, PERIOD), 4)
    return make_recording(FS, {"voltage": u, "current": i}, PERIOD, excited_bins=tuple(int(b) for b in mt.excited_bins))


def test_gain_and_delay_of_the_current_channel_are_found():
    check = check_resistor(estimate_spectra(resistor_recording(8.2, 1.04, 25e-6)), 8.2)
    assert check.ok, check.problems
    # Z = U / I_read = R / 1.04 with the phase of a 25 us lead: I must be read x 1/1.04 and advanced by 25 us.
    assert check.corrections.current_gain == pytest.approx(1 / 1.04, rel=1e-9)
    assert check.corrections.current_delay_s == pytest.approx(25e-6, rel=1e-6)
    assert check.phase_residual_deg < 1e-6


def test_a_resistor_of_another_value_or_an_inductive_one_is_refused():
    wrong = check_resistor(estimate_spectra(resistor_recording(4.0, 1.0, 0.0)), 8.2)
    assert not wrong.ok and "not the 8.2 Ω given" in wrong.problems[0]
    mt = design_multitone(FS, PERIOD, 20.0, 20000.0, rms=1.0, crest_iterations=0)
    f = np.fft.rfftfreq(PERIOD, 1 / FS)
    z = 8.2 + 2j * np.pi * f * 50e-6                    # 50 uH: a wire-wound resistor
    i = np.fft.irfft(np.fft.rfft(mt.waveform) / z, PERIOD)
    rec = make_recording(FS, {"voltage": np.tile(mt.waveform, 4), "current": np.tile(i, 4)}, PERIOD,
                         excited_bins=tuple(int(b) for b in mt.excited_bins))
    inductive = check_resistor(estimate_spectra(rec), 8.2)
    assert not inductive.ok and any("not a pure resistance" in p or "a filter" in p for p in inductive.problems)


def test_the_corrections_make_a_miscalibrated_current_channel_right_on_the_simulator():
    wrong = replace(RIG_CALIBRATION, volts_per_fs_current_sense=RIG_CALIBRATION.volts_per_fs_current_sense * 1.03)
    config = HardwareConfig(realtime=False, calibration=wrong)
    check = measure_resistor(config, 6.8, 1.0)
    assert check.ok
    assert check.corrections.current_gain == pytest.approx(1 / 1.03, rel=1e-4)
    assert check.corrections.apply(wrong).amperes_per_fs == pytest.approx(RIG_CALIBRATION.amperes_per_fs, rel=1e-4)
    again = measure_resistor(replace(config, calibration=check.corrections.apply(wrong)), 6.8, 1.0)
    assert again.corrections.current_gain == pytest.approx(1.0, abs=1e-4)


class _Blocks:
    """A stand-in AudioInterface: hands out a fixed two-channel signal in blocks of 1000."""

    sample_rate = FS
    channel_map = ChannelMap(0, 0, 1, None)

    def __init__(self, signal):
        self.signal, self.position = signal, 0

    def start(self, excitation):
        pass

    def read_blocks(self, timeout):
        block = InputBlock(self.position, self.signal[self.position:self.position + 1000].astype(np.float32))
        self.position += 1000
        return (block,)


class _Excitation:
    period_samples = PERIOD


@pytest.mark.parametrize("bin_", [3, 850, 1700])
def test_the_stream_correction_advances_the_current_by_the_delay(bin_):
    n = np.arange(PERIOD * 6)
    tone = np.cos(2 * np.pi * bin_ * n / PERIOD)
    audio = DelayCorrectedAudio(_Blocks(np.stack([tone, tone], axis=1)), 37e-6)
    audio.start(_Excitation())
    out = np.concatenate([audio.read_blocks(0)[0].samples for _ in range(24)])
    steady = slice(3 * PERIOD, 4 * PERIOD)
    advanced = np.cos(2 * np.pi * bin_ * FS / PERIOD * (n[steady] / FS + 37e-6))
    assert np.max(np.abs(out[steady, 1] - advanced)) < 1e-4           # the current, advanced
    assert np.array_equal(out[steady, 0], tone[steady].astype(np.float32))    # the voltage, untouched


def test_lost_samples_make_the_corrected_stream_report_an_xrun():
    audio = DelayCorrectedAudio(_Blocks(np.zeros((PERIOD * 4, 2))), 10e-6)
    audio.start(_Excitation())
    assert audio.read_blocks(0)[0].flags == 0
    audio._audio.position += 500                       # a block that never came
    assert audio.read_blocks(0)[0].flags != 0


def test_the_page_measures_stores_and_shows_the_corrections(qtbot, settings):
    wizard = MeasureWizard(settings.qsettings, rig_name="linpar-not-running-in-tests")
    qtbot.addWidget(wizard)
    to_hardware(wizard)
    choose_simulator(wizard, realtime=False)
    wizard.next_button.click()
    page = wizard.calibration_page
    assert "Measure the reference resistor" in wizard.reason.text()
    assert page.resistor.value() == 4.0                 # suggested by the nominal impedance
    run_job(qtbot, page.measure_button, page.jobs)
    assert "Computed and stored" in plain(page.result)
    assert "current gain ×1.0000" in plain(page.stored_label)
    stored = Corrections.from_dict(__import__("json").loads(settings.qsettings.value(settings_key("simulator"))))
    assert stored.source == "resistor" and stored.resistor_ohm == 4.0
    assert wizard.next_button.isEnabled()
    wizard.next_button.click()
    assert wizard.state.corrections == stored
    # A second wizard finds them stored: Next at once.
    second = MeasureWizard(settings.qsettings, rig_name="linpar-not-running-in-tests")
    qtbot.addWidget(second)
    to_hardware(second)
    choose_simulator(second, realtime=False)
    second.next_button.click()
    assert second.next_button.isEnabled()
    second.shutdown(5000)
    wizard.shutdown(5000)


def test_on_the_virtual_rig_no_correction_is_needed_or_measured(qtbot, settings):
    wizard = MeasureWizard(settings.qsettings, rig_name="linpar-not-running-in-tests")
    qtbot.addWidget(wizard)
    wizard.state.hardware = HardwareConfig(kind=RIG)
    wizard.go_to(2)
    page = wizard.calibration_page
    assert not page.measure_button.isEnabled()
    assert "exact by construction" in plain(page.stored_label)
    assert wizard.next_button.isEnabled()
