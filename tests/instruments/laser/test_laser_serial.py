"""The ILD1420 driver byte by byte: against the emulator on a pseudo-terminal
and on pyserial's loop:// port."""

import logging
import os
import threading
import time

import numpy as np
import pytest
from serial.urlhandler.protocol_loop import Serial as LoopSerial

from instruments.laser import LaserError, LaserSpec, concatenate_blocks, open_laser
from instruments.laser.ild1420 import DEFAULT_BAUDRATE, ErrorPlan, LaserErrorCode
from instruments.laser.ild1420.emulator import LaserEmulator
from instruments.laser.ild1420.frames import encode_measurements
from tests.pace import paced


def ild1420(port, baudrate=None, **options):
    """The driver, made as every caller makes it: through the factory."""
    return open_laser(LaserSpec("ild1420", port, baudrate, options=options))


def collect(sensor, n, timeout=10.0):
    """At least n measurements, as one block (`timeout` for an idle machine, at its pace now)."""
    blocks, total = [], 0
    deadline = time.monotonic() + paced(timeout)
    while total < n:
        assert time.monotonic() < deadline, f"only {total} of {n} measurements arrived"
        block = sensor.read_block(0.2)
        if block is not None:
            blocks.append(block)
            total += len(block)
    return concatenate_blocks(blocks)


def drain_until_lost(sensor, timeout=10.0, blocks=None):
    """(counters of ``blocks`` and of all blocks still to come, the error text)."""
    blocks = list(blocks or [])
    deadline = time.monotonic() + paced(timeout)
    with pytest.raises(LaserError, match="laser link lost") as lost:
        while True:
            assert time.monotonic() < deadline, "the lost link was never reported"
            block = sensor.read_block(0.2)
            if block is not None:
                blocks.append(block)
    counter = concatenate_blocks(blocks).counter.tolist() if blocks else []
    return counter, str(lost.value)


@pytest.fixture
def rig():
    """make(**emulator_kwargs) -> (started ILD1420, emulator); all closed after."""
    made = []

    def make(baudrate=DEFAULT_BAUDRATE, queue_blocks=1024, rate_hz=4000.0, start=True, **emulator_kwargs):
        emulator = LaserEmulator(**emulator_kwargs).start()
        sensor = ild1420(emulator.port_path, baudrate, queue_blocks=queue_blocks)
        made.append((sensor, emulator))
        if start:
            sensor.open()
            sensor.configure(rate_hz)
            sensor.start()
        return sensor, emulator

    yield make
    for sensor, emulator in reversed(made):
        sensor.close()
        emulator.close()


def expected_distance(emulator, counter):
    model = emulator.model
    return model.rest_distance_m + model.displacement(emulator.sample_times(counter))


LSB = 0.010 * 1.02 / 65520  # one step of a 10 mm sensor


def sine(t):
    return 2e-3 * np.sin(2 * np.pi * 40 * t)


# -- streaming on the pseudo-terminal ------------------------------------------
def test_open_reads_the_sensor_info(rig):
    sensor, _ = rig(start=False, measuring_range_mm=25, serial_number="42")
    info = sensor.open()
    assert (info.name, info.serial, info.measuring_range_m) == ("ILD1420-25", "42", 0.025)
    assert info.firmware and "GETINFO" in info.text


def test_streams_every_measurement_with_counter_time_stamp_and_distance(rig):
    sensor, emulator = rig(displacement=sine)
    block = collect(sensor, 800)
    assert block.counter.tolist() == list(range(len(block)))
    assert np.allclose(np.diff(block.timestamp_ms), 0.25)
    assert np.max(np.abs(block.distance_m - expected_distance(emulator, block.counter))) <= LSB / 2 + 1e-12
    assert block.in_range.all() and (block.error_code == 0).all()
    assert sensor.stats.discarded_bytes == 0 and sensor.stats.frames >= 800


def test_the_exact_ascii_commands_sent(rig):
    sensor, emulator = rig()
    sensor.stop()
    assert emulator.commands_received == [
        "GETINFO", "GETOUTINFO_RS422", "MEASRATE 4", "OUTADD_RS422 COUNTER TIMESTAMP",
        "GETOUTINFO_RS422", "RESETCNT", "OUTPUT RS422", "OUTPUT NONE"]
    assert not emulator.streaming


def test_a_command_answered_while_streaming_loses_and_corrupts_no_value(rig):
    # the reply comes 2 bytes after each measurement, spread over dozens of frames
    sensor, emulator = rig(displacement=sine, reply_bytes_per_measurement=2)
    collect(sensor, 100)
    info = sensor.command("GETINFO")
    rate = sensor.command("MEASRATE")
    assert "Name:            ILD1420-10" in info.body
    assert rate.body == ("MEASRATE 4",)
    block = collect(sensor, 1200)
    assert block.counter.tolist() == list(range(block.counter[0], block.counter[0] + len(block)))
    assert np.max(np.abs(block.distance_m - expected_distance(emulator, block.counter))) <= LSB / 2 + 1e-12
    assert sensor.stats.discarded_bytes == 0 and sensor.stats.stray_replies == 0


def test_resynchronises_after_garbage_bursts(rig):
    sensor, emulator = rig(displacement=sine, error_plan=ErrorPlan(garbage_every=25, garbage_bytes=20, seed=3))
    block = collect(sensor, 1000)
    assert block.counter.tolist() == list(range(len(block)))
    assert np.max(np.abs(block.distance_m - expected_distance(emulator, block.counter))) <= LSB / 2 + 1e-12
    assert sensor.stats.discarded_bytes > 0


def test_partial_frames_lose_only_themselves(rig):
    sensor, _ = rig(error_plan=ErrorPlan(truncate_every=100))
    block = collect(sensor, 700)
    counters = set(block.counter.tolist())
    top = int(block.counter[-1])
    cut = {k for k in range(top) if (k + 1) % 100 == 0}
    assert counters == set(range(top + 1)) - cut
    assert sensor.stats.incomplete_measurements >= len(cut)


def test_every_error_code_arrives_decoded(rig):
    codes = {10 + i: int(code) for i, code in enumerate(LaserErrorCode)}
    sensor, _ = rig(error_plan=ErrorPlan(codes_at=codes))
    block = collect(sensor, 100)
    for k, code in codes.items():
        assert block.error_code[k] == code and np.isnan(block.distance_m[k]) and not block.in_range[k]
    valid = block.error_code == 0
    assert valid.sum() == len(block) - len(codes) and np.isfinite(block.distance_m[valid]).all()
    assert dict(sensor.stats.errors_by_code) == {code: 1 for code in codes.values()}


def test_a_share_of_no_peak_errors_is_counted(rig):
    sensor, _ = rig(error_plan=ErrorPlan(error_share=0.2, seed=1))
    first = collect(sensor, 1000)
    # The stream goes on while the test looks (a loaded host let the reader count 2634 errors against the 194
    # of the block taken): stopped, the counters are compared with every block the driver handed out.
    sensor.stop()
    block = concatenate_blocks([first, *iter(lambda: sensor.read_block(0.1), None)])
    assert sensor.stats.queue_overflows == 0 and block.counter.tolist() == list(range(len(block)))
    share = np.mean(block.error_code == LaserErrorCode.NO_PEAK)
    assert 0.15 < share < 0.25
    assert sensor.stats.errors_by_code[LaserErrorCode.NO_PEAK] == np.count_nonzero(block.error_code)


def test_counter_wraps_at_18_bits_and_stays_monotonic(rig):
    sensor, _ = rig(counter_start=262_100)
    block = collect(sensor, 200)
    assert block.counter.tolist() == list(range(262_100, 262_100 + len(block)))
    assert block.counter[-1] > 262_143  # it went through the wrap


def test_reserves_and_out_of_range_codes(rig):
    # a ramp from 0.3 mm before the range to 0.3 mm beyond it (10 mm sensor)
    ramp = lambda t: -0.0003 + t * (0.0106 / 0.25)  # noqa: E731
    sensor, _ = rig(displacement=ramp, rest_distance_m=0.0)
    first = collect(sensor, 1001)
    sensor.stop()           # the counters against every block handed out, not one the stream has gone past
    block = concatenate_blocks([first, *iter(lambda: sensor.read_block(0.1), None)])
    d_true = ramp(block.counter / 4000.0)
    before = block.error_code == LaserErrorCode.PEAK_BEFORE_RANGE
    after = block.error_code == LaserErrorCode.PEAK_AFTER_RANGE
    reserve = (block.error_code == 0) & ~block.in_range
    assert before.any() and after.any() and reserve.any()
    assert (d_true[before] < -0.0001 + LSB).all() and (d_true[after] > 0.0101 - LSB).all()
    assert set(np.sign(block.distance_m[reserve] - 0.005)) == {-1.0, 1.0}  # reserves at both ends
    inside = (d_true > LSB) & (d_true < 0.010 - LSB)
    outside = (d_true < -LSB) | (d_true > 0.010 + LSB)
    assert block.in_range[inside].all() and not block.in_range[outside].any()
    assert sensor.stats.reserve_frames == reserve.sum()


def test_time_stamps_count_the_sensor_clock_not_the_host_clock(rig):
    sensor, emulator = rig(clock_ppm=500.0, rate_hz=1000.0)
    block = collect(sensor, 50)
    assert np.allclose(np.diff(block.timestamp_ms), 1.0)
    assert emulator.model.host_rate_hz == pytest.approx(1000.5)


def test_bandwidth_too_low_is_refused_naming_the_numbers(rig):
    sensor, emulator = rig(baudrate=115_200, start=False)
    sensor.open()
    with pytest.raises(LaserError, match=r"115\.2 kBd .* 4 kHz .* 4 values .* 528 kBd"):
        sensor.configure(4000.0)
    assert not any(c.startswith("MEASRATE") for c in emulator.commands_received)
    sensor.configure(1000.0, outputs=("distance",))  # 33 kBd needed: fine


def test_a_rate_the_sensor_does_not_offer_is_refused(rig):
    sensor, _ = rig(start=False)
    sensor.open()
    with pytest.raises(LaserError, match="3000 Hz.*250, 500, 1000, 2000, 4000"):
        sensor.configure(3000.0)


def test_an_exxx_reply_raises_and_a_warning_is_logged(rig, caplog):
    sensor, _ = rig(start=False, warnings={"MEASRATE": "W101 rate changes the exposure"})
    sensor.open()
    with pytest.raises(LaserError, match="E200 Unknown command"):
        sensor.command("FROB 1")
    with caplog.at_level(logging.WARNING, logger="instruments.laser.ild1420"):
        sensor.configure(2000.0)
    assert "W101 rate changes the exposure" in caplog.text


def test_distance_only_has_no_counter_nor_time_stamp(rig):
    sensor, emulator = rig(start=False)
    sensor.open()
    sensor.configure(4000.0, outputs=("distance",))
    sensor.start()
    block = collect(sensor, 100)
    assert (block.counter == -1).all() and np.isnan(block.timestamp_ms).all()
    assert emulator.commands_received[3] == "OUTADD_RS422 NONE"


def test_a_full_queue_drops_the_oldest_blocks_and_counts_them(rig):
    sensor, emulator = rig(queue_blocks=3)
    deadline = time.monotonic() + paced(10)
    while sensor.stats.queue_overflows < 5:
        assert time.monotonic() < deadline
        time.sleep(0.01)  # let the reader fill the queue: nothing to wait on but the stream
    sensor.stop()
    kept = [b for b in iter(lambda: sensor.read_block(0.1), None)]
    assert len(kept) <= 3
    assert kept[-1].counter[-1] == sensor.stats.frames - 1  # the newest survived


def test_link_lost_mid_stream_reports_after_draining_what_was_received(rig):
    sensor, emulator = rig(error_plan=ErrorPlan(disconnect_after=700))
    counter, message = drain_until_lost(sensor)
    # every measurement the driver parsed is handed out, in order, before the
    # error; bytes still inside the pty when it hung up may be gone, as on a
    # pulled cable, so the count can fall short of 700 but never have holes
    assert counter == list(range(sensor.stats.frames))
    assert len(counter) <= 700 and emulator.samples_sent == 700
    assert len(message) > len("laser link lost: ")  # says why
    with pytest.raises(LaserError, match="laser link lost"):
        sensor.command("GETINFO")


def test_disconnect_by_hand_mid_stream(rig):
    sensor, emulator = rig()
    first = collect(sensor, 100)
    emulator.disconnect()
    counter, _ = drain_until_lost(sensor, blocks=[first])
    assert counter == list(range(sensor.stats.frames))
    assert 100 <= len(counter) <= emulator.samples_sent


def test_nothing_on_the_port_is_a_clear_error():
    with pytest.raises(LaserError, match="cannot open the laser port /nonexistent/ttyLASER"):
        ild1420("/nonexistent/ttyLASER").open()


def test_a_silent_port_is_a_clear_error():
    master, slave = os.openpty()
    try:
        sensor = ild1420(os.ttyname(slave), reply_timeout_s=0.2)
        with pytest.raises(LaserError, match="no ILD1420 answering .* no reply to 'GETINFO'"):
            sensor.open()
        sensor.close()
    finally:
        os.close(master)
        os.close(slave)


def test_close_leaves_no_thread_and_no_file_descriptor():
    threads = threading.active_count()
    fds = len(os.listdir("/proc/self/fd"))
    with LaserEmulator(displacement=sine) as emulator:
        sensor = ild1420(emulator.port_path)
        sensor.open()
        sensor.configure(4000.0)
        sensor.start()
        collect(sensor, 100)
        assert threading.active_count() == threads + 2
        sensor.close()
        sensor.close()  # twice is fine
        with pytest.raises(LaserError, match="not open"):
            sensor.read_block(0.01)
    assert threading.active_count() == threads
    assert len(os.listdir("/proc/self/fd")) == fds


# -- loop:// ------------------------------------------------------------------
class AnsweringLoop(LoopSerial):
    """pyserial's loop:// answering like the sensor: the loop itself echoes
    the command; this adds the reply's lines and the prompt. ``inject`` puts
    sensor output on the line, one measurement at a time, so that a reply
    lands between values as with a real sensor."""

    ANSWERS = {"GETINFO": "Name: ILD1420-50\r\nSerial: 7\r\nVersion: 1.0\r\n",
               "GETOUTINFO_RS422": "DISTANCE COUNTER TIMESTAMP\r\n"}

    def __init__(self):
        super().__init__("loop://", baudrate=DEFAULT_BAUDRATE, timeout=0.02)
        self.line = threading.Lock()

    def write(self, data):
        with self.line:
            written = super().write(data)
            command = bytes(data).decode().strip()
            super().write(f"{self.ANSWERS.get(command, '')}->".encode())
        return written

    def inject(self, data):
        with self.line:
            super().write(data)


def test_loop_port_byte_by_byte_with_garbage_and_a_command_in_between():
    port = AnsweringLoop()
    sensor = ild1420(port)  # the port is handed in, and over: close() closes it
    try:
        assert sensor.open().measuring_range_m == 0.05
        sensor.start()
        k = np.arange(500)
        words = np.stack([1000 + k, k, (25 * k) & 0xFFFF, (25 * k) >> 16], axis=1)
        frames = encode_measurements(words)

        def feed_line():
            for i, frame in enumerate(frames):
                port.inject(frame.tobytes())
                if i % 50 == 7:
                    port.inject(bytes([0x9A, 0xC3, 0xFF]))  # H-class garbage

        feeder = threading.Thread(target=feed_line)
        feeder.start()
        reply = sensor.command("GETOUTINFO_RS422")
        feeder.join()
        block = collect(sensor, 500)
        assert reply.body == ("DISTANCE COUNTER TIMESTAMP",)
        assert block.counter.tolist() == k.tolist()
        assert np.allclose(block.timestamp_ms, k * 0.25)
        assert np.allclose(block.distance_m, ((1000 + k) * 1.02 / 65520 - 0.01) * 0.05)
        assert sensor.stats.discarded_bytes == 30
    finally:
        sensor.close()
    assert not port.is_open


def test_loop_port_that_goes_away_ends_the_stream_cleanly():
    port = AnsweringLoop()
    sensor = ild1420(port)
    try:
        sensor.open()
        sensor.start()
        port.inject(encode_measurements(np.stack([np.full(10, 2000), np.arange(10), np.zeros(10), np.zeros(10)], 1)
                                        .astype(np.int64)).tobytes())
        assert collect(sensor, 10).counter.tolist() == list(range(10))
        port.is_open = False  # what a pulled USB converter looks like to pyserial
        port.cancel_read()
        with pytest.raises(LaserError, match="laser link lost"):
            sensor.read_block(1.0)
    finally:
        sensor.close()
