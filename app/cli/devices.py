"""The devices of `linpar measure` (both plans): the virtual rig or a sound card, the laser, progress lines.

What is started here (a virtual rig this command started, PortAudio's hold on
the rig's JACK server) is stopped by the caller's ExitStack.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
from contextlib import ExitStack

from analysis.bounds import SAMPLE_RATE
from app.cli import output
from instruments.measurement.errors import MeasurementError

LASER_ANALOG, LASER_NONE = "analog", "none"


def open_devices(args: argparse.Namespace, stack: ExitStack):
    """(audio, laser port or None, driver info); what is started here is stopped by ``stack``."""
    if args.rig == "soundcard":
        return _sound_card(args), _laser_choice(args.laser, None), {}
    from instruments.audio import portaudio
    from instruments.rig import manager
    from instruments.audio import AudioSpec, open_audio

    handle = manager.find_rig(args.rig_name, args.runtime_dir)
    if handle is None:
        say(f"starting the virtual rig {args.rig_name!r}")
        handle = manager.start_rig(args.rig_name, runtime_dir=args.runtime_dir)
        stack.callback(lambda: (say(f"stopping the virtual rig {args.rig_name!r}"),
                                manager.stop_rig(args.rig_name, args.runtime_dir)))
    audio = open_audio(AudioSpec("rig", options={"rig": handle}))
    stack.callback(portaudio.release)      # PortAudio lets go of the rig's JACK server before it may stop
    laser = _laser_choice(args.laser, handle.state.laser_pty)
    if args.laser is None and laser is None:
        raise MeasurementError(f"the rig {args.rig_name!r} has no serial laser (started with --no-laser): "
                               f"use --laser analog or --laser none")
    if laser is not None or args.laser == LASER_NONE:
        audio.channel_map = dataclasses.replace(audio.channel_map, laser_analog=None)
    state = handle.state
    return audio, laser, {"name": state.extra.get("driver_name", state.driver), "sd_m2": state.extra.get("sd_m2")}


def _laser_choice(option: str | None, rig_pty: str | None) -> str | None:
    if option in (LASER_ANALOG, LASER_NONE):
        return None
    return option or rig_pty


def laser_sensor(port: str | None):
    if port is None:
        return None
    from instruments.laser import LaserSpec, open_laser
    return open_laser(LaserSpec(port=port))


def _sound_card(args: argparse.Namespace):
    from instruments.audio import AudioSpec, Calibration, ChannelMap, list_devices, open_audio
    if args.calibration is None:
        raise MeasurementError("--rig soundcard needs --calibration FILE (the sound card's calibration and "
                               "channel map)")
    from analysis.files import read_text
    what = 'a JSON file {"calibration": {...}, "channel_map": {...}}'
    text = read_text(args.calibration, "config", what, MeasurementError)
    try:
        doc = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as exc:
        raise MeasurementError(f"{args.calibration}: not JSON ({exc}): expected {what}") from None
    if not isinstance(doc, dict):
        raise MeasurementError(f"{args.calibration}: expected {what}")
    calibration = Calibration.from_dict(doc.get("calibration", {}))
    channel_map = ChannelMap.from_dict(doc.get("channel_map", {}))
    if args.laser != LASER_ANALOG:
        channel_map = dataclasses.replace(channel_map, laser_analog=None)
    elif channel_map.laser_analog is None:
        raise MeasurementError(f"--laser analog: the channel map in {args.calibration} has no laser_analog input")
    devices = [d for d in list_devices() if d.full_duplex and (args.device is None or d.name == args.device)]
    if len(devices) != 1:
        names = ", ".join(str(d.choice) for d in list_devices() if d.full_duplex) or "none"
        what = f"no full-duplex sound card named {args.device!r}" if not devices else \
            f"{len(devices)} sound cards match; name one with --device"
        raise MeasurementError(f"{what}; full-duplex cards: {names}")
    rate = SAMPLE_RATE.check(doc.get("sample_rate", 48000), f"{args.calibration}: sample_rate", MeasurementError)
    return open_audio(AudioSpec("sounddevice", devices[0].choice, calibration, rate, channel_map))


class Progress:
    """One stderr line per stage and per kept period."""

    def __init__(self):
        self._last = None

    def __call__(self, p) -> None:      # instruments.measurement.runner.MeasurementProgress
        key = (p.stage, p.periods_kept)
        if key == self._last:
            return
        self._last = key
        periods = f" {p.periods_kept}/{p.periods_wanted} periods" if p.stage in ("averaging", "settling") else ""
        say(f"[{p.elapsed_s:5.1f} s] {p.stage}{periods}{': ' + p.message if p.message else ''}")


def say(text: str) -> None:
    output.say("measure", text)
