"""RigEngine: the rig's analog chain without JACK (scales, faults, noise, displacement sinks)."""
from __future__ import annotations

import numpy as np
import pytest

from instruments.rig.engine import RIG_CALIBRATION, RigEngine, RigFaults, RigNoise, default_driver
from instruments.simulation import DriverBlock


class Resistor:
    """A BlockDriver that is a plain resistor with the cone following the current: easy to check."""

    sample_rate = 48000

    def __init__(self, ohm=4.0, metres_per_amp=1e-3):
        self.ohm, self.metres_per_amp = ohm, metres_per_amp

    def process(self, voltage):
        u = np.asarray(voltage, dtype=float)
        return DriverBlock(u, u / self.ohm, u / self.ohm * self.metres_per_amp)

    def reset(self):
        pass


QUIET = RigNoise(0.0, 0.0, 0.0)


def test_outputs_are_the_driver_signals_in_full_scale_units():
    engine = RigEngine(Resistor(), noise=QUIET)
    played = np.array([0.0, 0.1, -0.2], dtype=np.float32)       # 1 FS = 10 V at the terminals
    out = engine.process(played, 0)
    volts = played.astype(float) * 10.0
    assert np.allclose(out.voltage, volts / 20.0)                              # 20 V per FS
    assert np.allclose(out.current, volts / 4.0 / RIG_CALIBRATION.amperes_per_fs)
    assert np.allclose(out.displacement, volts / 4.0 * 1e-3 / RIG_CALIBRATION.metres_per_fs)
    assert out.voltage.dtype == np.float32


def test_faults_disconnect_clip_and_add_noise():
    engine = RigEngine(Resistor(), noise=RigNoise(voltage=1e-3, current=0.0, displacement=0.0), seed=0)
    engine.faults = RigFaults.parse(["disconnect=current", "clip=2"])
    played = np.full(48000, 0.5, dtype=np.float32)                           # 5 V asked, 2 V allowed
    out = engine.process(played, 0)
    assert not out.current.any()
    assert np.mean(out.voltage) * 20.0 == pytest.approx(2.0, rel=1e-3)
    assert np.std(out.voltage) * 20.0 == pytest.approx(1e-3, rel=0.05)
    engine.faults = RigFaults(noise_factor=10.0)
    assert np.std(engine.process(played, 0).voltage) * 20.0 == pytest.approx(1e-2, rel=0.05)


def test_inputs_clip_at_full_scale_like_an_adc():
    out = RigEngine(Resistor(ohm=0.5), noise=QUIET).process(np.full(8, 0.9, dtype=np.float32), 0)
    assert np.max(out.current) == 1.0          # 18 A would be 9 FS


def test_displacement_sinks_get_every_block_with_its_frame_counter():
    got = []

    def broken(block, frame):
        raise RuntimeError("a sink with a bug")

    engine = RigEngine(Resistor(), noise=QUIET, displacement_sinks=[lambda b, f: got.append((f, b.copy())), broken])
    for frame in (0, 1024, 2048):
        engine.process(np.full(1024, 0.1, dtype=np.float32), frame)
    assert [f for f, _ in got] == [0, 1024, 2048]
    assert got[0][1] == pytest.approx(np.full(1024, 0.25e-3))      # 1 V / 4 ohm * 1 mm/A, in metres
    assert engine.sink_errors == 3 and engine.blocks == 3


def test_default_driver_takes_the_effects_override_and_refuses_unknown_parameters():
    driver, definition = default_driver("paper", 48000, "lr2,creep-log-causal")
    assert driver.model.effect_ids == ("lr2", "creep-log-causal") and definition.sd_m2 == 0.0133
    with pytest.raises(ValueError, match="no value for"):
        default_driver("paper", 48000, "lr2,creep-3p")
