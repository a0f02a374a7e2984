"""Every `linpar` subcommand on every class of bad input: never a traceback, never an internal error.

Each file a command reads is replaced, one at a time, by something it cannot use: nothing there, a folder,
a FIFO, a device, an empty file, binary garbage, JSON with NaN, JSON nested a hundred thousand deep, a
symlink loop, a file of another kind, and a good file above its size limit. The command must end in
exit 2 with one line (or exit 0 where the input is optional, such as an archive root that holds nothing),
as tests/reliability/cli_outcome.py checks.
"""
from __future__ import annotations

import os
import shutil

import pytest

from analysis.recording.format import write_recording
from tests.builders import TYPICAL_NOISE, multitone, recording
from tests.reliability.cli_outcome import outcome

pytestmark = [pytest.mark.timeout(300), pytest.mark.filterwarnings("error::RuntimeWarning")]

BAD = ("missing", "folder", "fifo", "device", "empty", "garbage", "nan-json", "deep-json", "loop", "other-kind",
       "too-large")


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    """Good inputs of every kind, to be copied next to the bad one."""
    folder = tmp_path_factory.mktemp("good")
    write_recording(folder / "rec", recording(noise=TYPICAL_NOISE, n_periods=3, seed=8,
                                              mt=multitone(period_samples=4096, f_min=20.0)))
    (folder / "curve.zma").write_text("\n".join(f"{f:g} {5 + 20 / (1 + abs(f / 50 - 50 / f) * 4):g} 0"
                                                for f in (10, 20, 30, 40, 50, 60, 80, 100, 200, 500, 1000)))
    (folder / "limits.json").write_text('{"format": "linpar-limits/1", "parameters": {"RE": {"min": 1, '
                                        '"unit": "ohm"}}}')
    return folder


def make_bad(path, kind: str, good_file=None) -> str:
    """Put a bad `kind` at `path`; the --size-limit KIND to give (for "too-large"), else ""."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if kind == "missing":
        return ""
    if kind == "folder":
        path.mkdir()
    elif kind == "fifo":
        os.mkfifo(path)
    elif kind == "device":
        path.symlink_to("/dev/zero")
    elif kind == "empty":
        path.write_bytes(b"")
    elif kind == "garbage":
        path.write_bytes(bytes(range(256)) * 8)
    elif kind == "nan-json":
        path.write_text('{"format": NaN, "parameters": {"RE": {"min": Infinity}}, "value": -Infinity}')
    elif kind == "deep-json":
        path.write_text("[" * 100_000)
    elif kind == "loop":
        path.symlink_to(path)
    elif kind == "other-kind":
        path.write_text("10 5 0\n20 6 1\n")           # a curve where JSON or a WAV is expected
    elif kind == "too-large":
        shutil.copyfile(good_file, path)
    return ""


# command -> (argv with BAD where the bad file goes, the size-limit kind of that file, good file it stands for)
COMMANDS = {
    "analyze (sidecar)": (["analyze", "W/rec", "--json"], "W/rec.json", "sidecar", "rec.json"),
    "analyze (wav)": (["analyze", "W/rec", "--json"], "W/rec.wav", "wav", "rec.wav"),
    "analyze --impedance": (["analyze", "--impedance", "BAD", "--json"], "W/x.zma", "curve", "curve.zma"),
    "analyze --hx": (["analyze", "--impedance", "G/curve.zma", "--hx", "BAD"], "W/x.frd", "curve", "curve.zma"),
    "analyze --uiv": (["analyze", "--uiv", "BAD", "--json"], "W/x.csv", "curve", "curve.zma"),
    "analyze --limits": (["analyze", "G/rec", "--limits", "BAD", "--json"], "W/l.json", "config", "limits.json"),
    "diagnose": (["diagnose", "W/rec", "--json"], "W/rec.json", "sidecar", "rec.json"),
    "addedmass": (["addedmass", "G/curve.zma", "--mass", "10", "BAD"], "W/m.zma", "curve", "curve.zma"),
    "stats": (["stats", "G/rec", "W/rec"], "W/rec.wav", "wav", "rec.wav"),
    "levels": (["levels", "W/rec"], "W/rec.json", "sidecar", "rec.json"),
    "large-signal": (["large-signal", "W/rec", "--json"], "W/rec.json", "sidecar", "rec.json"),
    "large-signal (wav)": (["large-signal", "W/rec"], "W/rec.wav", "wav", "rec.wav"),
    "large-signal (plan summary)": (["large-signal", "BAD"], "W/p.large-signal.json", "config", "limits.json"),
    "report": (["report", "W/rec", "--html", "W/r.html"], "W/rec.json", "sidecar", "rec.json"),
    "report --limits": (["report", "G/rec", "--limits", "BAD", "--html", "W/r.html"], "W/l.json", "config",
                        "limits.json"),
    "export": (["export", "W/rec", "--csv", "W/p.csv"], "W/rec.wav", "wav", "rec.wav"),
    "archive store": (["archive", "store", "W/rec", "--root", "W/archive"], "W/rec.json", "sidecar", "rec.json"),
    "archive store --laser-stream": (["archive", "store", "G/rec", "--root", "W/archive", "--laser-stream", "BAD"],
                                     "W/laser.bin", "laser-stream", "rec.wav"),
    "archive list": (["archive", "list", "--root", "BAD", "--json"], "W/root", None, None),
    "archive rebuild": (["archive", "rebuild", "--root", "BAD"], "W/root", None, None),
    "archive show": (["archive", "show", "2024", "--root", "BAD"], "W/root", None, None),
    "qa limits --store": (["qa", "limits", "--root", "W/archive", "--store", "BAD"], "W/l.json", "config",
                          "limits.json"),
    "qa stats": (["qa", "stats", "--root", "BAD", "--json"], "W/root", None, None),
    "qa golden": (["qa", "golden", "--root", "BAD", "--json"], "W/root", None, None),
    "qa export": (["qa", "export", "--root", "BAD", "--csv", "W/out.csv"], "W/root", None, None),
    "recover": (["recover", "BAD"], "W/out", None, None),
    "measure --calibration": (["measure", "--rig", "soundcard", "--calibration", "BAD", "--out", "W/out"],
                              "W/cal.json", "config", "limits.json"),
    "rig start --driver": (["rig", "start", "--driver", "BAD", "--name", "never-started", "--runtime-dir", "W/rigs"],
                           "W/driver.json", "config", "limits.json"),
}


@pytest.mark.parametrize("kind", BAD)
@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_no_traceback_ever(good, tmp_path, capsys, command, kind):
    argv, bad_at, size_kind, stands_for = COMMANDS[command]
    if kind == "too-large" and size_kind is None:
        pytest.skip("a folder argument has no size")
    work = tmp_path / "w"
    work.mkdir()
    for name in ("rec.wav", "rec.json"):
        shutil.copyfile(good / name, work / name)
    bad = work / bad_at.removeprefix("W/")
    if bad.exists():
        bad.unlink()
    make_bad(bad, kind, good / stands_for if stands_for else None)
    names = {"BAD": str(bad)}
    argv = [names.get(a, a.replace("W/", f"{work}/").replace("G/", f"{good}/")) for a in argv]
    if kind == "too-large":
        argv = ["--size-limit", f"{size_kind}=16", *argv]
    outcome(capsys, argv)
