"""The rig dying under a capture: its JACK client killed, its JACK server killed.

The workstation side runs in a child process (``child_capture`` below): once
PortAudio's JACK server is gone, PortAudio cannot be closed or restarted in
that process (instruments/audio/portaudio.py), and the test process must keep
using the session rig. Each test starts a rig of its own, since it breaks it.
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

from instruments.rig.jackd import registered_servers
from instruments.rig.manager import find_rig, start_rig, stop_rig
from instruments.rig.state import pid_alive
from tests.pace import paced

REPO = Path(__file__).resolve().parents[3]
pytestmark = pytest.mark.rig


def child_capture() -> None:
    """In the child: capture from rig argv[1] (runtime dir argv[2]); print KEPT, then the outcome as JSON."""
    import numpy as np
    from instruments.audio import JACK_HOSTAPI, AudioDeviceChoice, AudioError, SoundDeviceAudio, capture, portaudio

    name, runtime_dir = sys.argv[1], Path(sys.argv[2])
    state = find_rig(name, runtime_dir).state
    portaudio.use_jack_server(state.jack_server)
    audio = SoundDeviceAudio(AudioDeviceChoice("system", JACK_HOSTAPI), state.workstation_calibration,
                             state.sample_rate, state.workstation_channel_map)
    wave = np.sin(2 * np.pi * 21 * np.arange(8192) / 8192)
    said = []

    def progress(kept, wanted):
        if kept >= 2 and not said:
            said.append(1)
            print("KEPT", flush=True)

    outcome = {}
    try:
        capture(audio, wave, n_periods=500, settle_periods=1, progress=progress)
    except AudioError as exc:
        outcome = {"error": str(exc), "kept": exc.partial.n_periods, "samples": int(exc.partial.voltage.size)}
    outcome["at"] = time.monotonic()
    print(json.dumps(outcome), flush=True)


def run_child_and(break_rig, name: str, runtime_dir: Path) -> tuple[dict, float, subprocess.Popen]:
    child = subprocess.Popen(
        [sys.executable, "-c", "from tests.instruments.rig.test_rig_faults import child_capture; child_capture()",
         name, str(runtime_dir)], cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        line = child.stdout.readline()
        assert line.strip() == "KEPT", f"child said {line!r}"
        broken_at = time.monotonic()
        break_rig()
        outcome = json.loads(child.stdout.readline())
        return outcome, broken_at, child
    except BaseException:
        child.kill()
        raise


@pytest.fixture
def own_rig(tmp_path, virtual_rig):   # virtual_rig: the same skip when jackd is missing
    name = f"linpar-fault-{os.getpid()}-{time.monotonic_ns() % 100000}"
    handle = start_rig(name, runtime_dir=tmp_path, seed=3)
    yield handle
    stop_rig(name, runtime_dir=tmp_path)


def test_killing_the_rigs_jack_client_ends_the_capture_within_2_s_keeping_the_periods(own_rig, tmp_path):
    outcome, broken_at, child = run_child_and(lambda: own_rig.command("kill-client"), own_rig.name, tmp_path)
    assert outcome["at"] - broken_at < paced(2.0)          # 2 s on an idle machine, at its pace now
    assert "exact zeros" in outcome["error"] and "JACK client" in outcome["error"]
    assert outcome["kept"] >= 2 and outcome["samples"] == outcome["kept"] * 8192
    assert child.wait(paced(30)) == 0
    status = own_rig.command("status")
    assert status["client_alive"] is False


def test_killing_the_jack_server_ends_the_capture_within_2_s_and_the_rig_goes_too(own_rig, tmp_path):
    jackd = own_rig.state.jackd_pid
    outcome, broken_at, child = run_child_and(lambda: os.kill(jackd, signal.SIGKILL), own_rig.name, tmp_path)
    assert outcome["at"] - broken_at < paced(2.0)          # 2 s on an idle machine, at its pace now
    assert "stopped by itself" in outcome["error"] or "no samples" in outcome["error"]
    assert outcome["kept"] >= 2
    # The child leaves its dead stream alone and exits normally (no hang, no abort in Pa_Terminate).
    assert child.wait(paced(30)) == 0
    # The rig notices its server is gone, cleans up and exits: nothing is left behind.
    deadline = time.monotonic() + paced(10)
    while pid_alive(own_rig.pid) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not pid_alive(own_rig.pid) and not pid_alive(jackd)
    assert find_rig(own_rig.name, tmp_path) is None
    # Nor in JACK's registry of servers, which has room for 8 and would keep a killed one's slot.
    assert own_rig.name not in [name for _, name in registered_servers()]
