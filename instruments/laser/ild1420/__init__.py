"""The optoNCDT ILD1420: its serial driver (driver.py), byte stream
(frames.py), ASCII commands (commands.py), 18-bit values (values.py), the
physics of a virtual one (sensor_model.py) and its emulator on a
pseudo-terminal (emulator.py, POSIX only: imported by the virtual rig and the
tests, never from here). See docs/laser-protocol.md.

``MODEL`` is what the factory (instruments/laser/factory.py) finds: importing
this package loads neither pyserial nor the emulator.
"""
from __future__ import annotations

from instruments.laser.ild1420 import commands
from instruments.laser.ild1420.frames import value_slots
from instruments.laser.ild1420.sensor_model import ErrorPlan, SensorModel
from instruments.laser.ild1420.values import LaserErrorCode, describe_error
from instruments.laser.model import LaserModel

DEFAULT_BAUDRATE = commands.DEFAULT_BAUDRATE


def _driver(port, baudrate: int, **options):
    from instruments.laser.ild1420.driver import ILD1420      # pyserial, loaded when a real sensor is made
    return ILD1420(port, baudrate, **options)


MODEL = LaserModel(
    name="ild1420", family="ILD1420", default_baudrate=DEFAULT_BAUDRATE, rates_hz=commands.RATES_HZ,
    check_configuration=commands.check_configuration, layout=value_slots,
    make_driver=_driver, make_physics=SensorModel)

__all__ = ["DEFAULT_BAUDRATE", "ErrorPlan", "LaserErrorCode", "MODEL", "describe_error"]
