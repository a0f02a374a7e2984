"""The in-process rig of the fault and crash tests (and of tools/soak.py): no JACK needed.

SimulatedAudio in real time drives the paper driver on a FIR of one period;
the displacement of its cone reaches the workstation through a laser that
measures it on its own clock: SimulatedLaser (blocks, in-process), or the
byte-level LaserEmulator on a pseudo-terminal read by the real ILD1420
driver, whose ErrorPlan puts garbage, cut frames, error codes and a hang-up
on the line. One measurement of PLAN takes about a second of sound; without
a laser on its own clock (``analog``) the sound card need not keep real
time and runs as fast as it is read.
"""
from __future__ import annotations

import numpy as np

from analysis.drivers import load_driver
from instruments.audio import SimulatedAudio
from instruments.audio.config import ChannelMap
from instruments.laser import ILD1420, LaserEmulator, SimulatedLaser
from instruments.measurement import MeasurementPlan
from instruments.rig.engine import RIG_CALIBRATION, RIG_CHANNEL_MAP
from instruments.rig.laser_feed import DisplacementFeed
from instruments.simulation.linear_driver import LinearBlockDriver

PAPER = load_driver("paper")
PERIOD = 8192
SERIAL_MAP = ChannelMap(output=0, voltage=0, current=1)       # the serial laser: no analog laser input


def plan(**changes) -> MeasurementPlan:
    base = dict(period_samples=PERIOD, n_periods=4, settle_periods=2, f_min_hz=5.0,
                driver={"name": PAPER.name, "sd_m2": PAPER.sd_m2})
    return MeasurementPlan.from_template("woofer", **{**base, **changes})


class Rig:
    """A simulated sound card and, optionally, a laser on the same cone; ``close()`` releases the laser's pty."""

    def __init__(self, laser: str = "simulated", error_plan=None, ppm: float = 25.0, seed: int = 2,
                 realtime: bool | None = None):
        self.feed = DisplacementFeed(48000, settle_s=0.2)
        driver = LinearBlockDriver(PAPER.model(), dict(PAPER.parameters), 48000, fir_length=PERIOD)
        self.audio = SimulatedAudio(calibration=RIG_CALIBRATION,
                                    channel_map=RIG_CHANNEL_MAP if laser == "analog" else SERIAL_MAP,
                                    driver=driver, realtime=laser != "analog" if realtime is None else realtime,
                                    blocksize=2048, seed=seed,
                                    displacement_sinks=[self.feed.sink])
        self.kind = laser
        self.emulator: LaserEmulator | None = None
        self.laser = None
        self.ppm, self.error_plan = ppm, error_plan
        self.new_laser(error_plan)

    def new_laser(self, error_plan=None):
        """A fresh laser (after a hang-up the old one is gone for good): what is plugged in from now on."""
        self.close()
        if self.kind == "simulated":
            self.laser = SimulatedLaser(clock_ppm=self.ppm, error_plan=error_plan)
            model = self.laser.model
        elif self.kind == "serial":
            self.emulator = LaserEmulator(clock_ppm=self.ppm, error_plan=error_plan).start()
            self.laser = ILD1420(self.emulator.port_path)
            model = self.emulator.model
        else:
            self.laser = None
            return None
        feed = self.feed
        model.displacement = lambda t: -feed.at_host_times(model.t0 + np.asarray(t))    # the cone's front
        return self.laser

    def close(self) -> None:
        if self.laser is not None and hasattr(self.laser, "close"):
            try:
                self.laser.close()
            except Exception:       # noqa: BLE001 - a laser already gone
                pass
        if self.emulator is not None:
            self.emulator.close()
            self.emulator = None
