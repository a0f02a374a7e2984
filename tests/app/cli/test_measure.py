"""`linpar measure`: on the session's virtual rig, on a rig of its own that it starts and stops, its errors, and
the archive it stores into (on the in-process simulated sound card)."""
from __future__ import annotations

import json
import os
import shlex
import shutil
from datetime import datetime, timezone

import pytest

from analysis.pipeline import analyze_recording, result_json
from analysis.recording.format import read_recording
from app.cli import main
from tests.rig_xruns import measure_until_no_xrun

SHORT = ["--period", "16384", "--periods", "4"]


@pytest.fixture(autouse=True)
def archive_root(tmp_path_factory, monkeypatch):
    """The default archive of every test here: a fresh folder, never the user's."""
    root = tmp_path_factory.mktemp("archive") / "archive"
    monkeypatch.setenv("LINPAR_ARCHIVE", str(root))
    return root


@pytest.mark.rig
def test_measure_on_the_running_rig_writes_then_prints_what_analyze_prints(virtual_rig, tmp_path):
    rig = ["--rig-name", virtual_rig.name, "--runtime-dir", str(virtual_rig.paths.directory.parent)]
    code, out, err, folder = measure_until_no_xrun(
        lambda out_folder: ["measure", "--out", str(out_folder), "--name", "m", *rig, *SHORT, "--json"], tmp_path)
    assert code == 0, err
    printed = json.loads(out)
    assert set(printed) == {"parameters", "model", "validity", "archive"}
    stored = printed.pop("archive")
    assert f"stored in the archive {stored['root']} as {stored['id']}" in err
    assert printed["parameters"]["Bl"]["value"] == pytest.approx(5.23, rel=0.005)
    assert "delay-x" in printed["model"]["effects"]          # the serial laser's default
    assert sorted(p.name for p in folder.iterdir()) == ["m.json", "m.laser.npz", "m.wav"]
    assert f"wrote {folder / 'm.wav'}" in err and "starting the virtual rig" not in err
    # What was printed is `linpar analyze` of what is on disk: its model has delay-x too.
    again = result_json(analyze_recording(read_recording(folder / "m")))
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
    (["--periods", "1"], "found 1, expected a number of periods: a whole number from 2"),
])
def test_mistakes_are_one_line_errors_before_anything_starts(tmp_path, capsys, argv, message):
    code = main(["measure", "--out", str(tmp_path), "--rig-name", f"never-{os.getpid()}",
                 "--runtime-dir", str(tmp_path / "rigs"), *argv])
    err = capsys.readouterr().err
    assert code == 2
    assert message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "rigs").exists()                   # no rig was started


@pytest.fixture
def simulated_card(monkeypatch):
    """`linpar measure` on the in-process simulated sound card (no JACK), analog laser on its input."""
    import app.cli.devices as cli_devices
    from instruments.audio.simulated import SimulatedAudio
    monkeypatch.setattr(cli_devices, "open_devices", lambda args, stack: (
        SimulatedAudio(realtime=False, seed=1), None, {"name": "paper (simulated)", "sd_m2": 0.0133}))


MEASURED = datetime(2024, 5, 1, 12, 0, 0, tzinfo=timezone.utc)


@pytest.fixture
def measured_on_may_1st(monkeypatch):
    """`linpar measure`'s clock (only its own: the archive's stays true) says 2024-05-01 12:00 UTC."""
    import app.cli.measure as cli_measure

    class Clock(datetime):
        @classmethod
        def now(cls, tz=None):
            return MEASURED.astimezone(tz)
    monkeypatch.setattr(cli_measure, "datetime", Clock)


def measure(capsys, tmp_path, *extra, out="out"):
    code = main(["measure", "--out", str(tmp_path / out), "--name", "m", *SHORT, "--json", *extra])
    out, err = capsys.readouterr()
    return code, (json.loads(out) if out else None), err


def test_a_measurement_is_stored_in_the_archive_with_its_id_printed(simulated_card, measured_on_may_1st,
                                                                    tmp_path, capsys):
    from analysis.archive import Archive
    root = tmp_path / "qa-archive"
    code, printed, err = measure(capsys, tmp_path, "--archive-root", str(root), "--serial", "SN-7",
                                 "--operator", "ana")
    assert code == 0, err
    mid = printed["archive"]["id"]
    assert printed["archive"]["root"] == str(root) and f"stored in the archive {root} as {mid}" in err
    (entry,) = Archive(root).list()
    assert (entry.id, entry.serial, entry.operator, entry.driver) == (mid, "SN-7", "ana", "paper (simulated)")
    assert entry.measured_at == "2024-05-01T12:00:00Z" != entry.stored_at     # when measured, not when stored
    m = Archive(root).get(mid)
    assert m.path("recording").read_bytes() == (tmp_path / "out" / "m.wav").read_bytes()
    assert m.result().parameters["fs"].value == pytest.approx(printed["parameters"]["fs"]["value"])


def test_the_default_archive_and_no_archive(simulated_card, tmp_path, capsys, archive_root):
    from analysis.archive import Archive
    code, printed, err = measure(capsys, tmp_path, "--no-archive")
    assert code == 0, err
    assert "archive" not in printed and "stored in the archive" not in err and not archive_root.exists()
    code, printed, err = measure(capsys, tmp_path, "--name", "m2")      # $LINPAR_ARCHIVE, as default_root()
    assert code == 0, err
    assert [e.id for e in Archive(archive_root).list()] == [printed["archive"]["id"]]


def test_a_failed_store_keeps_the_recording_warns_and_exits_3(simulated_card, measured_on_may_1st, tmp_path,
                                                               capsys):
    not_a_folder = tmp_path / "archive is a file"
    not_a_folder.write_text("")
    code, printed, err = measure(capsys, tmp_path, "--archive-root", str(not_a_folder), "--serial", "SN 8",
                                 out="my out")
    assert code == 3, err
    assert printed["parameters"]["Bl"]["value"] > 0 and set(printed["archive"]) == {"error", "root"}
    assert "warning: not stored in the archive" in err and printed["archive"]["error"] in err
    assert (tmp_path / "my out" / "m.wav").is_file() and (tmp_path / "my out" / "m.json").is_file()
    # What the warning says to do, as a shell reads it (paths and texts with spaces), stores it.
    hint = shlex.split(err.split("store it later with: ")[1].splitlines()[0])
    root = tmp_path / "later on"
    assert hint[:4] == ["linpar", "archive", "store", str(tmp_path / "my out" / "m")]
    assert hint[-2:] == ["--root", str(not_a_folder)]
    assert "--model" in hint and main([*hint[1:-1], str(root)]) == 0
    assert capsys.readouterr().out.startswith("stored ")
    from analysis.archive import Archive
    (entry,) = Archive(root).list()
    assert entry.serial == "SN 8" and entry.effects == tuple(printed["model"]["effects"])
    # Dated when it was measured, not when the command was run.
    assert entry.measured_at == "2024-05-01T12:00:00Z" != entry.stored_at


def test_a_measurement_with_the_voltage_lead_off_is_judged_kept_and_stored_red(monkeypatch, tmp_path, capsys):
    """It used to end in a ZeroDivisionError traceback after writing the recording; then it was judged but not
    archived. A broken measurement is stored, judged red with its remedy, as the GUI stores it."""
    import app.cli.devices as cli_devices
    from analysis.archive import Archive
    from instruments.audio.simulated import SimulatedAudio
    from instruments.rig.engine import RigFaults
    monkeypatch.setattr(cli_devices, "open_devices", lambda args, stack: (
        SimulatedAudio(realtime=False, seed=1, faults=RigFaults(disconnected={"voltage"})), None,
        {"name": "paper (simulated)", "sd_m2": 0.0133}))
    root = tmp_path / "archive"
    code, printed, err = measure(capsys, tmp_path, "--archive-root", str(root), "--serial", "SN-9")
    assert code == 0 and "Traceback" not in err, err
    assert printed["validity"]["channels"]["voltage"]["findings"][0]["code"] == "no-signal"
    assert printed["parameters"]["RE"]["value"] is None and set(printed["archive"]) == {"id", "root"}
    assert f"as {printed['archive']['id']} (judged red: nothing could be fitted)" in err
    assert (tmp_path / "out" / "m.wav").is_file()
    (entry,) = Archive(root).list()
    assert entry.id == printed["archive"]["id"] and entry.validity == "red" and entry.serial == "SN-9"
    stored = Archive(root).get(entry.id).result()
    assert stored.not_fitted and stored.validity.as_json()["channels"]["voltage"]["findings"][0]["remedy"]
