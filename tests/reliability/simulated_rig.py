"""The in-process rig of the fault and crash tests: no JACK needed (instruments/rig/in_process.py).

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

from analysis.drivers import load_driver
from instruments.measurement import MeasurementPlan
from instruments.rig.in_process import InProcessRig
from instruments.simulation.linear_driver import LinearBlockDriver

PAPER = load_driver("paper")
PERIOD = 8192


def plan(**changes) -> MeasurementPlan:
    base = dict(period_samples=PERIOD, n_periods=4, settle_periods=2, f_min_hz=5.0,
                driver={"name": PAPER.name, "sd_m2": PAPER.sd_m2})
    return MeasurementPlan.from_template("woofer", **{**base, **changes})


class Rig(InProcessRig):
    """The paper driver on a FIR of one period, behind the in-process rig."""

    def __init__(self, laser: str = "simulated", error_plan=None, ppm: float = 25.0, seed: int = 2,
                 realtime: bool | None = None):
        driver = LinearBlockDriver(PAPER.model(), dict(PAPER.parameters), 48000, fir_length=PERIOD)
        super().__init__(driver, laser, ppm=ppm, error_plan=error_plan, seed=seed, realtime=realtime)
