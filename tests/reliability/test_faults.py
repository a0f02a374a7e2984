"""Faults during a measurement on the in-process rig: said in one line, what was recorded kept, and the next works.

Each test breaks one measurement in one way (the serial line: garbage, cut
frames, error-code floods, the pseudo-terminal hung up; the sound card: an
xrun, its server gone; the disk: full or read-only while saving), checks
what the workstation says and what it kept on disk, then measures again in
the same process with the same sound card: that measurement must complete.
The measurements run as `run_journaled` runs them (instruments/measurement/
recovery.py), so each also checks that a handled end leaves no journal.
"""
from __future__ import annotations

import errno
import json
import os
import tempfile
from pathlib import Path

import pytest

from analysis.recording.format import read_recording
from instruments.laser.ild1420 import ErrorPlan
from instruments.measurement import MeasurementError, MeasurementFailed
from instruments.measurement.recovery import JournalKept, find_unfinished, recover, run_journaled
from tests.builders import PAPER
from tests.reliability.simulated_rig import Rig, plan

pytestmark = pytest.mark.timeout(90)
# With the floods and cut frames below, Bl of these one-second measurements came out within 0.0015 % of the
# truth in 36 runs, idle and with both cores busy (docs/timing.md; +0.15 to +1.2 % while the floods were
# bridged); the bound leaves thirty times that.
BL_SPREAD = 0.0005


@pytest.fixture
def rigs():
    made = []

    def make(*args, **kwargs) -> Rig:
        made.append(Rig(*args, **kwargs))
        return made[-1]
    yield make
    for rig in made:
        rig.close()


def sidecar(path: Path) -> dict:
    return json.loads(path.with_suffix(".json").read_text())


def no_journal_and_no_litter(folder: Path) -> None:
    assert find_unfinished(folder) == []
    assert not [p for p in folder.iterdir() if p.name.startswith(".") or p.suffix in (".tmp", ".unfinished")]


def measure_again(rig: Rig, folder: Path, name: str = "again") -> None:
    """The workstation stays usable: the next measurement, same process, same sound card, completes."""
    laser = rig.new_laser() if rig.kind != "analog" else None
    outcome = run_journaled(plan(n_periods=2), rig.audio, laser, folder, name=name, analyse=False)
    assert outcome.ended_by == "complete" and not outcome.partial and outcome.periods == 2
    assert {c.signal for c in read_recording(outcome.recording_path).channels} == {"voltage", "current",
                                                                                 "displacement"}
    no_journal_and_no_litter(folder)


def kept_partial(info, folder: Path, ended_by: str, *words: str) -> dict:
    """The failure's message is one line that says what happened and where the data are; the data are there."""
    message = str(info.value)
    assert "\n" not in message and all(w in message for w in words), message
    outcome = info.value.outcome
    assert outcome.ended_by == ended_by and outcome.partial and str(outcome.recording_path) in message
    rec = read_recording(outcome.recording_path)
    assert rec.n_periods == outcome.periods >= 2
    doc = sidecar(outcome.recording_path)
    assert doc["measurement"]["partial"] is True and doc["measurement"]["ended_by"] == ended_by
    no_journal_and_no_litter(folder)
    return doc


# --- the serial line ------------------------------------------------------------------------------------

def test_garbage_cut_frames_and_error_floods_on_the_serial_line_are_skipped_counted_and_judged(tmp_path, rigs,
                                                                                                  record_property):
    floods = {k: 262076 for start in range(2000, 12000, 1000) for k in range(start, start + 30)}
    rig = rigs("serial", ErrorPlan(garbage_every=40, garbage_bytes=24, truncate_every=97, codes_at=floods, seed=3))
    outcome = run_journaled(plan(), rig.audio, rig.laser, tmp_path, name="m")
    assert outcome.ended_by == "complete" and outcome.periods == 4
    # The floods and cut frames are missing data, not bridged and averaged: no bias (it was +1 % with floods,
    # by an amount that depended on where they fell); what is left is the fit's spread (BL_SPREAD).
    record_property("bl_error", outcome.result.parameters["Bl"].value / PAPER.parameters["Bl"] - 1)
    assert outcome.result.parameters["Bl"].value == pytest.approx(PAPER.parameters["Bl"], rel=BL_SPREAD)
    capture = sidecar(outcome.recording_path)["capture"]
    gaps = capture["laser_gaps"]
    assert gaps["lost"] > 0                                   # the cut measurements, counted where validity looks
    assert 0 < capture["laser_error_counts"]["262076"] < 300      # the floods inside the recording, not averaged
    assert gaps["samples"] >= gaps["lost"] + capture["laser_error_counts"]["262076"]
    findings = {f["code"]: f for f in outcome.result.validity.as_json()["channels"]["displacement"]["findings"]}
    assert "lost on the line" in findings["laser-errors"]["message"] and "dropouts" not in findings
    assert rig.laser.stats.discarded_bytes > 0 and rig.laser.stats.incomplete_measurements > 0
    no_journal_and_no_litter(tmp_path)
    measure_again(rig, tmp_path)


def test_the_pseudo_terminal_hung_up_mid_measurement(tmp_path, rigs):
    rig = rigs("serial")

    def progress(p):
        if p.periods_kept >= 3 and rig.emulator.streaming:
            rig.emulator.disconnect()
    with pytest.raises(MeasurementFailed) as info:
        run_journaled(plan(n_periods=30), rig.audio, rig.laser, tmp_path, name="m", progress=progress)
    kept_partial(info, tmp_path, "laser", "laser link lost", "marked partial")
    measure_again(rig, tmp_path)


# --- the sound card -----------------------------------------------------------------------------------------

def test_an_xrun_ends_the_measurement_keeping_the_periods_before_it(tmp_path, rigs):
    rig = rigs("analog")                     # as with the serial laser: on_xrun "end"

    def progress(p):
        if p.periods_kept >= 2 and not progress.done:
            progress.done = True
            rig.audio.inject_xrun()
    progress.done = False
    with pytest.raises(MeasurementFailed) as info:
        run_journaled(plan(n_periods=30, on_xrun="end"), rig.audio, None, tmp_path, name="m", progress=progress)
    kept_partial(info, tmp_path, "xrun", "xrun")
    measure_again(rig, tmp_path)


def test_the_audio_server_gone_ends_the_measurement_within_seconds_keeping_the_periods(tmp_path, rigs):
    rig = rigs("analog")

    def progress(p):
        if p.periods_kept >= 2:
            rig.audio.stop_delivering()
    with pytest.raises(MeasurementFailed) as info:
        run_journaled(plan(n_periods=30), rig.audio, None, tmp_path, name="m", progress=progress)
    kept_partial(info, tmp_path, "audio", "sound card", "no samples")
    measure_again(rig, tmp_path)


# --- the disk -------------------------------------------------------------------------------------------------

def _enospc(*args, **kwargs):
    raise OSError(errno.ENOSPC, "No space left on device")


def test_a_full_disk_while_writing_the_recording_keeps_the_journal_and_says_where(tmp_path, rigs, monkeypatch):
    rig = rigs("analog")
    real_replace = os.replace

    def replace(src, dst, *args, **kwargs):
        if Path(dst).parent == tmp_path:                # the recording and the raw laser file, not the journal
            raise OSError(errno.ENOSPC, "No space left on device", str(dst))
        return real_replace(src, dst, *args, **kwargs)
    monkeypatch.setattr(os, "replace", replace)
    with pytest.raises(JournalKept) as info:
        run_journaled(plan(), rig.audio, None, tmp_path, name="m")
    message = str(info.value)
    assert "\n" not in message and "No space left" in message and "m.unfinished" in message
    assert info.value.errno == errno.ENOSPC
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.unfinished"]   # no half file, no temporary file
    monkeypatch.undo()                                  # room again
    (unfinished,) = find_unfinished(tmp_path)
    assert unfinished.periods == 4 and unfinished.problem == ""
    rec = read_recording(recover(unfinished))
    assert rec.n_periods == 4 and rec.extra["measurement"]["ended_by"] == "crash"
    measure_again(rig, tmp_path)


def test_a_full_disk_under_the_journal_does_not_disturb_the_measurement(tmp_path, rigs, monkeypatch):
    rig = rigs("analog")                               # no pty: os.write is the journal's alone here
    monkeypatch.setattr(os, "write", _enospc)
    outcome = run_journaled(plan(), rig.audio, None, tmp_path, name="m", analyse=False)
    assert outcome.ended_by == "complete" and read_recording(outcome.recording_path).n_periods == 4
    no_journal_and_no_litter(tmp_path)
    monkeypatch.undo()
    measure_again(rig, tmp_path)


def test_a_folder_that_cannot_be_written_is_refused_before_anything_plays(tmp_path, rigs, monkeypatch):
    rig = rigs("analog")
    folder = tmp_path / "out"
    folder.mkdir()
    real_mkdir = Path.mkdir

    def mkdir(self, *args, **kwargs):
        if self.parent == folder:
            raise OSError(errno.EROFS, "Read-only file system", str(self))
        return real_mkdir(self, *args, **kwargs)
    monkeypatch.setattr(Path, "mkdir", mkdir)
    with pytest.raises(MeasurementError) as info:
        run_journaled(plan(), rig.audio, None, folder, name="m")
    assert "Read-only file system" in str(info.value) and "nothing was measured" in str(info.value)
    assert rig.audio.counters().frames_out == 0 and list(folder.iterdir()) == []
    monkeypatch.undo()
    measure_again(rig, folder)


@pytest.mark.skipif(os.geteuid() == 0, reason="file permissions do not bind root: the EROFS test above stands in")
def test_a_read_only_folder_is_refused_before_anything_plays(tmp_path, rigs):
    rig = rigs("analog")
    folder = tmp_path / "out"
    folder.mkdir(mode=0o555)
    try:
        with pytest.raises(MeasurementError, match="nothing was measured"):
            run_journaled(plan(), rig.audio, None, folder, name="m")
    finally:
        folder.chmod(0o755)
    measure_again(rig, folder)


def test_a_read_only_disk_mid_measurement_keeps_the_journal(tmp_path, rigs, monkeypatch):
    rig = rigs("analog")
    real_mkstemp = tempfile.mkstemp

    def mkstemp(*args, dir=None, **kwargs):
        if dir is not None and Path(dir) == tmp_path:
            raise OSError(errno.EROFS, "Read-only file system", str(dir))
        return real_mkstemp(*args, dir=dir, **kwargs)
    monkeypatch.setattr(tempfile, "mkstemp", mkstemp)
    with pytest.raises(JournalKept, match="Read-only file system"):
        run_journaled(plan(), rig.audio, None, tmp_path, name="m")
    monkeypatch.undo()
    (unfinished,) = find_unfinished(tmp_path)
    assert read_recording(recover(unfinished)).n_periods == 4
    measure_again(rig, tmp_path)
