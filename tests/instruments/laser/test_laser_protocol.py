"""One test suite for the DisplacementSensor protocol, run against the real
ILD1420 driver (on the emulator's pseudo-terminal) and SimulatedLaser."""

import os
import threading
import time
from dataclasses import FrozenInstanceError

import numpy as np
import pytest

from instruments.laser import (
    NO_COUNTER, DisplacementSensor, LaserBlock, LaserError, LaserSpec, concatenate_blocks, open_laser)
from instruments.laser.ild1420 import ErrorPlan, LaserErrorCode
from instruments.laser.ild1420.emulator import LaserEmulator
from tests.pace import paced

LSB = 0.010 * 1.02 / 65520


def sine(t):
    return 1.5e-3 * np.sin(2 * np.pi * 60 * t)


class Rig:
    """Makes one kind of sensor with given physics; knows its model and how
    to pull its cable; closes everything it made."""

    def __init__(self, kind):
        self.kind = kind
        self.sensor = self.model = None
        self._emulator = None

    def make(self, baudrate=921_600, connected=True, **physics):
        if self.kind == "simulated":
            self.sensor = open_laser(LaserSpec("ild1420", "sim://bench", baudrate, simulated=True,
                                               options=dict(connected=connected, **physics)))
            self.model = self.sensor.model
        elif connected:
            self._emulator = LaserEmulator(**physics).start()
            self.sensor = open_laser(LaserSpec("ild1420", self._emulator.port_path, baudrate))
            self.model = self._emulator.model
        else:
            self._silent = os.openpty()
            self.sensor = open_laser(LaserSpec("ild1420", os.ttyname(self._silent[1]), baudrate,
                                               options={"reply_timeout_s": 0.2}))
        return self.sensor

    def pull_cable(self):
        (self._emulator or self.sensor).disconnect()

    def close(self):
        if self.sensor is not None:
            self.sensor.close()
        if self._emulator is not None:
            self._emulator.close()
        for fd in getattr(self, "_silent", ()):
            os.close(fd)


@pytest.fixture(params=["ild1420", "simulated"])
def rig(request):
    rig = Rig(request.param)
    yield rig
    rig.close()


def collect(sensor, n, timeout=10.0):
    blocks, total = [], 0
    deadline = time.monotonic() + paced(timeout)      # written for an idle machine
    while total < n:
        assert time.monotonic() < deadline, f"only {total} of {n} measurements arrived"
        block = sensor.read_block(0.2)
        if block is not None:
            blocks.append(block)
            total += len(block)
    return concatenate_blocks(blocks)


def streaming(rig, rate_hz=4000.0, outputs=("distance", "counter", "timestamp"), **physics):
    sensor = rig.make(**physics)
    sensor.open()
    sensor.configure(rate_hz, outputs)
    sensor.start()
    return sensor


def test_is_a_displacement_sensor(rig):
    assert isinstance(rig.make(), DisplacementSensor)


def test_open_identifies_the_sensor(rig):
    info = rig.make(measuring_range_mm=50).open()
    assert info.name.startswith("ILD1420-50")
    assert info.measuring_range_m == 0.05


def test_blocks_carry_the_displacement_sample_by_sample(rig):
    sensor = streaming(rig, displacement=sine)
    before = time.monotonic()
    block = collect(sensor, 600)
    assert isinstance(block, LaserBlock)
    assert block.counter.dtype == np.int64 and block.timestamp_ms.dtype == np.float64
    assert block.distance_m.dtype == np.float64 and block.error_code.dtype == np.int32
    assert block.in_range.dtype == bool
    assert block.counter.tolist() == list(range(len(block)))
    assert np.allclose(np.diff(block.timestamp_ms), 0.25)
    expected = rig.model.rest_distance_m + sine(rig.model.sample_times(block.counter))
    assert np.max(np.abs(block.distance_m - expected)) <= LSB / 2 + 1e-12
    assert rig.model.t0 < block.host_time <= time.monotonic() and block.host_time > before - paced(1.0)
    assert sensor.stats.frames >= 600 and not sensor.stats.errors_by_code


def test_blocks_are_immutable(rig):
    block = collect(streaming(rig), 10)
    with pytest.raises(FrozenInstanceError):
        block.host_time = 0.0
    with pytest.raises(ValueError):
        block.distance_m[0] = 1.0


def test_the_rate_sets_the_sample_spacing(rig):
    sensor = streaming(rig, rate_hz=1000.0)
    block = collect(sensor, 50)
    assert np.allclose(np.diff(block.timestamp_ms), 1.0)


def test_distance_alone_leaves_counter_and_time_stamp_empty(rig):
    block = collect(streaming(rig, outputs=("distance",)), 50)
    assert (block.counter == NO_COUNTER).all() and np.isnan(block.timestamp_ms).all()
    assert np.isfinite(block.distance_m).all()


def test_error_codes_are_not_distances(rig):
    codes = {5: LaserErrorCode.NO_PEAK, 6: LaserErrorCode.LASER_OFF, 9: LaserErrorCode.NO_PEAK}
    sensor = streaming(rig, error_plan=ErrorPlan(codes_at=codes))
    block = collect(sensor, 20)
    assert np.flatnonzero(block.error_code).tolist() == [5, 6, 9]
    assert np.isnan(block.distance_m[[5, 6, 9]]).all() and not block.in_range[[5, 6, 9]].any()
    assert dict(sensor.stats.errors_by_code) == {262076: 2, 262082: 1}


def test_counter_runs_on_through_the_wrap(rig):
    block = collect(streaming(rig, counter_start=262_000), 300)
    assert block.counter.tolist() == list(range(262_000, 262_000 + len(block)))


def test_a_rate_it_cannot_do_is_refused(rig):
    sensor = rig.make()
    sensor.open()
    with pytest.raises(LaserError, match="cannot measure at 8000 Hz"):
        sensor.configure(8000.0)


def test_a_baud_rate_too_low_for_the_data_is_refused(rig):
    sensor = rig.make(baudrate=230_400)
    sensor.open()
    with pytest.raises(LaserError, match=r"230\.4 kBd .* 264 kBd"):
        sensor.configure(2000.0)
    sensor.configure(2000.0, outputs=("distance", "counter"))  # 132 kBd is enough


def test_not_connected_is_a_clear_error(rig):
    with pytest.raises(LaserError, match="no ILD1420 answering"):
        rig.make(connected=False).open()


def test_link_lost_gives_what_was_measured_then_an_error(rig):
    sensor = streaming(rig, error_plan=ErrorPlan(disconnect_after=400))
    blocks = []
    with pytest.raises(LaserError, match="laser link lost"):
        for _ in range(200):
            block = sensor.read_block(0.2)
            if block is not None:
                blocks.append(block)
    counter = concatenate_blocks(blocks).counter.tolist() if blocks else []
    # no holes and nothing held back; a pty may swallow what was in flight
    # when it hung up (as a pulled cable does), the simulation loses nothing
    assert counter == list(range(sensor.stats.frames))
    assert len(counter) <= 400
    if rig.kind == "simulated":
        assert len(counter) == 400


def test_pulling_the_cable_mid_stream(rig):
    sensor = streaming(rig)
    collect(sensor, 40)
    rig.pull_cable()
    with pytest.raises(LaserError, match="laser link lost"):
        for _ in range(200):
            sensor.read_block(0.2)


def test_stop_ends_the_stream_and_close_ends_the_sensor(rig):
    threads = threading.active_count()
    sensor = streaming(rig)
    collect(sensor, 40)
    sensor.stop()
    while sensor.read_block(0.1) is not None:  # what was on its way
        pass
    assert sensor.read_block(0.05) is None
    sensor.close()
    sensor.close()
    with pytest.raises(LaserError, match="not open"):
        sensor.read_block(0.01)
    rig.close()
    rig.sensor = None
    assert threading.active_count() == threads
