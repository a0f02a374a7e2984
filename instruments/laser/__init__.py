"""The laser displacement sensor: the optoNCDT ILD1420 on its serial link,
its emulator on a pseudo-terminal, an in-process simulation, and the scale
for its analog output. See shared/spec/laser-ild1420.md."""

from instruments.laser.analog import AnalogLaserScale
from instruments.laser.ild1420 import DEFAULT_BAUDRATE, ILD1420
from instruments.laser.sensor import (
    DEFAULT_OUTPUTS, NO_COUNTER, DisplacementSensor, LaserBlock, LaserError, LaserStats,
    SensorInfo, concatenate_blocks)
from instruments.laser.sensor_model import ErrorPlan
from instruments.laser.simulated import SimulatedLaser
from instruments.laser.values import LaserErrorCode, describe_error

__all__ = [
    "AnalogLaserScale", "DEFAULT_BAUDRATE", "DEFAULT_OUTPUTS", "DisplacementSensor", "ErrorPlan",
    "ILD1420", "LaserBlock", "LaserEmulator", "LaserError", "LaserErrorCode", "LaserStats",
    "NO_COUNTER", "SensorInfo", "SimulatedLaser", "concatenate_blocks", "describe_error",
]


def __getattr__(name: str):
    # The pty emulator needs termios and fcntl, which Windows lacks: it is loaded when asked for, not with the package.
    if name == "LaserEmulator":
        from instruments.laser.emulator import LaserEmulator
        return LaserEmulator
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
