"""instruments.laser.usb_link: a laser's samples through a USB serial adapter, in packets, late, with jitter."""
from __future__ import annotations

import numpy as np
import pytest

from instruments.laser.ild1420.sensor_model import SensorModel
from instruments.laser.usb_link import UsbLink, UsbLinkError

RATE = 4000.0


def taken(k):
    return np.asarray(k, dtype=np.float64) / RATE


def test_samples_arrive_with_their_packet_late_by_the_latency_plus_at_most_the_jitter_in_order():
    link = UsbLink(latency_s=0.008, jitter_s=0.002, packet_samples=20, seed=1)
    k = np.arange(20 * 500)
    arrival = link.arrival(k, taken)
    last_of_packet = (k // 20 + 1) * 20 - 1
    late = arrival - taken(last_of_packet)
    assert np.all(np.diff(arrival) >= 0)                              # a serial line keeps order
    assert np.all(arrival[k % 20 == 0] == arrival[k % 20 == 19])       # a packet arrives whole
    assert late.min() >= 0.008 and late.max() <= 0.010 + 0.005          # order may hold one back a packet's time
    assert np.ptp(late) > 0.0015                                       # the jitter is there


def test_what_has_arrived_by_a_time_is_whole_packets_and_agrees_with_the_arrival_times():
    link = UsbLink(latency_s=0.003, jitter_s=0.002, packet_samples=20, seed=2)
    arrival = link.arrival(np.arange(4000), taken)
    for now in np.linspace(0.0, 0.9, 97):
        count = link.arrived(now, taken, RATE, 0.0)
        assert count % 20 == 0 and count == int(np.sum(arrival <= now))


def test_without_packets_or_jitter_the_sensor_model_keeps_its_plain_latency():
    model = SensorModel(rate_hz=RATE, link_latency_s=0.002)
    model.begin(10.0)
    assert model.arrival_time(7) == pytest.approx(10.0 + 7 / RATE + 0.002)
    assert model.due(10.0 + 0.002 + 99.5 / RATE) == 100


def test_a_sensor_behind_a_jittery_link_hands_over_packets():
    model = SensorModel(rate_hz=RATE, link_latency_s=0.008, link_jitter_s=0.002)
    model.begin(0.0)
    counts = {model.due(t) for t in np.linspace(0.0, 0.5, 501)}
    assert all(c % 20 == 0 for c in counts) and max(counts) > 1800


@pytest.mark.parametrize("latency, jitter", [(-1e-3, 0.0), (2.0, 0.0), (0.0, -1e-3), (float("nan"), 0.0)])
def test_a_link_no_adapter_has_is_refused(latency, jitter):
    with pytest.raises(UsbLinkError):
        UsbLink(latency, jitter)
