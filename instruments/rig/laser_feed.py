"""The rig's serial laser: an ILD1420 emulator on a pseudo-terminal that measures the rig's own cone.

    audio thread ── RigEngine.displacement_sinks ──> DisplacementFeed.sink   (enqueue only)
                                                            │ SimpleQueue
    emulator thread ── displacement(host times) ──> DisplacementFeed.at_host_times
                                                     (drain into a ring buffer, interpolate)

Time base: one clock, the audio frame counter (frame_clock.py). Frame f of
the rig's audio is "taken" at host time

    H(f) = T0 + f / fs.

An emulated sound card (SimulatedAudio) runs on a FrameClock of its own and
hands it over (``use_clock``): T0 is then exact, by construction. The JACK
rig's clock has to be read off its cycles: T0 is the least (cycle start -
first frame of the cycle / fs) over the cycles of the first SETTLE_S seconds,
then fixed. The dummy JACK backend schedules its cycles on the host's
monotonic clock (measured: its schedule stays within ~20 us of one line over
20 s), and wake-ups are only ever late, so that minimum is the schedule
itself; fixed, it makes the time base one straight line, as a crystal's
would be (a T0 that kept following new minima would warp the laser's time by
microseconds, a fraction of a ppm). It starts again when the schedule has
clearly moved: RESCHEDULE_CYCLES cycles in a row later than T0 by
RESCHEDULE_S (JACK restarts its schedule after an xrun), or one cycle earlier
than T0 by EARLY_S. ``cycle_clock`` (the caller's) says when the current
cycle started (on JACK: time.monotonic() minus frames_since_cycle_start / fs,
which removes the time the callback spent before the sink ran).

Why that is the instant the workstation sees: PortAudio's stream runs first in
a JACK cycle and reads the rig's outputs of the previous cycle (the link that
closes the loop workstation -> rig -> workstation is JACK's "feedback" link), so
the block the rig computes in the cycle that starts at H(n) reaches the
workstation one cycle later, at H(n + period): exactly as if an ADC had
sampled frames n .. n+period-1 during that cycle and delivered them at its end.
SimulatedAudio keeps the same order (instruments/audio/simulated.py).
``capture_delay_s`` shifts the whole time base, for a wiring where that is not so.

A thread of the feed (``start``) moves the queued blocks into the ring every
DRAIN_S, so the queue stays short whether or not the laser is streaming.

The emulator asks for displacement at host times t0 + t (t0: when its output
was switched on). A frame the audio has not computed yet is waited for, as
long as the audio is still running (a block came within QUIET_S) and at most
MAX_WAIT_S: a busy machine delays the emulator's answer, it never turns the
cone's motion into rest. Frames older than the history, or after the audio
stopped, read as rest. Interpolation between the rig's samples is 4-point
Lagrange (cubic): at 2 kHz, the top of a 4 kHz laser's band, it is exact to ~1e-5.

Sign: the rig's laser looks at the front of the cone, so outward motion
(positive displacement) brings the target closer: distance = rest - x.
"""
from __future__ import annotations

import queue
import threading
import time
from typing import Callable

import numpy as np

from instruments.laser.ild1420.emulator import LaserEmulator
from instruments.laser.ild1420.sensor_model import SensorModel
from instruments.rig.frame_clock import FrameClock

HISTORY_FRAMES = 1 << 18          # 5.5 s at 48 kHz: far more than any laser latency
QUIET_S = 0.25                    # no block for this long: the audio stopped, frames to come will not come
MAX_WAIT_S = 2.0                  # longest the emulator waits for a frame the rig has not computed yet
DRAIN_S = 0.05                    # how often the feed's own thread empties the queue
SETTLE_S = 2.0                    # the earliest cycle start of this long fixes T0
RESCHEDULE_S = 0.0005             # cycles later than T0 by this ...
RESCHEDULE_CYCLES = 16            # ... so many in a row: JACK moved its schedule (after an xrun)
EARLY_S = 0.0002                  # a cycle this much earlier than T0: the schedule moved earlier


class DisplacementFeed:
    """The rig's displacement, kept with its time base, for a sensor that samples it at host times."""

    def __init__(self, sample_rate: int, cycle_clock: Callable[[], float] = time.monotonic,
                 capture_delay_s: float = 0.0, history_frames: int = HISTORY_FRAMES,
                 settle_s: float = SETTLE_S):
        self.sample_rate = int(sample_rate)
        self.settle_frames = int(settle_s * sample_rate)     # 0: T0 from the first block alone
        # NB: may be replaced once the JACK client exists (it needs the client); read by the audio thread.
        self.cycle_clock = cycle_clock
        self.capture_delay_s = float(capture_delay_s)
        self._inbox: queue.SimpleQueue = queue.SimpleQueue()   # NB: audio thread puts, emulator thread gets
        self._ring = np.zeros(history_frames)
        self._newest = -1                 # the last frame in the ring (frames are the audio's)
        self._last_block_at = -np.inf     # host time the newest block was handed to the sink
        self._late_cycles = 0
        self._settled_at = 0              # the frame from which T0 is fixed
        self.restarts = 0                 # times T0 started again (the schedule moved), for the rig's status
        self._t0: float | None = None
        self._fixed = False               # T0 given by an emulated sound card's own clock (use_clock)
        self._lock = threading.Lock()     # the ring and the time base: the drain thread and the emulator's
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def use_clock(self, clock: FrameClock) -> DisplacementFeed:
        """The frames' time base is this clock (an emulated sound card's): nothing is read off wake-ups."""
        if clock.sample_rate != self.sample_rate:
            raise ValueError(f"the clock runs at {clock.sample_rate} Hz, the feed at {self.sample_rate} Hz")
        with self._lock:
            self._t0, self._fixed = float(clock.t0), True
        return self

    @property
    def clock(self) -> FrameClock | None:
        """The time base (None until the first cycle of a JACK rig was seen)."""
        t0 = self._t0
        return None if t0 is None else FrameClock(t0 + self.capture_delay_s, self.sample_rate)

    def start(self) -> DisplacementFeed:
        """Keep the queue drained from a thread of its own (until ``close``)."""
        if self._thread is None:
            self._thread = threading.Thread(target=self._drain_loop, name="displacement-feed", daemon=True)
            self._thread.start()
        return self

    def close(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(1.0)

    def _drain_loop(self) -> None:
        while not self._stop.wait(DRAIN_S):
            self._drain()

    # --- audio thread ---------------------------------------------------------------------------
    def sink(self, displacement: np.ndarray, frame: int) -> None:
        """RigEngine's displacement sink: stamp and enqueue, nothing else (the audio thread calls it)."""
        self._inbox.put((int(frame), self.cycle_clock(), displacement))

    # --- emulator thread ------------------------------------------------------------------------
    def at_host_times(self, host_times: np.ndarray) -> np.ndarray:
        """Displacement (m, positive outward) at these host times (time.monotonic seconds)."""
        host_times = np.asarray(host_times, dtype=np.float64)
        self._drain()
        clock = self.clock
        if clock is None or host_times.size == 0:
            return np.zeros(host_times.shape)
        return self.at_frames(clock.frame_at(host_times))

    def at_frames(self, frames: np.ndarray) -> np.ndarray:
        """Displacement (m, positive outward) at these (fractional) frames of the audio; waits for frames
        still to be computed while the audio runs (module doc)."""
        frames = np.asarray(frames, dtype=np.float64)
        if frames.size == 0:
            return np.zeros(frames.shape)
        deadline = time.monotonic() + MAX_WAIT_S
        while frames.max() + 2 > self._newest:
            now = time.monotonic()
            if now >= deadline or now - self._last_block_at > QUIET_S:
                break
            time.sleep(0.002)      # the audio thread cannot notify (it must not take a lock): poll
            self._drain()
        with self._lock:
            return self._interpolate(frames)

    def _drain(self) -> None:
        with self._lock:
            while True:
                try:
                    frame, started, block = self._inbox.get_nowait()
                except queue.Empty:
                    return
                self._store(frame, np.asarray(block, dtype=np.float64))
                self._last_block_at = max(self._last_block_at, started)
                if not self._fixed:
                    self._clock(frame, started)

    def _store(self, frame: int, block: np.ndarray) -> None:
        n, size = block.size, self._ring.size
        if n == 0:
            return
        if frame > self._newest + 1 and self._newest >= 0:     # frames the rig never computed: at rest
            gap = np.arange(self._newest + 1, min(frame, self._newest + 1 + size))
            self._ring[gap % size] = 0.0
        block = block[-size:]
        index = (np.arange(block.size) + frame + n - block.size) % size
        self._ring[index] = block
        self._newest = max(self._newest, frame + n - 1)

    def _clock(self, frame: int, started: float) -> None:
        """T0: the earliest schedule of the first cycles, then fixed until the schedule moves (module doc)."""
        t0 = started - frame / self.sample_rate
        if self._t0 is None or t0 < self._t0 - EARLY_S:
            self._restart(frame, t0)
        elif frame < self._settled_at:
            self._t0 = min(self._t0, t0)
        else:
            self._late_cycles = self._late_cycles + 1 if t0 > self._t0 + RESCHEDULE_S else 0
            if self._late_cycles >= RESCHEDULE_CYCLES:
                self._restart(frame, t0)

    def _restart(self, frame: int, t0: float) -> None:
        self.restarts += self._t0 is not None
        self._t0, self._settled_at, self._late_cycles = t0, frame + self.settle_frames, 0

    def time_base(self) -> dict:
        """T0 (time.monotonic s of frame 0) and how often it started again: what the rig's status reports."""
        return {"t0": self._t0, "restarts": self.restarts, "newest_frame": self._newest}

    def _interpolate(self, frames: np.ndarray) -> np.ndarray:
        size = self._ring.size
        base = np.floor(frames).astype(np.int64)
        mu = frames - base
        out = np.zeros(frames.shape)
        oldest = self._newest - size + 1
        usable = (base - 1 >= max(oldest, 0)) & (base + 2 <= self._newest)
        if not np.any(usable):
            return out
        b, m = base[usable], mu[usable]
        p = [self._ring[(b + j) % size] for j in (-1, 0, 1, 2)]
        # 4-point Lagrange weights at mu in [0, 1) between the 2nd and 3rd point.
        w = (-m * (m - 1) * (m - 2) / 6, (m + 1) * (m - 1) * (m - 2) / 2,
             -(m + 1) * m * (m - 2) / 2, (m + 1) * m * (m - 1) / 6)
        out[usable] = w[0] * p[0] + w[1] * p[1] + w[2] * p[2] + w[3] * p[3]
        return out


def aim_at_cone(model: SensorModel, feed: DisplacementFeed) -> None:
    """Point a virtual sensor at the front of the feed's cone: outward motion shortens the distance."""
    model.displacement = lambda t: -feed.at_host_times(model.t0 + np.asarray(t))


# What the rig's "laser" command may change (SensorModel attributes of the same names).
CONFIGURABLE = ("clock_ppm", "start_latency_s", "noise_m", "link_latency_s", "link_jitter_s")


class RigLaser:
    """The ILD1420 emulator on the rig's pty, fed by a DisplacementFeed; unplug and plug it back."""

    def __init__(self, feed: DisplacementFeed, clock_ppm: float = 37.0, start_latency_s: float = 0.02,
                 noise_m: float = 0.0, measuring_range_mm: int = 10, link_latency_s: float = 0.0,
                 link_jitter_s: float = 0.0):
        self.feed = feed.start()
        self.settings = {"clock_ppm": float(clock_ppm), "start_latency_s": float(start_latency_s),
                         "noise_m": float(noise_m), "link_latency_s": float(link_latency_s),
                         "link_jitter_s": float(link_jitter_s),
                         "measuring_range_mm": int(measuring_range_mm)}
        self.emulator: LaserEmulator | None = None
        self._lock = threading.Lock()

    @property
    def port_path(self) -> str | None:
        emulator = self.emulator
        return None if emulator is None else emulator.port_path

    def plug(self) -> str:
        """A fresh emulator on a new pty (the old one, if any, is closed); its port path."""
        with self._lock:
            if self.emulator is not None:
                self.emulator.close()
            s = self.settings
            emulator = LaserEmulator(None, s["measuring_range_mm"], 4000.0, s["clock_ppm"], s["start_latency_s"],
                                     s["noise_m"], link_latency_s=s["link_latency_s"],
                                     link_jitter_s=s["link_jitter_s"])
            aim_at_cone(emulator.model, self.feed)
            self.emulator = emulator.start()
            return emulator.port_path

    def unplug(self) -> None:
        """The cable is pulled: the reader gets what was sent, then a dead line."""
        with self._lock:
            emulator, self.emulator = self.emulator, None
        if emulator is not None:
            emulator.disconnect()

    def configure(self, **settings: float) -> dict:
        """Change clock_ppm, start_latency_s, noise_m, link_latency_s, link_jitter_s (from the next time its
        output is switched on)."""
        unknown = sorted(set(settings) - set(CONFIGURABLE))
        if unknown:
            raise ValueError(f"laser: unknown setting(s) {', '.join(unknown)}; known: {', '.join(CONFIGURABLE)}")
        with self._lock:
            for key, value in settings.items():
                self.settings[key] = float(value)
            if self.emulator is not None:
                model = self.emulator.model
                for key in CONFIGURABLE:
                    setattr(model, key, self.settings[key])
            return dict(self.settings)

    def close(self) -> None:
        with self._lock:
            emulator, self.emulator = self.emulator, None
        if emulator is not None:
            emulator.close()
        self.feed.close()
