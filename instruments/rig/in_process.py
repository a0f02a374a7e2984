"""The virtual rig in this process, without JACK: a simulated sound card and a laser on the same cone.

SimulatedAudio in real time drives a BlockDriver; the displacement of its
cone reaches the workstation either through the card's analog laser input
(``laser="analog"``), or through a laser that measures it on a clock of its
own: SimulatedLaser (blocks, in-process: ``"simulated"``) or the byte-level
LaserEmulator on a pseudo-terminal read by the real ILD1420 driver
(``"serial"``). The laser measures through a DisplacementFeed that runs on
the card's own FrameClock (frame_clock.py), so where each laser sample sits
among the audio frames is the emulation's choice, not a thread's wake-up:

    laser sample k  <->  audio frame  offset + ratio * k,
    offset = the card's frame at (switch-on + start latency),  ratio = fs / (rate * (1 + ppm 1e-6)),

and ``truth()`` says what the workstation should find. Used by the fault and
crash tests, the in-process measurement tests and tools/soak.py.
"""
from __future__ import annotations

from dataclasses import dataclass

from instruments.audio.config import ChannelMap
from instruments.audio.factory import AudioSpec, open_audio
from instruments.rig.engine import RIG_CALIBRATION, RIG_CHANNEL_MAP
from instruments.rig.laser_feed import DisplacementFeed, aim_at_cone
from instruments.simulation.block_driver import BlockDriver

SERIAL_CHANNEL_MAP = ChannelMap(output=0, voltage=0, current=1)     # the serial laser: no analog laser input
KINDS = ("simulated", "serial", "analog", "none")


@dataclass(frozen=True, slots=True)
class LaserTruth:
    """Where the laser's samples really sat, in input samples of the card's running stream."""

    offset: float           # input index of laser sample 0
    ratio: float            # input samples per laser sample

    def delay_s(self, estimated_offset: float, sample_rate: float) -> float:
        """How much later than the truth an estimate puts the laser (what delay-x then fits)."""
        return (estimated_offset - self.offset) / sample_rate


class InProcessRig:
    """A simulated sound card and, optionally, a laser on the same cone; ``close()`` releases the laser's pty.

    ``calibration``: the chain's (instruments.audio.Calibration); the rig's own by default, whose amplifier
    gives 10 V at full scale (a multitone of ~7 V RMS at most).

    ``noise``: the sensors' instruments.rig.engine.RigNoise (the rig's default when None).

    ``laser``: one of KINDS. The laser's ``ppm``, ``start_latency_s`` (switch-on
    to first measurement), ``link_latency_s`` (measurement to arrival, which no
    host time shows), ``link_jitter_s`` (with it the samples arrive in a USB
    adapter's packets, late by the latency plus up to the jitter:
    instruments/laser/usb_link.py) and ``error_plan`` apply to every laser
    ``new_laser`` makes.
    """

    def __init__(self, driver: BlockDriver, laser: str = "simulated", *, ppm: float = 25.0,
                 start_latency_s: float = 0.0, link_latency_s: float = 0.0, link_jitter_s: float = 0.0,
                 error_plan=None, seed: int = 2,
                 blocksize: int = 2048, realtime: bool | None = None, calibration=RIG_CALIBRATION, noise=None):
        if laser not in KINDS:
            raise ValueError(f"laser: {laser!r}, expected one of {', '.join(KINDS)}")
        self.kind = laser
        self.feed = DisplacementFeed(driver.sample_rate)
        self.audio = open_audio(AudioSpec(
            "simulated", calibration=calibration, sample_rate=driver.sample_rate,
            channel_map=RIG_CHANNEL_MAP if laser in ("analog", "none") else SERIAL_CHANNEL_MAP,
            options=dict(driver=driver, blocksize=blocksize, seed=seed, feed=self.feed,
                         realtime=laser in ("simulated", "serial") if realtime is None else realtime,
                         **({} if noise is None else {"noise": noise}))))
        self.laser_settings = {"clock_ppm": float(ppm), "start_latency_s": float(start_latency_s),
                               "link_latency_s": float(link_latency_s), "link_jitter_s": float(link_jitter_s)}
        self.error_plan = error_plan
        self.emulator = None
        self.laser = None
        self.new_laser(error_plan)

    @property
    def model(self):
        """The laser's SensorModel (its clock, latencies and sample times), or None without one."""
        if self.emulator is not None:
            return self.emulator.model
        return None if self.laser is None else self.laser.model

    def new_laser(self, error_plan=None):
        """A fresh laser (after a hang-up the old one is gone for good): what is plugged in from now on."""
        from instruments.laser import LaserSpec, open_laser
        self.close()
        if self.kind == "simulated":
            self.laser = open_laser(LaserSpec(simulated=True, options=dict(error_plan=error_plan,
                                                                             **self.laser_settings)))
        elif self.kind == "serial":
            from instruments.laser.ild1420.emulator import LaserEmulator
            self.emulator = LaserEmulator(error_plan=error_plan, **self.laser_settings).start()
            self.laser = open_laser(LaserSpec(port=self.emulator.port_path))
        else:
            return None
        aim_at_cone(self.model, self.feed)
        return self.laser

    def truth(self) -> LaserTruth:
        """Where the current laser's stream sits in the card's running stream (both must have started)."""
        model, clock = self.model, self.feed.clock
        if model is None or model.t0 is None or clock is None:
            raise ValueError("the laser and the sound card must both have started")
        first = float(clock.frame_at(model.t0 + model.sample_times(0)))
        ratio = float(clock.sample_rate / model.host_rate_hz)
        return LaserTruth(first - float(self.audio.frame_of_input(0)), ratio)

    def close(self) -> None:
        if self.laser is not None and hasattr(self.laser, "close"):
            try:
                self.laser.close()
            except Exception:       # noqa: BLE001 - a laser already gone
                pass
        if self.emulator is not None:
            self.emulator.close()
            self.emulator = None
