"""Validity, live processing and the nonlinear simulator: how long each takes."""
from __future__ import annotations

import statistics
import time
from pathlib import Path

import numpy as np

from bench.common import Row, at_most, median_time, standard_recording

LIVE_TARGET_S = 5e-3          # one period of 3 x 65,536 samples, the target
SIMULATOR_TARGET_S = 5.0      # 16 periods of 16,384 samples through the nonlinear driver


def run(workdir: Path) -> list[Row]:
    from analysis.live import LiveAccumulator
    from analysis.recording.format import read_recording
    from analysis.spectra import estimate_spectra
    from analysis.validity.assessment import assess

    rec = read_recording(standard_recording(workdir))
    signals = ("voltage", "current", "displacement")
    periods = [np.stack([rec.periods(s)[p] for s in signals]) for p in range(rec.n_periods)]
    rows = []

    # Live: every period of the standard recording, a fresh accumulator per pass (frames from period 2 on
    # run every check); the median over all periods of several passes.
    # Wall time is the target; the thread's CPU time says what the work costs when other processes
    # compete for the cores (wall time then grows, CPU time hardly).
    times, cpu = [], []
    for _ in range(3):
        acc = LiveAccumulator(rec.sample_rate, rec.period_samples, rec.excited_bins, signals)
        for period in periods:
            t0, c0 = time.perf_counter(), time.thread_time()
            acc.add_period(period)
            times.append(time.perf_counter() - t0)
            cpu.append(time.thread_time() - c0)
    rows.append(at_most("live: one period of 3 x 65,536 samples (median)", statistics.median(times) * 1e3, "ms",
                        LIVE_TARGET_S * 1e3))
    rows.append(Row("  90th percentile", float(np.percentile(times, 90)) * 1e3, "ms", "", None))
    rows.append(Row("  CPU time of the thread (median)", statistics.median(cpu) * 1e3, "ms", "", None))

    spectra = estimate_spectra(rec)
    t_assess = median_time(lambda: assess(rec, spectra), repeats=7)
    rows.append(Row("validity of the standard recording (spectra given)", t_assess * 1e3, "ms", "", None))

    rows.append(at_most("nonlinear driver: 16 periods of 16,384 samples", _simulator_time(), "s",
                        SIMULATOR_TARGET_S))
    return rows


def _simulator_time() -> float:
    from analysis.drivers import load_driver
    from analysis.multitone import design_multitone
    from instruments.simulation.nonlinear_driver import NonlinearBlockDriver

    mt = design_multitone(48000, 16384, 5.0, 10000.0, rms=3.0, crest_iterations=0)
    driver = NonlinearBlockDriver(load_driver("paper").parameters, 48000)
    u = mt.tile(16)

    def simulate():
        driver.reset()
        driver.process(u)
    return median_time(simulate, repeats=3)
