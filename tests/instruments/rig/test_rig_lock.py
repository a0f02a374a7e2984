"""Two `linpar rig start` at the same moment (issue 31, class 5): one rig, each command a clear line, and `rig
status` and `rig stop` see it. Before the lock both saw no rig and started one: an internal error, and a rig
left running that neither status nor stop found."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from instruments.rig.state import RigPaths, pid_alive, read_pid

# Starts real JACK rigs: in the rig's unit of the suite, never beside another real-time rig (tests/scheduling.py).
pytestmark = pytest.mark.rig

REPO = Path(__file__).resolve().parents[3]


@pytest.mark.timeout(300)
def test_two_rig_starts_at_once_give_one_rig_that_stops(tmp_path):
    if shutil.which("jackd") is None:
        pytest.skip("jackd is not installed: install the Debian package jackd2 (tools/system-packages.sh)")
    name = f"linpar-race-{os.getpid()}"
    where = ["--name", name, "--runtime-dir", str(tmp_path)]

    def linpar(*args, wait=True):
        cmd = [sys.executable, "-m", "app.cli", "rig", *args, *where]
        if wait:
            return subprocess.run(cmd, cwd=REPO, capture_output=True, text=True, timeout=120)
        return subprocess.Popen(cmd, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    starts = [linpar("start", wait=False) for _ in range(2)]
    outcomes = [(p.wait(timeout=120), *p.communicate()) for p in starts]
    paths = RigPaths.for_name(name, tmp_path)
    pid = read_pid(paths)
    try:
        for code, out, err in outcomes:
            assert code == 0, err
            assert "Traceback" not in err and "internal error" not in err
        assert sum("already running" in out for _, out, _ in outcomes) == 1, outcomes
        rig_processes = subprocess.run(["pgrep", "-f", f"instruments.rig.server --name {name} "],
                                       capture_output=True, text=True).stdout.split()
        assert rig_processes == [str(pid)], rig_processes          # one rig, the one the files name
        assert linpar("status").returncode == 0
    finally:
        stopped = linpar("stop")
    assert stopped.returncode == 0 and "stopped" in stopped.stdout, stopped.stderr
    assert not pid_alive(pid)
