"""The virtual rig under a real measurement: 60 s of capture at 48 kHz, 3 inputs, through PortAudio and JACK.

Rows: xruns (as PortAudio reports them to the workstation, and as the rig's
JACK client sees them; target 0), the CPU share of the rig process, of its
jackd and of the workstation process (this one) while measuring, the cost of
one 1024-sample block of the rig's driver, and how close the parameters
come out. CPU shares are of one core, from /proc/<pid>/stat (rig, jackd) and
os.times() (this process), over the capture's wall time.
"""
from __future__ import annotations

import math
import os
import shutil
import time
from pathlib import Path

import numpy as np

from bench.common import Row, at_most, median_time

SAMPLE_RATE = 48000
PERIOD = 32768
SETTLE = 3
MEASURE_S = 60.0


def run(workdir: Path) -> list[Row]:
    if shutil.which("jackd") is None:
        return [Row("rig: skipped, jackd is not installed (Debian package jackd2)", 0.0, "", "", None)]
    from analysis.derived import derived_from_values
    from analysis.drivers import load_driver
    from analysis.multitone import design_multitone
    from analysis.pipeline import analyze_recording
    from instruments.audio import JACK_HOSTAPI, AudioDeviceChoice, AudioSpec, capture, open_audio, portaudio
    from instruments.rig.engine import default_driver
    from instruments.rig.manager import start_rig, stop_rig

    rows = [_driver_block_cost(default_driver("paper", SAMPLE_RATE)[0])]
    name = f"linpar-bench-{os.getpid()}"
    rig = start_rig(name, runtime_dir=workdir, seed=5)
    try:
        portaudio.use_jack_server(rig.state.jack_server)
        mt = design_multitone(SAMPLE_RATE, PERIOD, 5.0, 10000.0, rms=1.0)
        audio = open_audio(AudioSpec("sounddevice", AudioDeviceChoice("system", JACK_HOSTAPI),
                                     rig.state.workstation_calibration, SAMPLE_RATE, rig.state.workstation_channel_map))
        n_periods = math.ceil(MEASURE_S * SAMPLE_RATE / PERIOD)
        rig_xruns_before = rig.command("status")["xruns"]
        cpu_before = {"rig": _cpu_seconds(rig.pid), "jackd": _cpu_seconds(rig.state.jackd_pid), "self": _own_cpu()}
        t0 = time.monotonic()
        captured = capture(audio, mt.waveform, n_periods, SETTLE)
        wall = time.monotonic() - t0
        cpu = {"rig": _cpu_seconds(rig.pid), "jackd": _cpu_seconds(rig.state.jackd_pid), "self": _own_cpu()}
        rig_xruns = rig.command("status")["xruns"] - rig_xruns_before
        portaudio.release()
    finally:
        stop_rig(name, runtime_dir=workdir)

    share = {k: 100.0 * (cpu[k] - cpu_before[k]) / wall for k in cpu}
    stats = captured.stats
    rows += [
        at_most(f"rig: xruns reported to the workstation in {wall:.0f} s", stats.xruns, "", 0),
        at_most("rig: xruns seen by the rig's JACK client", rig_xruns, "", 0),
        at_most("rig: restarts of the averaging (dropouts)", stats.restarts, "", 0),
        at_most("rig: CPU of the rig process (driver FIR + JACK)", share["rig"], "%", 30.0),
        Row("rig: CPU of the rig's jackd (dummy backend)", share["jackd"], "%", "", None),
        at_most("rig: CPU of the workstation process (capture)", share["self"], "%", 30.0),
    ]
    truth = {**load_driver("paper").parameters, **derived_from_values(load_driver("paper").parameters)}
    result = analyze_recording(captured.to_recording(mt.excited_bins))
    worst = max(abs(result.parameters[k].value / truth[k] - 1) for k in ("RE", "fs", "Bl", "Mms", "Qts"))
    rows.append(at_most(f"rig: worst error of RE, fs, Bl, Mms, Qts ({captured.n_periods} periods)",
                        100 * worst, "%", 0.5))
    return rows


def _driver_block_cost(driver) -> Row:
    block = np.random.default_rng(0).normal(size=1024)
    seconds = median_time(lambda: [driver.process(block) for _ in range(20)], repeats=5) / 20
    return at_most("rig: LinearBlockDriver, one 1024-sample block (65,536 taps)", seconds * 1e6, "us", 2000.0)


def _cpu_seconds(pid: int) -> float:
    """user + system time of a process, from /proc/<pid>/stat (fields 14 and 15, in clock ticks)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _own_cpu() -> float:
    t = os.times()
    return t.user + t.system
