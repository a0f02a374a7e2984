"""level_check: the rules on made-up probes, then the real thing on the nonlinear simulated driver."""
import math

import numpy as np
import pytest

from analysis.level_check import LevelProbe, level_check
from analysis.recording.format import make_recording
from analysis.validity.assessment import assess
from instruments.simulation.faults import BENCH_NOISE, PAPER
from instruments.simulation.nonlinear_driver import NonlinearBlockDriver
from tests.builders import multitone


def fake(snr_at_1v=60.0, distortion_from=math.inf, x_per_volt=1e-3):
    """A linear system: SNR grows 20 dB/decade; distortion jumps to 12 dB above `distortion_from` volts."""
    def measure_at(level):
        return LevelProbe(level, snr_at_1v + 20 * math.log10(level), "current",
                          12.0 if level > distortion_from else 0.5, "current", x_per_volt * level)
    return measure_at


def test_it_stops_as_soon_as_the_snr_is_enough():
    decision = level_check(fake(), 0.01, 10.0)
    assert decision.reason_code == "snr-reached"
    assert decision.chosen.snr_db >= 40.0 and decision.probes[-2].snr_db < 40.0
    assert [p.level for p in decision.probes] == pytest.approx([0.01 * 1.6**k for k in range(len(decision.probes))])


def test_it_never_passes_the_excursion_limit_and_says_so():
    decision = level_check(fake(snr_at_1v=0.0), 0.01, 10.0, x_limit_m=0.5e-3)
    assert decision.reason_code == "excursion"
    assert all(p.peak_displacement_m <= 0.5e-3 for p in decision.probes)
    assert decision.level == pytest.approx(0.475, rel=1e-6)          # 0.95 of the limit, predicted
    assert "limit" in decision.reason


def test_distortion_sends_it_back_to_the_last_clean_level():
    decision = level_check(fake(snr_at_1v=0.0, distortion_from=0.2), 0.01, 10.0, x_limit_m=1.0)
    assert decision.reason_code == "distortion"
    assert decision.probes[-1].distortion_db >= 6.0
    assert decision.level == decision.probes[-2].level < 0.2
    assert "noise + distortion" in decision.reason


def test_at_the_maximum_voltage_it_measures_there_once():
    decision = level_check(fake(snr_at_1v=10.0), 0.1, 1.0, x_limit_m=1.0)
    assert decision.reason_code == "max-voltage"
    assert decision.level == 1.0 and decision.probes[-1].level == 1.0 and decision.probes[-2].level < 1.0


def test_too_loud_already_at_the_minimum():
    decision = level_check(fake(x_per_volt=1.0), 0.01, 1.0)
    assert decision.level is None and decision.reason_code == "too-loud-at-min"
    assert decision.chosen is None and "lower v_min" in decision.reason


def test_bad_arguments():
    with pytest.raises(ValueError):
        level_check(fake(), 1.0, 0.5)
    with pytest.raises(ValueError):
        level_check(fake(), 0.1, 1.0, step=1.0)


# --- on the nonlinear simulated driver ------------------------------------------------------------

MT = multitone(period_samples=8192)
SETTLE, AVERAGED = 2, 4


def _nonlinear_recording(level):
    driver = NonlinearBlockDriver(PAPER.parameters, MT.sample_rate, fir_length=MT.period_samples)
    block = driver.process(MT.scaled(rms=level).tile(SETTLE + AVERAGED))
    rng = np.random.default_rng(round(level * 1e6))
    signals = {name: getattr(block, name) + rng.normal(0, getattr(BENCH_NOISE, name), len(block))
               for name in ("voltage", "current", "displacement")}
    return make_recording(MT.sample_rate, signals, MT.period_samples, SETTLE,
                          tuple(int(b) for b in MT.excited_bins))


def _measure_at(level):
    return LevelProbe.from_recording(level, _nonlinear_recording(level))


def test_on_the_nonlinear_driver_it_stops_below_its_distortion_limit():
    decision = level_check(_measure_at, 0.02, 20.0, snr_target_db=200.0)   # never enough: push to the limit
    assert decision.reason_code == "distortion", decision.reason
    assert decision.chosen.distortion_db < 6.0
    assert decision.chosen.peak_displacement_m < 0.5e-3           # distortion, not excursion, limited it
    # Measured again at the chosen level: no channel shows distortion ...
    again = assess(_nonlinear_recording(decision.level))
    assert not any(f.code == "distortion-high" for f in again.findings), again.as_json()
    # ... and one ordinary step above it the driver's distortion stands above the noise: the limit is close.
    above = _measure_at(decision.level * 1.6)
    assert above.distortion_db >= 6.0 and above.distortion_channel in ("current", "displacement")


def test_on_the_nonlinear_driver_defaults_stop_once_the_snr_is_enough():
    decision = level_check(_measure_at, 1e-3, 20.0)
    assert decision.reason_code == "snr-reached", decision.reason
    assert decision.chosen.snr_db >= 40.0
    assert str(decision.chosen.validity.overall) == "green"
