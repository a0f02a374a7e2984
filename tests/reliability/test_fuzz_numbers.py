"""Every numeric field of every input format, and every numeric option, over the extremes (issue 15, item 7).

0, -0, the smallest subnormal, tiny, huge, the largest float, NaN, +-inf, integers beyond the float range:
put in one field at a time of a recording's sidecar and WAV header, an imported curve, a limits file, an
archive's records, a calibration file, and typed into every numeric option. `linpar` run in-process may
then only end in exit 0 with strict JSON (no NaN, no Infinity), exit 2 with one line, or the QA verdict of
`analyze --limits`; never a traceback or an internal error (tests/reliability/cli_outcome.py checks it and
counts the outcomes). Hypothesis runs derandomised, with a bounded number of examples (FUZZ).
"""
from __future__ import annotations

import json
import math
import shutil
import struct
import sys

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from analysis.archive import Archive
from analysis.recording.format import write_recording
from tests.builders import TYPICAL_NOISE, multitone, recording
from tests.reliability.cli_outcome import outcome
from tests.reliability.fuzzing import FUZZ, FUZZ_FEW, FUZZ_MANY

# A numpy warning is noise on the user's terminal, and here the sign of a number that was let in unchecked.
pytestmark = [pytest.mark.timeout(120), pytest.mark.filterwarnings("error::RuntimeWarning")]

EXTREMES = [0.0, -0.0, 5e-324, -5e-324, 1e-310, 2.2250738585072014e-308, 1e-300, -1e-300, 1e-9, 1.0, -1.0, 1e9,
            1e300, -1e300, sys.float_info.max, -sys.float_info.max, math.nan, math.inf, -math.inf,
            10**400, -(10**400), 2**63, -(2**63)]
numbers = st.one_of(st.sampled_from(EXTREMES), st.floats(), st.integers(-(2**70), 2**70))
# How a user may type a number: the extremes as Python prints them, and text that is almost a number.
typed = st.one_of(numbers.map(repr), numbers.map(str),
                  st.sampled_from(["nan", "-inf", "1e999", "-1e999", "0x10", "1_0", "", " ", "1e", "--1", "+0",
                                   "١", "1,5", "4G", "1e-400"]))


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    """A short recording (3 periods of 4096 samples) that analyses in milliseconds; its path stem."""
    path = tmp_path_factory.mktemp("small") / "rec"
    write_recording(path, recording(noise=TYPICAL_NOISE, n_periods=3, seed=7,
                                    mt=multitone(period_samples=4096, f_min=20.0)))
    return path


def copy_recording(stem, folder):
    folder.mkdir(parents=True, exist_ok=True)
    for suffix in (".wav", ".json"):
        shutil.copyfile(stem.with_name(stem.name + suffix), folder / f"rec{suffix}")
    return folder / "rec"


def set_path(doc, path, value):
    for key in path[:-1]:
        doc = doc[key]
    doc[path[-1]] = value


# --- the recording: its sidecar's numbers, its WAV header, its samples --------------------------------------

SIDECAR_FIELDS = [("channels", 0, "scale"), ("channels", 1, "scale"), ("channels", 2, "scale"),
                  ("excitation", "period_samples"), ("excitation", "settle_periods"), ("excitation", "excited_bins", 0),
                  ("excitation", "excited_bins", -1), ("driver", "sd_m2"), ("displacement_max_hz",),
                  ("capture", "xruns"), ("capture", "laser_samples"), ("capture", "laser_out_of_range_share"),
                  ("capture", "full_scale_fraction", "voltage"), ("capture", "clipped_samples", "current"),
                  ("capture", "dropouts", "displacement")]


@FUZZ_MANY
@given(field=st.sampled_from(SIDECAR_FIELDS), value=numbers)
@example(field=("channels", 0, "scale"), value=5e-324)             # a silent voltage: ZeroDivisionError
@example(field=("driver", "sd_m2"), value=1e300)                   # OverflowError in the derived parameters
@example(field=("channels", 2, "scale"), value=0.0)
def test_a_number_in_the_sidecar(small, tmp_path_factory, capsys, field, value):
    stem = copy_recording(small, tmp_path_factory.mktemp("sidecar"))
    doc = json.loads(stem.with_suffix(".json").read_text())
    doc.setdefault("capture", {"full_scale_fraction": {}, "clipped_samples": {}, "dropouts": {}})
    if field[0] == "capture" and len(field) == 3:
        doc["capture"].setdefault(field[1], {})
    set_path(doc, field, value)
    stem.with_suffix(".json").write_text(json.dumps(doc))         # NaN and Infinity as Python writes them
    outcome(capsys, ["analyze", stem, "--json"])


# (offset in the WAV file, struct format) of the 'fmt ' chunk's numbers, after a 12-byte RIFF header and the
# 8-byte chunk header: format code, channels, sample rate, byte rate, block align, bits per sample.
WAV_FIELDS = {"channels": (22, "<H"), "sample rate": (24, "<I"), "byte rate": (28, "<I"), "block align": (32, "<H"),
              "bits": (34, "<H"), "RIFF size": (4, "<I")}


@FUZZ
@given(field=st.sampled_from(sorted(WAV_FIELDS)),
       value=st.sampled_from([0, 1, 2, 3, 999, 1000, 48000, 1_000_001, 2**15, 2**16 - 1, 2**31, 2**32 - 1]))
@example(field="sample rate", value=2**32 - 1)                       # 4.29 GHz was green
def test_a_number_in_the_wav_header(small, tmp_path_factory, capsys, field, value):
    stem = copy_recording(small, tmp_path_factory.mktemp("header"))
    wav = bytearray(stem.with_suffix(".wav").read_bytes())
    offset, fmt = WAV_FIELDS[field]
    wav[offset:offset + struct.calcsize(fmt)] = struct.pack(fmt, value & (0xFFFF if fmt == "<H" else 0xFFFFFFFF))
    stem.with_suffix(".wav").write_bytes(bytes(wav))
    outcome(capsys, ["analyze", stem, "--json"])


@FUZZ_FEW
@given(value=st.sampled_from([math.nan, math.inf, -math.inf, 3.4e38, -3.4e38, 1e-45, 0.0]),
       channel=st.integers(0, 2), where=st.sampled_from(["one", "all"]))
def test_a_sample_of_the_wav(small, tmp_path_factory, capsys, value, channel, where):
    stem = copy_recording(small, tmp_path_factory.mktemp("samples"))
    wav = bytearray(stem.with_suffix(".wav").read_bytes())
    data = wav.index(b"data") + 8
    frames = np.frombuffer(wav, dtype="<f4", offset=data).reshape(-1, 3).copy()
    if where == "one":
        frames[frames.shape[0] // 2, channel] = value
    else:
        frames[:, channel] = value
    wav[data:] = frames.tobytes()
    stem.with_suffix(".wav").write_bytes(bytes(wav))
    outcome(capsys, ["analyze", stem, "--json"])


# --- imported curves ----------------------------------------------------------------------------------------

def zma_rows() -> list[list[float]]:
    f = np.geomspace(10, 2000, 40)
    z = 5 + 20 / (1 + 1j * 4 * (f / 50 - 50 / f)) + 1j * 2 * np.pi * f * 3e-4
    return [[fi, abs(zi), math.degrees(np.angle(zi))] for fi, zi in zip(f, z)]


@FUZZ
@given(row=st.integers(0, 39), column=st.integers(0, 2), value=numbers)
@example(row=39, column=0, value=1e308)                              # frequencies near 1e308: OverflowError
def test_a_number_in_an_impedance_curve(tmp_path_factory, capsys, row, column, value):
    rows = zma_rows()
    rows[row][column] = value
    path = tmp_path_factory.mktemp("zma") / "curve.zma"
    path.write_text("\n".join(" ".join(repr(v) if isinstance(v, float) else str(v) for v in r) for r in rows))
    outcome(capsys, ["analyze", "--impedance", path, "--json"])


@FUZZ_FEW
@given(row=st.integers(0, 19), column=st.integers(0, 6), value=numbers)
def test_a_number_in_a_uiv_file(tmp_path_factory, capsys, row, column, value):
    f = np.geomspace(10, 2000, 20)
    u = np.ones(20, complex)
    z = 5 + 20 / (1 + 1j * 4 * (f / 50 - 50 / f))
    i = u / z
    v = 1j * 2 * np.pi * f * 1e-3 / (1 + 1j * f / 50) * u
    rows = [[f[k], u[k].real, u[k].imag, i[k].real, i[k].imag, v[k].real, v[k].imag] for k in range(20)]
    rows[row][column] = value
    path = tmp_path_factory.mktemp("uiv") / "spectra.csv"
    path.write_text("f_Hz,U_re,U_im,I_re,I_im,V_re,V_im\n" + "\n".join(",".join(map(str, r)) for r in rows))
    outcome(capsys, ["analyze", "--uiv", path, "--json"])


# --- a limits file ------------------------------------------------------------------------------------------

@FUZZ
@given(entry=st.sampled_from(["nominal", "tolerance", "min", "max"]), value=numbers,
       unit=st.sampled_from(["ohm", "Hz", "g", "mm/N", "-"]), parameter=st.sampled_from(["RE", "fs", "Mms", "Cms",
                                                                                         "Qts"]))
def test_a_number_in_a_limits_file(small, tmp_path_factory, capsys, entry, value, unit, parameter):
    limit = {"nominal": 1.0, "tolerance": "5%"} if entry in ("nominal", "tolerance") else {"min": 0.0}
    limit[entry] = value
    units = {"RE": "ohm", "fs": "Hz", "Mms": "g", "Cms": "mm/N", "Qts": "-"}
    path = tmp_path_factory.mktemp("limits") / "limits.json"
    path.write_text(json.dumps({"format": "linpar-limits/1", "parameters": {
        parameter: {**limit, "unit": units[parameter] if unit == "-" else unit}}}))
    outcome(capsys, ["analyze", small, "--limits", path, "--json"])


# --- an archive's records ------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def archive(small, tmp_path_factory):
    root = tmp_path_factory.mktemp("archive") / "archive"
    from analysis.pipeline import analyze_path
    ids = [Archive(root).store(small, analyze_path(small), {"serial": f"SN{i}"}) for i in range(2)]
    return root, ids


RECORD_FIELDS = [("key_parameters", "RE", "value"), ("key_parameters", "fs", "std"), ("sd_m2",)]
RESULTS_FIELDS = [("parameters", "RE", "value"), ("parameters", "RE", "std"), ("parameters", "Mms", "display_scale"),
                  ("model", "values", "RE"), ("model", "chi2_red", "impedance"), ("model", "aic"), ("sd_m2",),
                  ("curves", "impedance", "freqs_hz", 0), ("curves", "impedance", "measured_re", 3),
                  ("curves", "impedance", "std", 5)]


@FUZZ_FEW
@given(which=st.sampled_from(["measurement.json", "results.json"]), index=st.integers(0, 9), value=numbers,
       command=st.sampled_from([["list"], ["show", 0], ["compare", 0, 1], ["rebuild"]]))
def test_a_number_in_an_archive_record(archive, tmp_path_factory, capsys, which, index, value, command):
    root, ids = archive
    work = tmp_path_factory.mktemp("work") / "archive"
    shutil.copytree(root, work)
    folder = Archive(work).get(ids[0]).folder
    fields = RECORD_FIELDS if which == "measurement.json" else RESULTS_FIELDS
    doc = json.loads((folder / which).read_text())
    set_path(doc, fields[index % len(fields)], value)
    (folder / which).write_text(json.dumps(doc))
    (work / "index.sqlite").unlink()                  # rebuilt from the folders, the damaged one among them
    argv = ["archive", *[ids[a] if isinstance(a, int) else a for a in command], "--root", work, "--json"]
    outcome(capsys, argv)
    if which == "results.json":
        outcome(capsys, ["report", ids[0], "--root", work, "--html", work.parent / "r.html"])


# --- a sound card calibration file ---------------------------------------------------------------------------

@FUZZ_FEW
@given(key=st.sampled_from(["volts_per_fs_out", "volts_per_fs_voltage_sense", "shunt_ohm", "current_amp_gain",
                            "sample_rate", "voltage"]), value=numbers)
def test_a_number_in_a_calibration_file(tmp_path_factory, capsys, monkeypatch, key, value):
    import instruments.audio as audio
    monkeypatch.setattr(audio, "list_devices", lambda: [])       # no sound card: the file is read first
    doc = {"calibration": {"volts_per_fs_out": 10.0, "volts_per_fs_voltage_sense": 20.0,
                           "volts_per_fs_current_sense": 1.0, "shunt_ohm": 0.1, "current_amp_gain": 5.0},
           "channel_map": {"output": 0, "voltage": 0, "current": 1}, "sample_rate": 48000}
    if key == "sample_rate":
        doc[key] = value
    elif key == "voltage":
        doc["channel_map"][key] = value
    else:
        doc["calibration"][key] = value
    path = tmp_path_factory.mktemp("cal") / "cal.json"
    path.write_text(json.dumps(doc))
    folder = path.parent / "out"
    outcome(capsys, ["measure", "--rig", "soundcard", "--calibration", path, "--out", folder, "--no-archive"])


# --- every numeric option ------------------------------------------------------------------------------------

OPTIONS = {
    "analyze --sd": ["analyze", "REC", "--sd", "X", "--json"],
    "diagnose --sd": ["diagnose", "/nonexistent/rec", "--sd", "X"],
    "stats --sd": ["stats", "REC", "--sd", "X", "--json"],
    "levels --sd": ["levels", "/nonexistent/rec", "--sd", "X"],
    "levels --levels": ["levels", "/nonexistent/rec", "--levels", "1,X"],
    "analyze --fmin": ["analyze", "--impedance", "ZMA", "--fmin", "X", "--json"],
    "analyze --fmax": ["analyze", "--impedance", "ZMA", "--fmax", "X", "--json"],
    "analyze --hx-fmax": ["analyze", "--impedance", "ZMA", "--hx", "ZMA", "--hx-fmax", "X", "--json"],
    "addedmass --mass": ["addedmass", "ZMA", "--mass", "X", "ZMA", "--json"],
    "addedmass --sd": ["addedmass", "ZMA", "--mass", "10", "ZMA", "--sd", "X", "--json"],
    "archive list --limit": ["archive", "list", "--root", "ROOT", "--limit", "X", "--json"],
    "archive store --sd": ["archive", "store", "/nonexistent/rec", "--root", "ROOT", "--sd", "X"],
    "report --sd": ["report", "/nonexistent/rec", "--sd", "X", "--html", "OUT/r.html"],
    "export --sd": ["export", "/nonexistent/rec", "--sd", "X", "--csv", "OUT/p.csv"],
    "measure --level": ["measure", "--rig", "soundcard", "--out", "OUT", "--level", "X"],
    "measure --periods": ["measure", "--rig", "soundcard", "--out", "OUT", "--periods", "X"],
    "measure --period": ["measure", "--rig", "soundcard", "--out", "OUT", "--period", "X"],
    "measure --sd": ["measure", "--rig", "soundcard", "--out", "OUT", "--sd", "X"],
    "rig fault --xrun": ["rig", "fault", "--name", "never-started", "--runtime-dir", "OUT", "--xrun", "X"],
    "--size-limit": ["--size-limit", "wav=X", "analyze", "REC", "--json"],
}


@pytest.fixture(scope="module")
def zma(tmp_path_factory):
    path = tmp_path_factory.mktemp("zma") / "curve.zma"
    path.write_text("\n".join(" ".join(map(str, r)) for r in zma_rows()))
    return path


@FUZZ_MANY
@given(option=st.sampled_from(sorted(OPTIONS)), text=typed)
@example(option="analyze --sd", text="1e160")                       # OverflowError in the derived parameters
@example(option="measure --level", text="inf")
@example(option="archive list --limit", text="-1")
def test_every_numeric_option(small, zma, tmp_path_factory, capsys, option, text):
    out = tmp_path_factory.mktemp("opt")
    names = {"REC": str(small), "ZMA": str(zma), "ROOT": str(out / "archive"), "OUT": str(out)}
    argv = [text if a == "X" else a.replace("X", text) if a in ("1,X", "wav=X") else
            names.get(a, a.replace("OUT", str(out))) for a in OPTIONS[option]]
    # `measure --rig soundcard` without --calibration stops before any device is opened: only the option is tried.
    outcome(capsys, argv)
