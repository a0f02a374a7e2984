"""`linpar levels`: a level series from files or from the simulated nonlinear driver; one-line errors."""
import contextlib
import io
import json

import pytest

from analysis.recording.format import write_recording
from app.cli import main
from tests.builders import TYPICAL_NOISE, recording

# Two levels are enough for the command's plumbing; the physics is tested in tests/analysis.
LEVELS = "0.3,10"


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    """The simulated series written by `linpar levels --simulate --out`, and what it printed."""
    out_dir = tmp_path_factory.mktemp("levels")
    stdout, stderr = io.StringIO(), io.StringIO()      # capsys is per test; this runs once per module
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        code = main(["levels", "--simulate", "--levels", LEVELS, "--out", str(out_dir), "--json"])
    return code, stdout.getvalue(), stderr.getvalue(), out_dir


def test_simulate_writes_the_recordings_and_prints_the_series(simulated):
    code, out, err, out_dir = simulated
    assert code == 0, err
    assert sorted(p.name for p in out_dir.glob("*.wav")) == ["level-01-0.3V.wav", "level-02-10V.wav"]
    assert "simulating level 2/2: 10 V RMS" in err       # progress on stderr, stdout is the JSON
    doc = json.loads(out)
    assert doc["n_levels"] == 2
    small, large = doc["levels"]
    assert small["small_signal"] and not large["small_signal"]
    assert small["peak_displacement_m"] < large["peak_displacement_m"]
    assert large["drift"]["fs"]["percent"] < 0 < large["drift"]["Cms"]["percent"]
    assert doc["fs_vs_peak"]["fs_hz"] == [small["parameters"]["fs"]["value"], large["parameters"]["fs"]["value"]]


def test_files_give_the_same_series_as_a_text_table(capsys, simulated):
    _, out_json, _, out_dir = simulated
    files = sorted(str(p) for p in out_dir.glob("*.wav"))
    code, out, err = run(capsys, "levels", *reversed(files))
    assert code == 0, err
    lines = out.splitlines()
    assert lines[0] == "2 levels, sorted by peak excursion"
    assert "fs" in lines[1] and "[Hz]" in lines[2]
    assert lines[3].split()[:3] == ["0.3", f"{json.loads(out_json)['levels'][0]['peak_displacement_m'] * 1e3:.3f}",
                                    "yes"]
    assert lines[4].split()[0] == "10" and lines[4].split()[2] == "no"
    assert "drift relative to the smallest level, %" in out and "distortion-high" in out


def test_simulate_in_memory_keeps_nothing(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = run(capsys, "levels", "--simulate", "--levels", "0.3")
    assert code == 0, err
    assert "1 levels" in out and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("argv, message", [
    ((), "needs recordings at rising levels"),
    (("--simulate", "some.wav"), "not both"),
    (("some.wav", "--out", "d"), "--out: only with --simulate"),
    (("some.wav", "--levels", "1,2"), "--levels: only with --simulate"),
    (("--simulate", "--levels", "1,40"), "at most 16 V"),
    (("--simulate", "--levels", "a,b"), "volts RMS"),
    (("--simulate", "--levels", "1,-2"), "found -2, expected a drive level"),
    (("--simulate", "--model", "nonsense"), "--model"),
    (("missing.wav",), "missing.json"),
])
def test_errors_are_one_line_with_exit_2(capsys, argv, message):
    code, out, err = run(capsys, "levels", *argv)
    assert code == 2 and out == ""
    assert message in err and len(err.strip().splitlines()) == 1


def test_a_recording_without_laser_is_refused(capsys, tmp_path):
    path = tmp_path / "zonly"
    write_recording(path, recording(noise=TYPICAL_NOISE, n_periods=4, displacement=False))
    code, out, err = run(capsys, "levels", str(path) + ".wav")
    assert code == 2 and "no displacement channel" in err
