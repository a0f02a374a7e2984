"""Soak: many consecutive measurements in one process; does anything grow (memory, files, threads)?

    .venv/bin/python tools/soak.py [--count 200] [--rig virtual|simulated] [--period 8192] [--periods 4]
                                   [--no-analysis] [--no-archive] [--json FILE]

`make soak` runs it with the defaults (not part of `make test`: 200
measurements take a while). Each measurement is what the workstation does:
run_journaled (the runner with its crash journal) on the virtual rig's JACK
server with the serial laser on the rig's pty, the analysis, and a store
into an archive; the recording files are removed after the store so that
the disk does not fill. ``--rig simulated`` uses the in-process simulator in
real time instead (no JACK needed; chosen by itself when jackd is missing).

After WARMUP measurements (imports, caches, first allocations) the process's
resident memory (VmRSS), open file descriptors (/proc/self/fd) and threads
are taken as the baseline, then sampled every --every measurements and at
the end. It passes (exit 0) when the memory grew by at most --max-growth-mb
(default 50) and no file descriptor and no thread was left behind; else it
exits 1. A failed measurement is counted and reported, and the soak goes on.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

WARMUP = 3


def resources() -> dict:
    rss_kb = next(int(line.split()[1]) for line in Path("/proc/self/status").read_text().splitlines()
                  if line.startswith("VmRSS:"))
    fds = sorted(os.listdir("/proc/self/fd"))
    return {"rss_mb": rss_kb / 1024.0, "fds": len(fds), "threads": threading.active_count(),
            "tasks": len(os.listdir("/proc/self/task")), "fd_targets": _targets(fds)}


def _targets(fds) -> dict[str, int]:
    """How many descriptors point at each kind of thing (pipe, socket, pty, file), to name a leak."""
    kinds: dict[str, int] = {}
    for fd in fds:
        try:
            target = os.readlink(f"/proc/self/fd/{fd}")
        except OSError:
            continue
        kind = target.split(":")[0] if ":" in target else ("pty" if target.startswith("/dev/pts") else
                                                           "dev" if target.startswith("/dev") else "file")
        kinds[kind] = kinds.get(kind, 0) + 1
    return kinds


class VirtualRig:
    """The rig of its own: a JACK server, the driver, the serial laser emulator (stopped at the end)."""

    def __init__(self):
        from instruments.rig.manager import start_rig
        self.runtime = Path(tempfile.mkdtemp(prefix="linpar-soak-rig-"))
        self.name = f"linpar-soak-{os.getpid()}"
        self.handle = start_rig(self.name, runtime_dir=self.runtime, seed=1)

    def devices(self):
        import dataclasses

        from instruments.laser import LaserSpec, open_laser
        from instruments.audio import AudioSpec, open_audio
        audio = open_audio(AudioSpec("rig", options={"rig": self.handle}))
        audio.channel_map = dataclasses.replace(audio.channel_map, laser_analog=None)
        return audio, open_laser(LaserSpec(port=self.handle.command("laser")["laser_pty"]))

    def close(self):
        from instruments.audio import portaudio
        from instruments.rig.manager import stop_rig
        portaudio.release()
        stop_rig(self.name, runtime_dir=self.runtime)
        shutil.rmtree(self.runtime, ignore_errors=True)


class SimulatedRig:
    """SimulatedAudio in real time and a SimulatedLaser on its cone, new for every measurement."""

    def devices(self):
        from analysis.drivers import load_driver
        from instruments.rig.in_process import InProcessRig
        from instruments.simulation.linear_driver import LinearBlockDriver
        paper = load_driver("paper")
        driver = LinearBlockDriver(paper.model(), dict(paper.parameters), 48000, fir_length=65536)
        rig = InProcessRig(driver, "simulated", ppm=37.0, start_latency_s=0.02)
        return rig.audio, rig.laser

    def close(self):
        pass


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--count", type=int, default=200, help="measurements (default %(default)s)")
    parser.add_argument("--rig", choices=("virtual", "simulated"), default="virtual")
    parser.add_argument("--period", type=int, default=8192, help="samples per period (default %(default)s)")
    parser.add_argument("--periods", type=int, default=4, help="periods averaged (default %(default)s)")
    parser.add_argument("--no-analysis", action="store_true", help="measure and write only")
    parser.add_argument("--no-archive", action="store_true", help="do not store the measurements")
    parser.add_argument("--every", type=int, default=10, help="sample the resources every N measurements")
    parser.add_argument("--max-growth-mb", type=float, default=50.0)
    parser.add_argument("--json", type=Path, metavar="FILE", help="also write the summary as JSON")
    args = parser.parse_args(argv)

    from analysis.archive import Archive
    from instruments.measurement import MeasurementError, MeasurementPlan
    from instruments.measurement.recovery import find_unfinished, run_journaled

    rig_kind = args.rig
    if rig_kind == "virtual" and shutil.which("jackd") is None:
        print("soak: jackd is not installed: using the in-process simulator in real time", file=sys.stderr)
        rig_kind = "simulated"
    rig = VirtualRig() if rig_kind == "virtual" else SimulatedRig()
    work = Path(tempfile.mkdtemp(prefix="linpar-soak-"))
    archive = None if args.no_archive else Archive(work / "archive")
    plan = MeasurementPlan.from_template("woofer", period_samples=args.period, n_periods=args.periods, f_min_hz=5.0,
                                         driver={"name": "Paper driver (Table I)", "sd_m2": 0.0133})
    samples, failures, durations, baseline, unfinished = [], [], [], None, 0
    started = time.monotonic()
    try:
        for i in range(1, args.count + 1):
            t0 = time.monotonic()
            try:
                audio, laser = rig.devices()
                outcome = run_journaled(plan, audio, laser, work / "out", name=f"m{i:04d}",
                                        analyse=not args.no_analysis)
                if archive is not None and outcome.result is not None:
                    archive.store(outcome.recording_path, outcome.result, {"serial": f"soak-{i}"},
                                  laser_stream=outcome.raw_path)
            except (MeasurementError, OSError, ValueError, RuntimeError) as exc:
                failures.append(f"#{i}: {type(exc).__name__}: {exc}")
                print(f"soak: measurement {i} failed: {exc}", file=sys.stderr)
            finally:
                unfinished += len(find_unfinished(work / "out"))    # a journal left: a measurement lost
                shutil.rmtree(work / "out", ignore_errors=True)
            durations.append(time.monotonic() - t0)
            if i == WARMUP:
                baseline = resources()
            if baseline is not None and (i % args.every == 0 or i == args.count):
                now = resources()
                samples.append({"measurement": i, **{k: v for k, v in now.items() if k != "fd_targets"}})
                print(f"soak: {i}/{args.count}  rss {now['rss_mb']:.1f} MB ({now['rss_mb'] - baseline['rss_mb']:+.1f})"
                      f"  fds {now['fds']} ({now['fds'] - baseline['fds']:+d})  threads {now['threads']}"
                      f" ({now['threads'] - baseline['threads']:+d})  {durations[-1]:.1f} s/measurement"
                      f"  failures {len(failures)}", file=sys.stderr, flush=True)
        end = resources()                     # before the rig goes: its sockets and PortAudio's are still open
    finally:
        rig.close()
    base = baseline or end
    summary = {
        "rig": rig_kind, "count": args.count, "period_samples": args.period, "periods": args.periods,
        "analysis": not args.no_analysis, "archive": archive is not None, "wall_s": time.monotonic() - started,
        "s_per_measurement": {"mean": sum(durations) / len(durations), "max": max(durations)},
        "baseline_after_warmup": base, "end": end, "after_the_rig_stopped": resources(),
        "rss_growth_mb": end["rss_mb"] - base["rss_mb"], "fd_growth": end["fds"] - base["fds"],
        "thread_growth": end["threads"] - base["threads"], "failures": failures, "unfinished_journals": unfinished,
        "stored": len(archive.list()) if archive is not None else 0, "samples": samples,
    }
    shutil.rmtree(work, ignore_errors=True)
    ok = (summary["rss_growth_mb"] <= args.max_growth_mb and summary["fd_growth"] <= 0
          and summary["thread_growth"] <= 0)
    summary["verdict"] = "pass" if ok else "fail"
    print(json.dumps({k: v for k, v in summary.items() if k != "samples"}, indent=1))
    if args.json:
        args.json.write_text(json.dumps(summary, indent=1))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
