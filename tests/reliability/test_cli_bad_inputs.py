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

import numpy as np
import pytest

from analysis.recording.format import write_recording
from app.cli import main
from tests.builders import TYPICAL_NOISE, multitone, recording
from tests.reliability.cli_outcome import OUTCOMES, outcome, strict_json

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


# --- values, not files: what issue 31's last pass added (a time without its offset, curves no driver gives) ---

def _zma(path, freqs, z) -> str:
    path.write_text("\n".join(f"{f:.9e} {abs(v):.9e} {np.degrees(np.angle(v)):.9e}" for f, v in zip(freqs, z)))
    return str(path)


def _driver_z(freqs):
    from analysis.effects import parse_effects
    from analysis.model.composed import Model
    from tests.builders import DRIVERS
    return Model(parse_effects("lr2,creep-log")).impedance(2j * np.pi * freqs, DRIVERS["midwoofer-6in"])


FREQS = np.logspace(1, np.log10(20e3), 300)
# name -> (how to make the file in `work`, the argv; BAD is the file) and what the run must end in
HOSTILE_VALUES = {
    "measured-at without an offset": (None, ["archive", "store", "G/rec", "--root", "W/archive",
                                             "--measured-at", "2026-05-04T09:30"], "refused"),
    "impedance with the current reversed": (lambda p: _zma(p, FREQS, -_driver_z(FREQS)), None, "red"),
    "impedance with a channel delay left in": (
        lambda p: _zma(p, FREQS, _driver_z(FREQS) * np.exp(-2j * np.pi * FREQS * 100e-6)), None, "red"),
    "a resistor given as a driver": (lambda p: _zma(p, FREQS, 8.0 + 2j * np.pi * FREQS * 0.3e-3), None, "red"),
    # The start values find no resonance in Re(Z) here (4.4 fs and up): refused before any fit, as it was.
    "an impedance starting above fs": (lambda p: _zma(p, FREQS[FREQS > 200], _driver_z(FREQS[FREQS > 200])), None,
                                       "refused"),
}


@pytest.mark.parametrize("name", sorted(HOSTILE_VALUES))
def test_values_no_driver_or_clock_gives_end_in_one_line_or_red(good, tmp_path, capsys, name):
    make, argv, expected = HOSTILE_VALUES[name]
    if make is not None:
        argv = ["analyze", "--impedance", make(tmp_path / "x.zma")] + (["--json"] if expected == "red" else [])
    argv = [a.replace("W/", f"{tmp_path}/").replace("G/", f"{good}/") for a in argv]
    if expected == "refused":
        assert outcome(capsys, argv) == "refused"
        return
    code = main(argv)
    out, err = capsys.readouterr()
    assert code == 0 and "Traceback" not in err, err
    doc = strict_json(out)
    assert doc["validity"]["overall"] == "red" and doc["parameters"]["fs"]["value"] is None, doc["validity"]
    OUTCOMES["exit 0, strict JSON, red: no driver's"] += 1
