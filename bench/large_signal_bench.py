"""Large signal: the identification's speed, and the large-signal plan on the JACK rig's nonlinear model.

Rows: the identification (analysis.large_signal.identify) of one recording
of 4 periods of 16,384 samples (the issue's 4 x 16,384; target <= 5 s), the
whole analysis with limits, residuals and distortion (large_signal), and
`measure --plan large-signal`'s plan on the rig (linpar rig start --model
nonlinear --driver demo-large-signal; its serial laser behind a USB link 8 ms
late with 2 ms of jitter, --fault latency=0.008,jitter=0.002; the default limits:
on the rig's chain the current input's 2 A full scale ends it near 2 mm;
target <= 60 s), each a median.
"""
from __future__ import annotations

import os
import shutil
import statistics
import time
from pathlib import Path

from bench.common import Row, at_most, median_time

PLAN_RUNS = 3
USB_LINK = "latency=0.008,jitter=0.002"       # the serial laser as a USB serial adapter delivers it


def run(workdir: Path) -> list[Row]:
    from analysis.large_signal import large_signal
    from analysis.large_signal.data import recording_data
    from analysis.large_signal.identify import identify
    from tests.large_signal_truth import clean_periods, known_driver, noisy_recording

    block, mt = clean_periods(known_driver(16384), 10.5, 4)
    recording = noisy_recording(block, mt)
    data = [recording_data(recording)]
    rows = [at_most("large signal: identification, 4 x 16,384 samples", median_time(lambda: identify(data), 5),
                    "s", 5.0),
            Row("large signal: the same, CPU time of this process",
                median_time(lambda: identify(data), 5, warmup=0, clock=time.process_time), "s", "", None),
            Row("large signal: identification + limits + residuals + distortion",
                median_time(lambda: large_signal([recording]), 3), "s", "", None)]
    return rows + _plan_on_the_rig(workdir)


def _plan_on_the_rig(workdir: Path) -> list[Row]:
    if shutil.which("jackd") is None:
        return [Row("large signal: plan skipped, jackd is not installed (Debian package jackd2)", 0.0, "", "", None)]
    from instruments.audio import AudioSpec, open_audio, portaudio
    from instruments.laser import LaserSpec, open_laser
    from instruments.measurement.large_signal_plan import LargeSignalPlan, run_large_signal
    from instruments.measurement.plan import MeasurementPlan
    from instruments.rig.manager import start_rig, stop_rig

    name = f"linpar-bench-ls-{os.getpid()}"
    handle = start_rig(name, driver="demo-large-signal", faults=[USB_LINK], runtime_dir=workdir, seed=5,
                       model="nonlinear")
    times, outcomes = [], []
    try:
        for k in range(PLAN_RUNS):
            audio = open_audio(AudioSpec("rig", options={"rig": handle}))
            plan = LargeSignalPlan(MeasurementPlan.from_template("large-signal"), 0.5)
            t0 = time.monotonic()
            outcomes.append(run_large_signal(plan, audio, open_laser(LaserSpec(port=handle.state.laser_pty)), workdir / f"plan-{k}",
                                             name="ls"))
            times.append(time.monotonic() - t0)
            portaudio.release()
    finally:
        portaudio.release()
        stop_rig(name, runtime_dir=workdir)
    last = outcomes[-1]
    peak = max((s.measures.peak_m or 0.0) for s in last.steps if s.measures is not None)
    return [at_most(f"large signal: plan on the rig (laser link {USB_LINK}), {len(last.steps)} steps to "
                    f"{peak * 1e3:.2f} mm "
                    f"(stopped: {last.stopped_by})", statistics.median(times), "s", 60.0)]
