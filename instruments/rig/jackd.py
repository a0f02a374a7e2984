"""The rig's own JACK server: ``jackd -n NAME -d dummy``, started and stopped by the rig process.

Its own name, so the rig never touches a JACK server the user runs for real
audio; the dummy backend, so it needs no sound card and keeps time with the
system clock. jackd runs as a child of the rig with a parent-death signal,
so it cannot outlive the rig even when the rig is killed.
"""
from __future__ import annotations

import ctypes
import os
import shutil
import signal
import subprocess
import time
from pathlib import Path
from typing import IO

from analysis.errors import LinparError
from instruments.audio.portaudio import jack_server_alive

CAPTURE_PORTS, PLAYBACK_PORTS = 4, 2
# Frames per JACK cycle: the deadline of every client's process callback, the rig's and the
# workstation's PortAudio stream alike. Both callbacks are Python and need the GIL; on a busy machine
# the thread holding it may wait for a CPU while the callback waits for it (the GIL has no priority
# inheritance). Measured with four CPU hogs on two cores and a Python-busy thread beside the
# measurement (docs/timing.md): 1024 frames (21 ms) ended 5 of 5 measurements of 40 periods with an
# xrun, 2048 (43 ms) and 4096 (85 ms) none and 1 of 5. 4096 leaves room for a busier machine still.
RIG_PERIOD = 4096
_PR_SET_PDEATHSIG = 1
# JACK2's server registry (common/shm.h): a header of 24 bytes, then MAX_SERVERS = 8 entries of
# {pid_t pid; char name[257]} padded to 264 bytes; the name is "jack-<uid>:<server name>:".
_REGISTRY = "jack-shm-registry"
_REGISTRY_MAGIC = b"KCAJ"
_HEADER, _ENTRY, _MAX_SERVERS = 24, 264, 8


class JackServerError(LinparError, RuntimeError):
    pass


def jackd_path() -> str:
    path = shutil.which("jackd")
    if path is None:
        raise JackServerError("jackd is not installed: install the Debian package jackd2 "
                              "(tools/system-packages.sh does it)")
    return path


def _die_with_parent() -> None:   # runs in the child between fork and exec
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)
    except OSError:
        pass


class JackServer:
    def __init__(self, name: str, sample_rate: int = 48000, period: int = RIG_PERIOD, log: IO | None = None):
        self.name, self.sample_rate, self.period = name, int(sample_rate), int(period)
        self._log = log
        self.process: subprocess.Popen | None = None

    @property
    def command(self) -> list[str]:
        return [jackd_path(), "-n", self.name, "-d", "dummy", "-r", str(self.sample_rate), "-p", str(self.period),
                "-C", str(CAPTURE_PORTS), "-P", str(PLAYBACK_PORTS)]

    def start(self, timeout: float = 10.0) -> None:
        if jack_server_alive(self.name):
            raise JackServerError(f"a JACK server named {self.name!r} is already running")
        remove_stale_files(self.name)
        if len(registered_servers()) >= _MAX_SERVERS:
            reclaim_stale_slots()
        env = dict(os.environ, JACK_NO_AUDIO_RESERVATION="1")
        self.process = subprocess.Popen(self.command, stdin=subprocess.DEVNULL, stdout=self._log or subprocess.DEVNULL,
                                        stderr=subprocess.STDOUT, env=env, preexec_fn=_die_with_parent)
        deadline = time.monotonic() + timeout
        while not jack_server_alive(self.name):
            if self.process.poll() is not None:
                raise JackServerError(f"jackd exited with code {self.process.returncode} while starting "
                                      f"(see the rig log)")
            if time.monotonic() > deadline:
                self.stop()
                raise JackServerError(f"jackd did not answer within {timeout:g} s")
            time.sleep(0.05)

    @property
    def pid(self) -> int | None:
        return self.process.pid if self.process else None

    def running(self) -> bool:
        return self.process is not None and self.process.poll() is None

    def stop(self, timeout: float = 5.0) -> None:
        """SIGTERM (jackd closes its clients and removes its socket), SIGKILL if it does not go."""
        process = self.process
        if process is None:
            return
        died_unclean = process.poll() is not None and process.returncode < 0 and \
            process.returncode != -signal.SIGTERM
        if process.poll() is None:
            process.terminate()
            try:
                process.wait(timeout)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait(timeout)
                died_unclean = True
        remove_stale_files(self.name)
        if died_unclean:
            reclaim_stale_slots(only=self.name)


def remove_stale_files(name: str) -> None:
    """The socket and semaphores a killed jackd of this name left in /dev/shm (only if no server answers)."""
    if jack_server_alive(name):
        return
    shm = Path(os.environ.get("JACK_TMP_DIR", "/dev/shm"))
    uid = os.getuid()
    for path in [shm / f"jack_{name}_{uid}_0", *shm.glob(f"jack_sem.{uid}_{name}_*")]:
        try:
            path.unlink()
        except OSError:
            pass


def registered_servers() -> list[tuple[int, str]]:
    """(pid, name) of this user's servers in JACK2's registry, dead ones included; [] if there is none."""
    try:
        with open(Path(os.environ.get("JACK_TMP_DIR", "/dev/shm")) / _REGISTRY, "rb") as f:
            data = f.read(_HEADER + _MAX_SERVERS * _ENTRY)
    except OSError:
        return []
    if data[:4] != _REGISTRY_MAGIC or len(data) < _HEADER + _MAX_SERVERS * _ENTRY:
        return []
    prefix = f"jack-{os.getuid()}:"
    servers = []
    for i in range(_MAX_SERVERS):
        entry = data[_HEADER + i * _ENTRY:_HEADER + (i + 1) * _ENTRY]
        pid = int.from_bytes(entry[:4], "little", signed=True)
        name = entry[4:].split(b"\0", 1)[0].decode("utf-8", "replace")
        if pid and name.startswith(prefix):
            servers.append((pid, name[len(prefix):].rstrip(":")))
    return servers


def reclaim_stale_slots(only: str | None = None) -> list[str]:
    """Free the registry slots of servers that died without unregistering (SIGKILL).

    JACK2 keeps at most 8 servers in its registry and frees a dead server's
    slot only when a server of the same name starts; a killed server of a
    unique name would hold its slot for good, and after 8 of them no JACK
    server can start ("Too many servers already active"). So start a dummy
    server of each dead name for a moment: it takes over the slot and gives
    it back when it stops cleanly. Returns the names reclaimed.
    """
    reclaimed = []
    for pid, name in registered_servers():
        if (only is not None and name != only) or _process_exists(pid) or jack_server_alive(name):
            continue
        probe = subprocess.Popen([jackd_path(), "-n", name, "-d", "dummy", "-r", "48000", "-p", str(RIG_PERIOD)],
                                 stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                 preexec_fn=_die_with_parent)
        deadline = time.monotonic() + 5.0
        while not jack_server_alive(name) and probe.poll() is None and time.monotonic() < deadline:
            time.sleep(0.02)
        if probe.poll() is None:
            probe.terminate()
            try:
                probe.wait(5.0)
            except subprocess.TimeoutExpired:
                probe.kill()
                probe.wait()
        remove_stale_files(name)
        reclaimed.append(name)
    return reclaimed


def _process_exists(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True
