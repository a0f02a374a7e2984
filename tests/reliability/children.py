"""What the crash tests run in a child process, to be killed with SIGKILL at the moment that matters.

    python -c "from tests.reliability.children import measure; measure()" OUT NAME KIND PERIODS
        a journaled measurement on the in-process rig (KIND: simulated | serial | analog); prints
        "JOURNAL <path>" once the journal exists, "DONE <wav>" at the end
    python -c "from tests.reliability.children import store; store()" ROOT RECORDING RESULTS_JSON KILL_AT
        Archive.store of a recording, killing itself (SIGKILL) at the step KILL_AT of the store
"""
from __future__ import annotations

import json
import os
import signal
import sys
from pathlib import Path

STORE_STEPS = ("copy-recording", "results", "settings", "calibration", "record", "rename", "index-insert",
               "index-commit", "none")


def measure() -> None:
    from instruments.measurement.recovery import journal_path, run_journaled
    from tests.reliability.simulated_rig import Rig, plan

    out, name, kind, periods = Path(sys.argv[1]), sys.argv[2], sys.argv[3], int(sys.argv[4])
    rig = Rig(kind)

    def progress(p):
        if p.stage == "settling" and not progress.said:
            progress.said = True
            print("JOURNAL", journal_path(out, name), flush=True)
    progress.said = False
    outcome = run_journaled(plan(n_periods=periods), rig.audio, rig.laser, out, name=name, progress=progress,
                            analyse=False)
    print("DONE", outcome.recording_path, flush=True)


def _die() -> None:
    os.kill(os.getpid(), signal.SIGKILL)


def store() -> None:
    import shutil

    import analysis.archive.archive as archive_module
    from analysis.archive import Archive

    root, recording, results, kill_at = Path(sys.argv[1]), Path(sys.argv[2]), Path(sys.argv[3]), sys.argv[4]
    assert kill_at in STORE_STEPS, kill_at
    real_write, real_rename, real_insert, real_copy = (archive_module.write_atomic, archive_module.os.rename,
                                                       archive_module.insert, shutil.copyfile)

    def write_atomic(path, payload):
        step = {"results.json": "results", "settings.json": "settings", "calibration.json": "calibration",
                "measurement.json": "record"}[Path(path).name]
        if step == kill_at:
            real_write(Path(path).with_name(Path(path).name + ".half"), payload[: len(payload) // 2])
            _die()
        return real_write(path, payload)

    def copyfile(src, dst, **kwargs):
        if kill_at == "copy-recording" and str(dst).endswith(".json"):
            _die()                          # the .wav is copied, its sidecar not yet
        return real_copy(src, dst, **kwargs)

    def rename(src, dst):
        if kill_at == "rename":
            _die()
        return real_rename(src, dst)

    def insert(conn, record):
        real_insert(conn, record)
        if kill_at == "index-insert":
            _die()                          # inside the transaction: rolled back by the next open

    archive_module.write_atomic = write_atomic
    archive_module.shutil.copyfile = copyfile
    archive_module.os.rename = rename
    archive_module.insert = insert
    mid = Archive(root).store(recording, json.loads(results.read_text()), {"serial": f"kill-{kill_at}"})
    if kill_at == "index-commit":
        _die()                              # stored and indexed: a kill now must change nothing
    print("STORED", mid, flush=True)
