"""The laser displacement sensor, whatever its model: the protocol every
sensor keeps (sensor.py), the factory that makes one from a LaserSpec
(factory.py), the in-process simulation (simulated.py) and the scale of an
analog output read by the sound card (analog.py). Each model lives in a
subpackage of its own (ild1420/); importing this package loads none of
their drivers or emulators, so it imports on every system.
"""

from instruments.laser.analog import AnalogLaserScale
from instruments.laser.factory import DEFAULT_MODEL, LaserSpec, laser_model, laser_models, open_laser
from instruments.laser.model import LaserModel
from instruments.laser.sensor import (
    DEFAULT_OUTPUTS, NO_COUNTER, DisplacementSensor, LaserBlock, LaserError, LaserStats, SensorInfo,
    concatenate_blocks)

__all__ = [
    "AnalogLaserScale", "DEFAULT_MODEL", "DEFAULT_OUTPUTS", "DisplacementSensor", "LaserBlock", "LaserError",
    "LaserModel", "LaserSpec", "LaserStats", "NO_COUNTER", "SensorInfo", "concatenate_blocks", "laser_model",
    "laser_models", "open_laser",
]

