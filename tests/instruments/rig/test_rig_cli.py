"""`linpar rig start|status|fault|stop` as a user runs them, and what they leave behind (nothing)."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.pace import paced

REPO = Path(__file__).resolve().parents[3]
pytestmark = pytest.mark.rig


def linpar(*args: str, timeout: float = 60) -> subprocess.CompletedProcess:
    """`linpar ARGS` in a process of its own; `timeout` (a hang's bound, for an idle machine) at the pace now."""
    return subprocess.run([sys.executable, "-m", "app.cli", *args], cwd=REPO, capture_output=True, text=True,
                          timeout=paced(timeout))


def processes_mentioning(word: str) -> list[str]:
    ps = subprocess.run(["ps", "-eo", "pid,stat,args"], capture_output=True, text=True, check=True).stdout
    return [line for line in ps.splitlines() if word in line and " Z" not in line and "ps -eo" not in line]


@pytest.fixture
def rig_name(virtual_rig, tmp_path):   # virtual_rig: the same skip when jackd is missing
    name = f"linpar-cli-{os.getpid()}"
    yield name, str(tmp_path)
    linpar("rig", "stop", "--name", name, "--runtime-dir", str(tmp_path))


def test_start_status_fault_stop_and_nothing_left_behind(rig_name):
    name, runtime = rig_name
    where = ["--name", name, "--runtime-dir", runtime]

    started = linpar("rig", "start", *where, "--fault", "clip=5")
    assert started.returncode == 0, started.stderr
    assert f"rig '{name}' running" in started.stdout and "JACK_DEFAULT_SERVER=" + name in started.stdout
    assert "clip=5" in started.stdout
    state = json.loads(Path(runtime, name, "state.json").read_text())
    assert state["jack_server"] == name and state["sample_rate"] == 48000
    assert state["laser_pty"].startswith("/dev/pts/") and Path(state["laser_pty"]).exists()   # the serial laser
    assert set(state["ports"]) == {"amplifier", "voltage-sense", "current-sense", "laser-analog"}
    assert len(processes_mentioning(f"jackd -n {name} ")) == 1
    # The rig is detached (its own session, not the CLI's) and jackd is its child.
    assert os.getsid(state["pid"]) == state["pid"]
    assert Path(f"/proc/{state['jackd_pid']}/stat").read_text().rsplit(")", 1)[1].split()[1] == str(state["pid"])

    again = linpar("rig", "start", *where)
    assert again.returncode == 0 and "already running" in again.stdout
    assert json.loads(Path(runtime, name, "state.json").read_text())["pid"] == state["pid"]

    fault = linpar("rig", "fault", *where, "disconnect=current")
    assert fault.returncode == 0 and "disconnect=current" in fault.stdout and "clip=5" in fault.stdout
    cleared = linpar("rig", "fault", *where, "--clear")
    assert cleared.returncode == 0 and "faults: none" in cleared.stdout

    status = linpar("rig", "status", *where, "--json")
    assert status.returncode == 0
    doc = json.loads(status.stdout)
    assert doc["running"] and doc["client_alive"] and doc["cycles"] > 0 and doc["faults"] == []

    stopped = linpar("rig", "stop", *where)
    assert stopped.returncode == 0 and "stopped" in stopped.stdout
    deadline = time.monotonic() + paced(10)
    while processes_mentioning(name) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert processes_mentioning(name) == []
    assert not any(Path("/dev/shm").glob(f"jack_{name}_*"))
    assert not Path(runtime, name, "state.json").exists()

    after = linpar("rig", "status", *where)
    assert after.returncode == 1 and "not running" in after.stdout
    assert linpar("rig", "stop", *where).returncode == 0


def test_a_bad_driver_fails_to_start_with_a_one_line_error(rig_name):
    name, runtime = rig_name
    result = linpar("rig", "start", "--name", name, "--runtime-dir", runtime, "--driver", "no-such-driver")
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and "no such driver file" in result.stderr
    assert processes_mentioning(f"jackd -n {name} ") == []


def test_fault_on_a_rig_that_is_not_running_says_so(tmp_path):
    result = linpar("rig", "fault", "--name", "nobody", "--runtime-dir", str(tmp_path), "--xrun")
    assert result.returncode == 2 and "not running" in result.stderr
