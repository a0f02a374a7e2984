"""The rig process: ``python -m instruments.rig.server --name linpar --driver paper [...]``.

It starts its own JACK server (jackd -n NAME -d dummy, 4 capture and 2
playback ports), the JACK client "linpar-rig" around a RigEngine, and the
command socket; then writes state.json (instruments.rig.state) to say it is
ready. It runs until SIGTERM/SIGINT, a "stop" command, or the death of its
JACK server; then it removes its state, closes its client, stops jackd and
exits. Normally started by ``linpar rig start`` (instruments.rig.manager),
which detaches it into its own process group.
"""
from __future__ import annotations

import argparse
import gc
import os
import signal
import sys
import threading
import time
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any, Sequence

from analysis.files import write_atomic
from instruments.rig.control import ControlServer
from instruments.rig.engine import RIG_CALIBRATION, RIG_CHANNEL_MAP, RigEngine, RigFaults, RigNoise, default_driver
from instruments.rig.jack_rig import DEFAULT_CLIENT_PATTERN, PLAYED_CHANNEL, JackRig
from instruments.rig.jackd import RIG_PERIOD, JackServer
from instruments.rig.laser_feed import DisplacementFeed, RigLaser
from instruments.rig.state import DEFAULT_NAME, RigPaths, RigState

EXIT_OK, EXIT_FAILED, EXIT_SERVER_DIED = 0, 1, 3


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m instruments.rig.server", description=__doc__.splitlines()[0])
    p.add_argument("--name", default=DEFAULT_NAME, help="rig name = JACK server name (default %(default)s)")
    p.add_argument("--driver", default="paper", help="driver name in resources/drivers or a JSON file")
    p.add_argument("--effects", help="effect ids replacing the driver file's (comma-separated)")
    p.add_argument("--noise", help="sensor noise, e.g. voltage=1e-4,current=1e-5,displacement=1e-8 (V, A, m rms)")
    p.add_argument("--fault", action="append", default=[],
                   help="disconnect=voltage|current|displacement, clip=VOLTS, noise=FACTOR (repeatable)")
    p.add_argument("--sample-rate", type=int, default=48000)
    p.add_argument("--period", type=int, default=RIG_PERIOD, help="JACK period (frames per cycle, default %(default)s)")
    p.add_argument("--runtime-dir", type=Path, help="folder holding the rig folders (default: see state.py)")
    p.add_argument("--client-pattern", default=DEFAULT_CLIENT_PATTERN,
                   help="regular expression of the JACK client names wired to the rig (default %(default)s)")
    p.add_argument("--seed", type=int, help="noise seed (default: random)")
    p.add_argument("--model", choices=("linear", "nonlinear"), default="linear",
                   help="the driver's simulation: linear FIRs, or Bl(x), Kms(x), Le(x) in the time domain "
                        "(about a tenth of a cycle)")
    p.add_argument("--no-laser", action="store_true", help="no serial laser emulator on a pty")
    p.add_argument("--laser-ppm", type=float, default=37.0, help="the serial laser's clock error (ppm)")
    p.add_argument("--laser-latency", type=float, default=0.02,
                   help="seconds from the laser's output switched on to its first measurement")
    p.add_argument("--laser-noise", type=float, default=0.0, help="the serial laser's noise, m rms")
    return p


class OrderedJackRig(JackRig):
    """JackRig that wires a workstation only once its played channel exists.

    PortAudio registers its capture ports before its playback ports; wired as
    they appear, the links rig -> workstation could be made before workstation
    -> rig. JACK makes the link that closes a loop its "feedback" link, so the
    order decides whether the rig runs before or after the workstation in a
    cycle: one period (85 ms by default) of difference in when a displacement reaches the
    workstation, which the serial laser's time base (laser_feed.py) must know.
    Played channel first, always: the rig runs after the workstation.
    """

    def _workstation_ports(self):
        return {name: ports for name, ports in super()._workstation_ports().items()
                if len(ports[1]) > PLAYED_CHANNEL}


class RigProcess:
    def __init__(self, args: argparse.Namespace):
        self.args = args
        self.paths = RigPaths.for_name(args.name, args.runtime_dir)
        self.stop_requested = threading.Event()
        self.exit_code = EXIT_OK
        self.state: RigState | None = None
        self.jackd: JackServer | None = None
        self.rig: JackRig | None = None
        self.control: ControlServer | None = None
        self.laser: RigLaser | None = None
        self._state_lock = threading.Lock()

    def run(self) -> int:
        args, paths = self.args, self.paths
        paths.ensure()
        write_atomic(paths.pid_file, f"{os.getpid()}\n")
        try:
            faults = RigFaults.parse(args.fault)
            noise = RigNoise.parse(args.noise) if args.noise else RigNoise()
            driver, definition = default_driver(args.driver, args.sample_rate, args.effects)
            if args.model == "nonlinear":
                from instruments.simulation.nonlinear_driver_file import nonlinear_driver_of
                driver = nonlinear_driver_of(definition, args.sample_rate)
            engine = RigEngine(driver, RIG_CALIBRATION, noise, faults, seed=args.seed)
            feed = DisplacementFeed(args.sample_rate)
            if not args.no_laser:
                engine.displacement_sinks.append(feed.sink)
            # jackd first, from the main thread: its parent-death signal follows this thread.
            self.jackd = JackServer(args.name, args.sample_rate, args.period, log=sys.stdout)
            self.jackd.start()
            self.rig = OrderedJackRig(engine, args.name, args.client_pattern, on_shutdown=self._server_gone)
            client = self.rig.client
            # The cycle's start, not the moment the sink runs (after the driver's FIRs): see laser_feed.
            feed.cycle_clock = lambda: time.monotonic() - client.frames_since_cycle_start / args.sample_rate
            self.rig.activate()
            laser_pty = None
            if not args.no_laser:
                self.laser = RigLaser(feed, args.laser_ppm, args.laser_latency, args.laser_noise,
                                      **faults.laser_link)
                laser_pty = self.laser.plug()
            self.control = ControlServer(paths.control_socket, self.handle)
            self.control.start()
            self.state = RigState(
                name=args.name, jack_server=args.name, pid=os.getpid(), jackd_pid=self.jackd.pid,
                sample_rate=args.sample_rate, period_frames=args.period, driver=str(args.driver),
                effects=tuple(driver.model.effect_ids), fir_length=driver.fir_length,
                faults=tuple(faults.describe()), noise=asdict(noise), calibration=RIG_CALIBRATION.to_dict(),
                channel_map=RIG_CHANNEL_MAP.to_dict(), ports=self.rig.port_names,
                client_pattern=args.client_pattern, laser_pty=laser_pty,
                extra={"driver_name": definition.name, "sd_m2": definition.sd_m2, "model": args.model,
                       "laser": None if self.laser is None else self.laser.settings})
            # What start-up made lives as long as the rig: out of the cyclic collector's way, or its first full
            # collection (~10 ms of held GIL, more under load) makes the JACK callback miss a cycle.
            gc.collect()
            gc.freeze()
            self._write_state()
            print(f"rig {args.name!r} ready: driver {definition.name}, JACK server {args.name!r}", flush=True)
            while not self.stop_requested.wait(0.5):
                if not self.jackd.running():
                    print("jackd exited", flush=True)
                    self.exit_code = EXIT_SERVER_DIED
                    break
        except Exception as exc:
            print(f"rig failed: {type(exc).__name__}: {exc}", flush=True)
            self.exit_code = EXIT_FAILED
        finally:
            self.shutdown()
        return self.exit_code

    def _server_gone(self, reason: str) -> None:
        """JACK closed the rig's client: the server died (then the rig goes too) or dropped the client."""
        if self.jackd is not None and self.jackd.running():
            # A client that overran too long is zombified by the server: the rig stays, without audio,
            # as after kill-client, so that status can say so.
            print(f"JACK dropped the rig's client: {reason}", flush=True)
            return
        print(f"JACK server shut down: {reason}", flush=True)
        self.exit_code = EXIT_SERVER_DIED
        self.stop_requested.set()

    def _write_state(self) -> None:
        with self._state_lock:
            write_atomic(self.paths.state_file, self.state.to_json())

    def _update_state(self, **changes: Any) -> None:
        with self._state_lock:
            self.state = replace(self.state, **changes)
            write_atomic(self.paths.state_file, self.state.to_json())

    def handle(self, request: dict[str, Any]) -> dict[str, Any]:
        cmd, rig = request.get("cmd"), self.rig
        if cmd == "ping":
            return {"pid": os.getpid()}
        if cmd == "status":
            return self.status()
        if cmd == "fault":
            faults = RigFaults() if request.get("clear") else rig.engine.faults
            faults = RigFaults.parse([faults_text(faults), *request.get("set", [])])
            rig.engine.faults = faults
            if self.laser is not None:          # the link's lateness: from the laser's next switch-on
                self.laser.configure(**faults.laser_link)
            self._update_state(faults=tuple(faults.describe()))
            return {"faults": faults.describe()}
        if cmd == "xrun":
            rig.inject_xrun(float(request.get("seconds", 0.1)))
            return {}
        if cmd == "kill-client":
            rig.kill_client()
            return {}
        if cmd == "laser-pty":
            self._update_state(laser_pty=request.get("path"))
            return {}
        if cmd == "laser":
            return self._laser_command(request)
        if cmd == "stop":
            self.stop_requested.set()
            return {}
        raise ValueError(f"unknown command {cmd!r}")

    def _laser_command(self, request: dict[str, Any]) -> dict[str, Any]:
        """{"cmd": "laser", "set": {"clock_ppm": .., "start_latency_s": .., "noise_m": ..}} | "unplug" | "plug"."""
        if self.laser is None:
            raise ValueError("this rig has no serial laser (started with --no-laser)")
        settings = self.laser.configure(**request.get("set", {}))
        if request.get("unplug"):
            self.laser.unplug()
        if request.get("plug"):
            self.laser.plug()
        self._update_state(laser_pty=self.laser.port_path, extra={**self.state.extra, "laser": settings})
        return {"laser_pty": self.laser.port_path, "laser": settings, "time_base": self.laser.feed.time_base()}

    def status(self) -> dict[str, Any]:
        rig = self.rig
        engine = rig.engine
        return {
            "state": json_state(self.state), "client_alive": rig.alive, "cycles": rig.cycles, "xruns": rig.xruns,
            "connections": rig.connections() if rig.alive else {}, "faults": engine.faults.describe(),
            "callback_errors": rig.callback_errors, "last_error": rig.last_error,
            "peak_terminal_volts": engine.peak_terminal_volts, "sink_errors": engine.sink_errors,
            # When the laser's time base started again (the schedule moved): what a misplaced stream points to.
            "laser_time_base": None if self.laser is None else self.laser.feed.time_base(),
        }

    def shutdown(self) -> None:
        self.paths.state_file.unlink(missing_ok=True)   # first: nobody may start using a dying rig
        if self.control is not None:
            self.control.close()
        if self.laser is not None:
            self.laser.close()
        if self.rig is not None:
            self.rig.close()
        if self.jackd is not None:
            self.jackd.stop()
        self.paths.pid_file.unlink(missing_ok=True)


def faults_text(faults: RigFaults) -> str:
    return ",".join(faults.describe())


def json_state(state: RigState | None) -> dict[str, Any] | None:
    import json
    return None if state is None else json.loads(state.to_json())


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    # The JACK callback is Python: it must get the GIL within a cycle while the laser emulator's threads run
    # (the default 5 ms per holder let it miss cycles).
    sys.setswitchinterval(0.001)
    process = RigProcess(args)
    for sig in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
        signal.signal(sig, lambda *_: process.stop_requested.set())
    started = time.monotonic()
    code = process.run()
    print(f"rig {args.name!r} stopped after {time.monotonic() - started:.1f} s (exit {code})", flush=True)
    return code


if __name__ == "__main__":
    sys.exit(main())
