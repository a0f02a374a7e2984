"""CaptureStats: how a capture ended is a CaptureEnd; the sidecar's "audio_capture" says it as before."""
from __future__ import annotations

import json
import threading

import numpy as np
import pytest

from instruments.audio.capture_loop import capture
from instruments.audio.captured import CaptureEnd, CaptureStats
from instruments.audio.errors import CaptureCancelled
from instruments.audio.simulated import SimulatedAudio

WAVE = np.sin(2 * np.pi * 3 * np.arange(1024) / 1024)


def stats(**how_it_ended) -> CaptureStats:
    counts = dict.fromkeys(("fade_samples", "settle_samples", "discarded_samples", "samples_received",
                            "samples_lost", "gaps", "queue_overflows", "input_overflows", "input_underflows",
                            "output_underflows", "output_overflows", "restarts", "output_clipped_samples"), 0)
    return CaptureStats(sample_rate=48000, period_samples=1024, periods_kept=2, output_peak_fs=0.5,
                        clipped_inputs=(("voltage", 0),), full_scale_fraction=(("voltage", 0.5),),
                        silent_channels=(), **counts, **how_it_ended)


def test_a_complete_capture_says_complete():
    got = capture(SimulatedAudio(realtime=False), WAVE, 2, 1, fade_s=0.0)
    assert got.stats.ended_by is CaptureEnd.COMPLETE and got.stats.failure == ""
    assert got.stats.as_dict()["ended_by"] == "complete"


def test_a_cancelled_capture_says_cancelled_and_keeps_its_periods():
    cancel = threading.Event()
    cancel.set()
    with pytest.raises(CaptureCancelled) as info:
        capture(SimulatedAudio(realtime=False), WAVE, 50, 1, fade_s=0.0, cancel=cancel)
    assert info.value.partial.stats.ended_by is CaptureEnd.CANCELLED
    assert info.value.partial.stats.as_dict()["ended_by"] == "cancelled"


def test_the_sidecar_reads_as_before_a_failure_in_its_own_words():
    words = "the audio stream stopped by itself (device unplugged or audio server gone)"
    failed = stats(ended_by=CaptureEnd.FAILED, failure=words)
    doc = json.loads(json.dumps(failed.as_dict()))
    assert doc["ended_by"] == words and "failure" not in doc
    assert json.dumps(stats().as_dict()["ended_by"]) == '"complete"'
    assert json.dumps(stats(ended_by=CaptureEnd.CANCELLED).as_dict()["ended_by"]) == '"cancelled"'


def test_capture_stats_are_built_by_keyword():
    with pytest.raises(TypeError):
        CaptureStats(48000, 1024, 2)      # noqa: the positional form is refused
