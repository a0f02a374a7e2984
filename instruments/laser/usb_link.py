"""A USB serial adapter between a laser and the host: samples arrive in packets, late, with jitter.

A real optoNCDT reaches a PC through a USB-RS422 adapter. The adapter hands
its bytes to the host in USB packets, when its buffer fills or its latency
timer runs out (16 ms by default on the common FTDI chips), and the host's
USB stack adds its own irregular delay. So a laser sample reaches the host
not when it was taken but with the packet that holds it:

    packet j = samples j*P .. (j+1)*P - 1   (P = packet_samples)
    arrival(j) = taken(last sample of j) + latency_s + jitter_s * u_j,   u_j uniform in [0, 1)

and never before the packet ahead of it (a serial line keeps order). The
u_j come from ``seed``, so a run can be repeated. With P = 1 and no jitter
every sample arrives ``latency_s`` after it was taken: the link without an
adapter's packets, as before this module.

No host time shows this latency: the alignment (instruments/measurement/
alignment.py) places the stream by the arrival times' lower envelope, so the
displacement lags by about ``latency_s``, which the analysis finds from the
data (analysis/laser_delay.py).
"""
from __future__ import annotations

import math

import numpy as np

from analysis.errors import LinparError

#: A full-speed FTDI packet carries 62 bytes of data; a distance-only ILD1420 measurement is 3 bytes.
PACKET_SAMPLES = 20
MAX_LATENCY_S = 1.0         # beyond a second a link is broken, not late


class UsbLinkError(LinparError, ValueError):
    """A link latency or jitter that no link has (negative, not finite, above MAX_LATENCY_S)."""


def check_link_seconds(value: float, what: str) -> float:
    """A link latency or jitter in seconds: finite, 0 .. MAX_LATENCY_S."""
    value = float(value)
    if not (math.isfinite(value) and 0.0 <= value <= MAX_LATENCY_S):
        raise UsbLinkError(f"{what}: expected seconds from 0 to {MAX_LATENCY_S:g}, got {value!r}")
    return value


class UsbLink:
    """When each packet of a laser's stream reaches the host (module doc); host seconds after switch-on."""

    def __init__(self, latency_s: float = 0.0, jitter_s: float = 0.0, packet_samples: int = 1, seed: int = 0):
        self.latency_s = check_link_seconds(latency_s, "latency")
        self.jitter_s = check_link_seconds(jitter_s, "jitter")
        if int(packet_samples) < 1:
            raise UsbLinkError(f"packet_samples: expected a whole number >= 1, got {packet_samples!r}")
        self.packet_samples = int(packet_samples)
        self._rng = np.random.default_rng(seed)
        self._u = np.zeros(0)       # u_j of the packets drawn so far (grown on demand, never redrawn)

    def _draws(self, n_packets: int) -> np.ndarray:
        if n_packets > self._u.size:
            grow = max(n_packets - self._u.size, 4096)
            self._u = np.concatenate([self._u, self._rng.random(grow)])
        return self._u[:n_packets]

    def packet_arrivals(self, n_packets: int, taken) -> np.ndarray:
        """Arrival (host s after switch-on) of packets 0 .. n_packets-1; ``taken(k)``: when sample k was taken."""
        last = (np.arange(n_packets) + 1) * self.packet_samples - 1
        arrival = taken(last) + self.latency_s + self.jitter_s * self._draws(n_packets)
        return np.maximum.accumulate(arrival) if n_packets else arrival

    def arrival(self, k, taken) -> np.ndarray:
        """Arrival of samples k (with their packets)."""
        k = np.asarray(k, dtype=np.int64)
        packet = k // self.packet_samples
        n = int(packet.max()) + 1 if packet.size else 0
        return self.packet_arrivals(n, taken)[packet]

    def arrived(self, elapsed_s: float, taken, rate_hz: float, start_s: float) -> int:
        """How many samples have reached the host ``elapsed_s`` after switch-on (whole packets only).

        Packets whose last sample is taken after elapsed_s - latency_s cannot have arrived; of the others,
        those whose arrival is due."""
        taken_by = elapsed_s - self.latency_s - start_s
        if taken_by < 0:
            return 0
        candidates = (int(math.floor(taken_by * rate_hz)) + 1) // self.packet_samples
        if candidates == 0:
            return 0
        arrivals = self.packet_arrivals(candidates, taken)
        return int(np.searchsorted(arrivals, elapsed_s, side="right")) * self.packet_samples
