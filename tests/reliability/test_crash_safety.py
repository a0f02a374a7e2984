"""The workstation killed (SIGKILL) mid-measurement or mid-store: nothing measured is lost, nothing half-stored shows.

A measurement runs in a child process (tests/reliability/children.py) on
the in-process rig, journaled as `run_journaled` does it; the child is
killed once the first periods are on disk. On the next start
`find_unfinished` offers the measurement; `recover` turns it into a
recording (marked partial, "ended_by": "crash") that reads and analyses, or
`discard` drops it. A store into the archive is killed at each of its steps:
afterwards the archive shows either the whole measurement or nothing, and
`Archive.rebuild()` agrees with what the index said.
"""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from analysis.archive import Archive
from analysis.archive.archive import FOLDERS, RESULTS_FILE
from analysis.archive.results import results_document
from analysis.pipeline import analyze_recording
from analysis.recording.format import read_recording, write_recording
from instruments.measurement.recovery import RecoveryError, discard, find_unfinished, inspect, recover
from tests.builders import PAPER, REPO_ROOT, TYPICAL_NOISE, recording
from tests.pace import paced

pytestmark = pytest.mark.timeout(120)


def child(function: str, *args) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-c", f"from tests.reliability.children import {function}; "
                                                   f"{function}()", *map(str, args)],
                            cwd=REPO_ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def kill_when_periods_on_disk(out: Path, name: str, kind: str, periods_on_disk: int) -> Path:
    """Start a long measurement, SIGKILL it once the journal holds that many whole periods; the journal."""
    proc = child("measure", out, name, kind, 200)
    try:
        line = proc.stdout.readline()
        assert line.startswith("JOURNAL "), (line, proc.stderr.read() if proc.poll() is not None else "")
        journal = Path(line.split(" ", 1)[1].strip())
        assert find_unfinished(out) == []            # running: in use, not unfinished
        deadline = time.monotonic() + paced(30)
        while inspect(journal).periods < periods_on_disk:
            assert proc.poll() is None and time.monotonic() < deadline, proc.stderr.read()
            time.sleep(0.05)
        os.kill(proc.pid, signal.SIGKILL)
        assert proc.wait(10) == -signal.SIGKILL
        return journal
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.stdout.close()
        proc.stderr.close()


@pytest.mark.parametrize("kind", ["serial", "analog"])
def test_a_measurement_killed_mid_way_is_offered_on_the_next_start_and_recovers_into_a_recording(tmp_path, kind):
    journal = kill_when_periods_on_disk(tmp_path, "m", kind, 4)
    assert not (tmp_path / "m.wav").exists()         # the runner never got to write it
    (unfinished,) = find_unfinished(tmp_path)
    assert unfinished.journal == journal and unfinished.problem == "" and unfinished.periods >= 4
    assert unfinished.driver == PAPER.name and f"{unfinished.periods} whole period" in unfinished.describe()
    wav = recover(unfinished)
    assert wav == tmp_path / "m.wav" and find_unfinished(tmp_path) == [] and not journal.exists()
    rec = read_recording(wav)
    # With the serial laser, a period is kept once the laser's stream covers it (it lags the sound a little).
    assert rec.n_periods >= 3 and {c.signal for c in rec.channels} == {"voltage", "current", "displacement"}
    measurement = rec.extra["measurement"]
    assert measurement["partial"] is True and measurement["ended_by"] == "crash"
    assert "recovered" in measurement["message"]
    result = analyze_recording(rec)     # as `linpar analyze` reads them: with delay-x for the serial laser
    for name in ("RE", "fs", "Bl", "Mms"):
        assert result.parameters[name].value == pytest.approx(PAPER.parameters.get(name, result.parameters[name]
                                                                                    .value), rel=0.02), name
    if kind == "serial":
        assert (tmp_path / "m.laser.npz").is_file()     # the raw laser stream is kept too


def test_a_journal_killed_before_two_periods_says_so_and_can_be_discarded(tmp_path):
    journal = kill_when_periods_on_disk(tmp_path, "short", "analog", 0)
    (unfinished,) = find_unfinished(tmp_path)
    if unfinished.periods < 2:
        assert "too few" in unfinished.problem
        with pytest.raises(RecoveryError, match="too few"):
            recover(unfinished)
    discard(unfinished)
    assert not journal.exists() and find_unfinished(tmp_path) == [] and list(tmp_path.iterdir()) == []


# --- the archive ------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def stored_inputs(tmp_path_factory):
    base = tmp_path_factory.mktemp("inputs")
    rec = recording(noise=TYPICAL_NOISE, n_periods=3, seed=11)
    write_recording(base / "rec", rec)
    (base / "results.json").write_text(json.dumps(results_document(analyze_recording(rec), rec)))
    return base / "rec", base / "results.json"


# Killing it while it writes results, settings or calibration is the same case as while it writes
# measurement.json: a file of the hidden folder is half written. Each step costs a process start (~1 s).
@pytest.mark.parametrize("kill_at", ["copy-recording", "record", "rename", "index-insert", "index-commit"])
def test_a_store_killed_at_any_step_leaves_all_of_the_measurement_or_nothing(tmp_path, stored_inputs, kill_at):
    rec_path, results = stored_inputs
    root = tmp_path / "archive"
    archive = Archive(root)
    first = archive.store(rec_path, json.loads(results.read_text()), {"serial": "before"})
    proc = child("store", root, rec_path, results, kill_at)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == (0 if kill_at == "none" else -signal.SIGKILL), err
    stored = kill_at in ("index-insert", "index-commit", "none")     # the folder was renamed into place

    after = Archive(root)
    listed = {e.id: e for e in after.list()}
    visible = sorted(p.name for p in (root / FOLDERS).iterdir() if not p.name.startswith("."))
    assert first in listed and len(visible) == len(listed) == (2 if stored else 1)
    for mid in listed:                                  # whatever is listed is whole
        m = after.get(mid)
        assert read_recording(m.recording_path()).n_periods == 3
        assert m.result().parameters["RE"].value is not None
        assert {p.name for p in m.folder.iterdir()} >= {"measurement.json", RESULTS_FILE, "recording.wav",
                                                        "recording.json", "settings.json", "calibration.json"}
    report = Archive(root).rebuild()
    assert report.indexed == len(listed) and report.skipped == []
    assert {e.id for e in Archive(root).list()} == set(listed)
