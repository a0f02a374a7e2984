"""Lasers by specification: open_laser makes every sensor, a new model is
found without touching the factory, and knowing the models loads nothing
POSIX-only (the pty emulator stays with the rig)."""

import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from instruments.laser import (
    DisplacementSensor, LaserBlock, LaserError, LaserModel, LaserSpec, concatenate_blocks, factory, laser_models,
    open_laser)
from instruments.laser.factory import register_laser_model
from tests.pace import paced

ROOT = Path(__file__).resolve().parents[3]


class ToyPhysics:
    """A sensor without bytes: the simplest physics a SimulatedLaser can run on."""

    measuring_range_m = 0.002
    disconnect_after = None

    def __init__(self, rate_hz: float = 1000.0, **_):
        self.rate_hz = rate_hz
        self.t0 = None

    def begin(self, t0):
        self.t0 = t0

    def reset_counter(self):
        pass

    def due(self, now):
        return 0 if self.t0 is None or now < self.t0 else int((now - self.t0) * self.rate_hz) + 1

    def arrival_time(self, k):
        return self.t0 + k / self.rate_hz

    def decoded_block(self, k0, k1, layout, host_time):
        n = k1 - k0
        return LaserBlock(np.arange(k0, k1), np.full(n, np.nan), np.full(n, 1e-3), np.zeros(n, np.int32),
                          np.ones(n, bool), host_time)


def toy_check(baudrate, rate_hz, outputs):
    if rate_hz != 1000.0:
        raise LaserError(f"the toy measures at 1000 Hz only, not {rate_hz:g}")


class ToyDriver:
    def __init__(self, port, baudrate, **options):
        self.port, self.baudrate, self.options = port, baudrate, options


TOY = LaserModel(name="toy", family="TOY", default_baudrate=115200, rates_hz=(1000.0,),
                 check_configuration=toy_check, layout=tuple, make_driver=ToyDriver, make_physics=ToyPhysics)


@pytest.fixture
def toy_model(monkeypatch):
    monkeypatch.setattr(factory, "_models", dict(laser_models()))   # the registration ends with the test
    register_laser_model(TOY)
    return TOY


def test_the_ild1420_is_found_in_its_subpackage():
    assert laser_models()["ild1420"].family == "ILD1420"


def test_a_new_model_is_one_registration_away_real_and_simulated(toy_model):
    real = open_laser(LaserSpec("toy", "COM3", options={"queue_blocks": 8}))
    assert (real.port, real.baudrate, real.options) == ("COM3", 115200, {"queue_blocks": 8})

    sensor = open_laser(LaserSpec("toy", simulated=True))
    assert isinstance(sensor, DisplacementSensor)
    assert sensor.open().name == "TOY-2 (simulated)"
    with pytest.raises(LaserError, match="1000 Hz only"):
        sensor.configure(4000.0)
    sensor.configure(1000.0)
    sensor.start()
    blocks, deadline = [], time.monotonic() + paced(10.0)
    while sum(map(len, blocks)) < 20 and time.monotonic() < deadline:
        block = sensor.read_block(0.1)
        if block is not None:
            blocks.append(block)
    sensor.close()
    counter = concatenate_blocks(blocks).counter
    assert len(counter) >= 20 and np.array_equal(counter, np.arange(len(counter)))


def test_an_unknown_model_and_a_missing_port_say_what_to_do():
    with pytest.raises(LaserError, match="unknown laser model 'ild9999'; known: .*ild1420"):
        open_laser(LaserSpec("ild9999", "/dev/ttyUSB0"))
    with pytest.raises(LaserError, match="give the laser's serial port"):
        open_laser(LaserSpec("ild1420"))


def test_knowing_the_models_loads_nothing_posix_only_nor_pyserial():
    """Issue 22: the GUI must import on Windows, where pty, termios and fcntl do not exist."""
    code = ("import sys, instruments.laser as laser\n"
            "laser.laser_models()\n"
            "laser.open_laser(laser.LaserSpec(simulated=True)).open()\n"
            "bad = sorted(m for m in ('pty', 'tty', 'termios', 'fcntl', 'serial') if m in sys.modules)\n"
            "print(bad); sys.exit(1 if bad else 0)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=paced(60), cwd=ROOT)
    assert done.returncode == 0, done.stdout + done.stderr


def test_nothing_outside_the_factory_makes_a_driver_by_class_name():
    callers = [path.relative_to(ROOT) for folder in ("app", "instruments", "tools", "bench")
               for path in (ROOT / folder).rglob("*.py")
               if "ILD1420(" in path.read_text(encoding="utf-8") and "laser/ild1420" not in path.as_posix()]
    assert callers == []
