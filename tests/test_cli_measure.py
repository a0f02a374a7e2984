"""`linpar measure`: on the session's virtual rig, on a rig of its own that it starts and stops, and its errors."""
from __future__ import annotations

import json
import os
import shutil

import pytest

from analysis.pipeline import result_json
from analysis.recording import read_recording
from app.cli import main
from instruments.measurement.analysis_step import analyse_measurement
from instruments.measurement.runner import default_effects

SHORT = ["--period", "16384", "--periods", "4"]


@pytest.mark.rig
def test_measure_on_the_running_rig_writes_then_prints_what_analyze_prints(virtual_rig, tmp_path, capsys):
    rig = ["--rig-name", virtual_rig.name, "--runtime-dir", str(virtual_rig.paths.directory.parent)]
    code = main(["measure", "--out", str(tmp_path), "--name", "m", *rig, *SHORT, "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    printed = json.loads(out)
    assert set(printed) == {"parameters", "model", "validity"}
    assert printed["parameters"]["Bl"]["value"] == pytest.approx(5.23, rel=0.005)
    assert "delay-x" in printed["model"]["effects"]          # the serial laser's default
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.json", "m.laser.npz", "m.wav"]
    assert f"wrote {tmp_path / 'm.wav'}" in err and "starting the virtual rig" not in err
    # What was printed is the analysis of what is on disk.
    again = result_json(analyse_measurement(read_recording(tmp_path / "m"), effects=default_effects(True)))
    assert json.loads(json.dumps(again, default=lambda v: None)) == printed
    assert virtual_rig.command("ping")                        # the rig it did not start is still running


@pytest.mark.rig
def test_measure_starts_a_rig_when_none_runs_and_stops_it_after(virtual_rig, tmp_path, capsys):
    if shutil.which("jackd") is None:
        pytest.skip("jackd is not installed")
    from instruments.audio import portaudio
    from instruments.rig.manager import find_rig, stop_rig
    name, runtime = f"linpar-cli-{os.getpid()}", tmp_path / "rigs"
    try:
        code = main(["measure", "--out", str(tmp_path / "out"), "--name", "m", "--rig-name", name,
                     "--runtime-dir", str(runtime), "--laser", "analog", *SHORT])
    finally:
        stop_rig(name, runtime)                                   # only if the command left it running
        portaudio.use_jack_server(virtual_rig.state.jack_server)  # back to the session's rig
    out, err = capsys.readouterr()
    assert code == 0, err
    assert f"starting the virtual rig '{name}'" in err and f"stopping the virtual rig '{name}'" in err
    assert find_rig(name, runtime) is None
    assert out.splitlines()[0].split() == ["parameter", "value", "1-sigma", "unit"]
    assert "validity: green" in out and "model: lr2,creep-log " in out     # analog: no delay-x
    assert not (tmp_path / "out" / "m.laser.npz").exists() and (tmp_path / "out" / "m.wav").is_file()


@pytest.mark.parametrize("argv, message", [
    (["--period", "1000"], "power of two"),
    (["--rig", "soundcard"], "--calibration"),
    (["--rig", "soundcard", "--calibration", "/nonexistent/cal.json"], "cal.json"),
    (["--periods", "1"], "at least 2 periods"),
])
def test_mistakes_are_one_line_errors_before_anything_starts(tmp_path, capsys, argv, message):
    code = main(["measure", "--out", str(tmp_path), "--rig-name", f"never-{os.getpid()}",
                 "--runtime-dir", str(tmp_path / "rigs"), *argv])
    err = capsys.readouterr().err
    assert code == 2
    assert message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "rigs").exists()                   # no rig was started
