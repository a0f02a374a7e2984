"""Shared bits of the benchmarks: timing, rows, the standard recording."""
from __future__ import annotations

import os
import statistics
import subprocess
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

RESULTS_DIR = Path(__file__).resolve().parent / "results"


@dataclass(frozen=True)
class Row:
    name: str
    value: float
    unit: str
    target: str          # e.g. "<= 0.3"
    ok: bool | None      # None: no target

    def as_json(self) -> dict:
        return {"name": self.name, "value": self.value, "unit": self.unit, "target": self.target, "ok": self.ok}


def median_time(fn: Callable[[], object], repeats: int = 5, warmup: int = 1,
                clock: Callable[[], float] = time.perf_counter) -> float:
    """Median seconds per call of `fn` after `warmup` calls; `clock` time.process_time gives the CPU time of
    this process (all its threads), what the wall time would be on an idle machine."""
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeats):
        t0 = clock()
        fn()
        times.append(clock() - t0)
    return statistics.median(times)


def child_time(cmd: list[str], env: dict | None = None) -> tuple[float, float]:
    """(CPU seconds, wall seconds) of running `cmd` once as a child process (in `env`, default this process's).
    The CPU time is the child's user + system time (its threads and the children it waited for, from wait4): on
    a machine shared with others it is what the wall time would be on an idle one, where the wall time measures
    the others too."""
    t0 = time.perf_counter()
    child = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env)
    _, status, usage = os.wait4(child.pid, 0)
    wall = time.perf_counter() - t0
    if status != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit status {status}: {child.stderr.read().decode()[-500:]}")
    child.stderr.close()
    return usage.ru_utime + usage.ru_stime, wall


def child_times(cmd: list[str], repeats: int = 5) -> tuple[float, float]:
    """Median (CPU seconds, wall seconds) of `repeats` runs of `cmd` as a child process (child_time)."""
    runs = [child_time(cmd) for _ in range(repeats)]
    return statistics.median(cpu for cpu, _ in runs), statistics.median(wall for _, wall in runs)


def compiled_env(env: dict, workdir: Path) -> dict:
    """`env` as an installed copy runs: linpar's modules compiled once (pip compiles what it installs), here into
    a cache folder of the benchmark's own (PYTHONPYCACHEPREFIX), never into the source tree. A machine that sets
    PYTHONDONTWRITEBYTECODE compiles every module of linpar at each start instead (0.05-0.1 s of `qa stats`), or
    each module changed since its bytecode was last written (a checkout that has just been merged)."""
    compiled = {k: v for k, v in env.items() if k != "PYTHONDONTWRITEBYTECODE"}
    compiled["PYTHONPYCACHEPREFIX"] = str(workdir / "pycache")
    return compiled


def at_most(name: str, value: float, unit: str, limit: float) -> Row:
    return Row(name, value, unit, f"<= {limit:g}", value <= limit)


def standard_recording(directory: Path) -> Path:
    """3 channels, 48 kHz, 16 periods of 65,536 samples plus one settle period (the issue's benchmark)."""
    from analysis.drivers import load_driver
    from analysis.multitone import design_multitone
    from analysis.recording.format import write_recording
    from analysis.synthesis import ChannelNoise, synthesize_recording

    path = directory / "standard"
    if (directory / "standard.wav").exists():
        return path
    driver = load_driver("paper")
    mt = design_multitone(48000, 65536, 5.0, 10000.0, rms=1.0)
    rec = synthesize_recording(driver.model(), driver.parameters, mt.waveform, mt.excited_bins, 48000, 16, 1,
                               ChannelNoise(1e-4, 1e-4, 1e-8), seed=1, driver={"name": "paper", "sd_m2": 0.0133})
    write_recording(path, rec)
    return path
