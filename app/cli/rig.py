"""`linpar rig start|stop|status|fault`: the virtual rig from the command line.

    linpar rig start [--name linpar] [--driver paper|FILE] [--model linear|nonlinear] [--effects IDS]
                     [--noise SPEC] [--fault SPEC]...
    linpar rig status [--name linpar] [--json]
    linpar rig fault [--name linpar] SPEC... | --clear | --xrun [SECONDS] | --kill-client
    linpar rig stop [--name linpar]

Exit codes: 0 done (start also when the rig was already running: start is
idempotent, so scripts may call it unconditionally; it says so on stdout);
status: 0 running, 1 not running; 2 on an error (one line on stderr).
"""
from __future__ import annotations

import argparse
from pathlib import Path

from analysis.bounds import XRUN_S
from app.cli.options import CliError, number
from app.cli.output import print_json

EXIT_OK, EXIT_NOT_RUNNING = 0, 1
# The rig server's --model choices (instruments/rig/server.py), spelled here so that the parser loads no rig code.
RIG_MODELS = ("linear", "nonlinear")

def _manager():
    """instruments.rig.manager, imported on use: it loads scipy, which plain `linpar` commands do not need."""
    from instruments.rig import manager
    return manager


def register(sub) -> None:
    rig = sub.add_parser("rig", help="the virtual rig: a simulated amplifier, driver and sensors on JACK")
    rig.set_defaults(run=run)
    actions = rig.add_subparsers(dest="rig_action", required=True, parser_class=type(rig))
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--name", default="linpar", help="rig name = its JACK server's name (default %(default)s)")
    common.add_argument("--runtime-dir", type=Path, help=argparse.SUPPRESS)

    start = actions.add_parser("start", parents=[common], help="start the rig in the background")
    start.add_argument("--driver", default="paper", help="driver name in resources/drivers, or a JSON file")
    start.add_argument("--model", choices=RIG_MODELS, default="linear",
                       help="how the rig simulates the driver: 'linear' (default), the small-signal model as "
                            "FIRs; 'nonlinear', Bl(x), Kms(x) and Le(x) integrated in the time domain, so that "
                            "distortion and level-dependent parameters appear at high drive (more CPU per cycle)")
    start.add_argument("--effects", metavar="IDS",
                       help="effect ids replacing the driver file's (comma-separated; linear model only)")
    start.add_argument("--noise", metavar="SPEC",
                       help="sensor noise rms, e.g. voltage=1e-4,current=1e-5,displacement=1e-8 (V, A, m)")
    start.add_argument("--fault", action="append", default=[], metavar="SPEC",
                       help="disconnect=voltage|current|displacement, clip=VOLTS, noise=FACTOR, "
                            "latency=SECONDS[,jitter=SECONDS] (the serial laser's samples late in packets, as "
                            "through a USB serial adapter; 0 to 1 s) (repeatable)")
    start.add_argument("--json", action="store_true", help="print the rig's state as JSON")

    status = actions.add_parser("status", parents=[common], help="say whether the rig runs, and how")
    status.add_argument("--json", action="store_true")

    fault = actions.add_parser("fault", parents=[common], help="change the faults of the running rig")
    fault.add_argument("specs", nargs="*", metavar="SPEC", help="faults to add (as for start --fault)")
    fault.add_argument("--clear", action="store_true", help="remove every fault first")
    fault.add_argument("--xrun", nargs="?", const=0.1, type=number(XRUN_S), metavar="SECONDS",
                       help="make one process cycle overrun by SECONDS (default 0.1)")
    fault.add_argument("--kill-client", action="store_true", help="close the rig's JACK client (a crash)")

    actions.add_parser("stop", parents=[common], help="stop the rig and its JACK server")


def run(args: argparse.Namespace) -> int:
    """Run one `linpar rig` action."""
    if args.rig_action == "start":
        return _start(args)
    if args.rig_action == "status":
        return _status(args)
    if args.rig_action == "fault":
        return _fault(args)
    if args.rig_action == "stop":
        stopped = _manager().stop_rig(args.name, args.runtime_dir)
        print(f"rig {args.name!r} stopped" if stopped else f"rig {args.name!r} is not running")
        return EXIT_OK
    raise AssertionError(f"unknown rig action {args.rig_action!r}")     # the parser allows no other


def _start(args) -> int:
    if args.model != "linear" and args.effects:
        # The nonlinear driver takes its small-signal model from the driver file's values.
        raise CliError(f"--effects applies to the linear model only, not to --model {args.model}")
    # A driver file or a spec that cannot be used is one line here, not a rig process that dies starting.
    from analysis.drivers import load_driver
    from instruments.rig.engine import RigFaults, RigNoise
    definition = load_driver(args.driver)
    if args.model == "nonlinear":         # its curves too (a short FIR: only the shapes are checked)
        from instruments.simulation.nonlinear_driver_file import nonlinear_driver_of
        nonlinear_driver_of(definition, 48000, fir_length=1024)
    RigFaults.parse(args.fault)
    if args.noise:
        RigNoise.parse(args.noise)
    handle = _manager().start_rig(args.name, args.driver, args.effects, args.fault, args.noise, args.runtime_dir,
                                  model=args.model)
    if args.json:
        print(handle.state.to_json())
        return EXIT_OK
    if handle.already_running:
        print(f"rig {args.name!r} is already running (pid {handle.pid}); not started again")
    status = _manager().rig_status(args.name, args.runtime_dir)
    print(format_status(status))
    return EXIT_OK


def _status(args) -> int:
    status = _manager().rig_status(args.name, args.runtime_dir)
    if args.json:
        print_json({"running": status is not None, **(status or {})}, indent=1)
    else:
        print(format_status(status) if status else f"rig {args.name!r} is not running")
    return EXIT_OK if status else EXIT_NOT_RUNNING


def _fault(args) -> int:
    from instruments.rig.engine import RigFaults
    RigFaults.parse(args.specs)          # a spec that cannot be used is one line here, before the rig is asked
    handle = _manager().find_rig(args.name, args.runtime_dir)
    if handle is None:
        raise _manager().RigError(f"rig {args.name!r} is not running (start it with 'linpar rig start')")
    if args.clear or args.specs:
        reply = handle.command("fault", set=list(args.specs), clear=bool(args.clear))
        print(f"faults: {', '.join(reply['faults']) or 'none'}")
    if args.xrun is not None:
        handle.command("xrun", seconds=args.xrun)
        print(f"one cycle will overrun by {args.xrun:g} s")
    if args.kill_client:
        handle.command("kill-client")
        print("the rig's JACK client is closed (stop and start the rig to get it back)")
    return EXIT_OK


def format_status(status: dict) -> str:
    state = status.get("state") or {}
    if not state:
        return f"rig process {status.get('pid')} does not answer: {status.get('error')}"
    cal = state["calibration"]
    connections = status.get("connections") or {}
    wired = ", ".join(f"{port} <-> {', '.join(peers)}" for port, peers in connections.items() if peers)
    lines = [
        f"rig {state['name']!r} running: pid {state['pid']}, jackd pid {state['jackd_pid']}",
        f"  JACK server   {state['jack_server']} (set JACK_DEFAULT_SERVER={state['jack_server']}), "
        f"{state['sample_rate']} Hz, {state['period_frames']} frames per cycle",
        f"  driver        {state['extra'].get('driver_name', state['driver'])} "
        f"[{', '.join(state['effects']) or 'textbook'}], {state['extra'].get('model', 'linear')} model, "
        f"FIR {state['fir_length']} taps",
        f"  faults        {', '.join(status.get('faults') or []) or 'none'}"
        f"{'' if status.get('client_alive', True) else '; JACK client killed'}",
        f"  calibration   {cal['volts_per_fs_out']:g} V/FS out, {cal['volts_per_fs_voltage_sense']:g} V/FS voltage, "
        f"{cal['volts_per_fs_current_sense'] / (cal['shunt_ohm'] * cal['current_amp_gain']):g} A/FS current, "
        f"{cal['volts_per_fs_laser'] * cal['laser_m_per_volt'] * 1e3:g} mm/FS laser",
        f"  channels      out {state['channel_map']['output']}; in voltage {state['channel_map']['voltage']}, "
        f"current {state['channel_map']['current']}, laser {state['channel_map']['laser_analog']}",
        f"  connections   {wired or 'none (no workstation stream open)'}",
        f"  cycles {status.get('cycles', 0)}, xruns {status.get('xruns', 0)}, "
        f"laser pty {state.get('laser_pty') or 'none'}",
    ]
    return "\n".join(lines)
