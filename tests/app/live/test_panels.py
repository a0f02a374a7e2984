"""The live panels: they take every frame, draw the newest at a bounded rate, and show each channel's light."""
from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QTimer

from analysis.live import LiveAccumulator
from app.live.panels import MIN_REPAINT_GAP_S, LivePanels
from instruments.simulation import faults

from tests.app.wizard.test_wizard_helpers import plain
from tests.pace import wait_ms


def frames_of(recording, n: int | None = None):
    signals = [c.signal for c in recording.channels]
    acc = LiveAccumulator(recording.sample_rate, recording.period_samples, recording.excited_bins, signals=signals)
    count = recording.n_periods if n is None else n
    return [acc.add_period({s: recording.periods(s)[k] for s in signals}) for k in range(count)]


@pytest.fixture(scope="module")
def clean_frames():
    return frames_of(faults.clean())


@pytest.fixture
def panels(qtbot):
    p = LivePanels()
    qtbot.addWidget(p)
    p.resize(1100, 700)
    p.show()
    return p


def test_frames_arriving_fast_are_drawn_at_most_thirty_times_a_second(qtbot, panels, clean_frames):
    sent = []
    feeder = QTimer()
    feeder.setInterval(2)
    # Three frames a tick, 300 in 100 ticks (~1500 frames a second, far faster than any measurement): a draw
    # takes the newest frame of at least one tick, so at most 100 draws however the host schedules the loop.
    # One frame a tick let a loaded host fire the feeder about once per draw, near the bound of 150.
    per_tick = 3

    def feed():
        for _ in range(per_tick):
            sent.append(clean_frames[len(sent) % len(clean_frames)])
            panels.set_frame(sent[-1])
        if len(sent) >= 300:
            feeder.stop()
    feeder.timeout.connect(feed)
    feeder.start()
    qtbot.waitUntil(lambda: len(sent) >= 300 and panels.frame is sent[-1], timeout=wait_ms(20))   # the last one too
    assert panels.frames_received == 300
    assert panels.frame is sent[-1]
    intervals = np.diff(panels.paint_times)
    assert len(panels.paint_times) >= 3
    assert len(panels.paint_times) < 300 / 2            # most frames were skipped, never queued
    assert intervals.min() >= MIN_REPAINT_GAP_S


def test_each_panel_shows_lines_noise_and_distortion(qtbot, panels, clean_frames):
    frame = clean_frames[-1]
    with qtbot.waitSignal(panels.repainted, timeout=wait_ms(10)):
        panels.set_frame(frame)
    for name, panel in panels.panels.items():
        x, y = panel.lines.getData()              # each line a short segment: two points
        lines_db = (y[0::2] + y[1::2]) / 2
        assert len(x) == 2 * frame.line_freqs.size and np.all(np.isfinite(y))
        assert np.allclose(10 ** x[0::2], frame.line_freqs)
        assert len(panel.distortion.getData()[0]) > 100 and len(panel.noise.getData()[0]) > 50
        # The signal lines stand above the noise floor.
        assert np.median(lines_db) > np.nanmedian(panel.noise.getData()[1]) + 20
        assert panel.light.light.status == "green"
    assert f"{frame.n_periods} periods averaged" in plain(panels.status)


def test_a_disconnected_current_is_red_on_its_panel_with_the_finding_and_remedy(qtbot, panels):
    frame = frames_of(faults.current_disconnected())[-1]
    with qtbot.waitSignal(panels.repainted, timeout=wait_ms(10)):
        panels.set_frame(frame)
    current = panels.panels["current"]
    assert current.light.light.status == "red"
    text = plain(current.light.details)
    finding = frame.channels["current"].findings[0]
    assert finding.message in text and finding.remedy in text
    assert current.light.details.isVisible()
    assert panels.panels["voltage"].light.light.status == "green"


def test_before_two_periods_the_lights_are_unknown(qtbot, panels, clean_frames):
    with qtbot.waitSignal(panels.repainted, timeout=wait_ms(10)):
        panels.set_frame(clean_frames[0])
    assert all(p.light.light.status == "unknown" for p in panels.panels.values())
    assert "needs two periods" in plain(panels.panels["voltage"].light.details)


def test_a_measurement_without_displacement_shows_that_channel_absent(qtbot, panels):
    recording = faults.clean()
    frames = frames_of(recording.__class__(
        recording.sample_rate, recording.channels[:2], recording.data[:2], recording.period_samples,
        recording.settle_periods, recording.excited_bins), 3)
    with qtbot.waitSignal(panels.repainted, timeout=wait_ms(10)):
        panels.set_frame(frames[-1])
    assert panels.panels["displacement"].light.light.status == "absent"
    assert panels.panels["displacement"].lines.getData()[0].size == 0


def test_clear_calls_back_after_the_last_channel_is_emptied_and_not_when_a_newer_clear_took_over(qtbot, panels,
                                                                                                 clean_frames):
    """A measurement begins on this call back (app.wizard.measure_session): the three channels emptied first,
    each in its own turn, and a superseded clear never calls."""
    with qtbot.waitSignal(panels.repainted, timeout=wait_ms(10)):
        panels.set_frame(clean_frames[-1])
    called, superseded = [], []
    panels.clear(band_hz=(10.0, 1000.0), then=lambda: superseded.append(1))
    panels.clear(band_hz=(10.0, 1000.0),
                 then=lambda: called.append([p.lines.getData()[0].size for p in panels.panels.values()]))
    assert not called                                  # later turns, not the clear's own
    qtbot.waitUntil(lambda: bool(called), timeout=wait_ms(10))
    assert called == [[0, 0, 0]]                       # every channel empty by then
    assert superseded == []             # its next turn was due before the newer chain's: it ran, and stopped
