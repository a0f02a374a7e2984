"""Start, find and stop rig processes (what `linpar rig` and the test fixture use).

``start_rig`` launches ``python -m instruments.rig.server`` detached: its own
session and process group, stdin closed, output to rig.log. It returns once
the rig has written its state and answers on its socket. Starting a rig whose
name is already running returns the running one (``already_running``).
``stop_rig`` asks the rig to stop (it closes its JACK client and stops its
jackd), waits, and kills the whole process group only if it does not go.
"""
from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator, Sequence

from analysis.errors import LinparError
from analysis.file_lock import take
from instruments.rig.control import ControlError, send_command
from instruments.rig.state import DEFAULT_NAME, RigPaths, RigState, pid_alive, read_pid, read_state

MODELS = ("linear", "nonlinear")     # the rig server's --model choices
START_TIMEOUT_S = 20.0               # how long a start waits for the rig to answer
LOCK_MARGIN_S = 15.0                 # beyond it, how long a second start or a stop waits for the first's lock


class RigError(LinparError, RuntimeError):
    """The rig could not be started or stopped; one line for the user."""


@dataclass(frozen=True)
class RigHandle:
    name: str
    paths: RigPaths
    state: RigState
    already_running: bool = False

    @property
    def pid(self) -> int:
        return self.state.pid

    def command(self, cmd: str, **args) -> dict:
        return send_command(self.paths.control_socket, {"cmd": cmd, **args})


def require_linux(platform: str | None = None) -> None:
    """RigError where the rig cannot run (``sys.platform`` unless given): before any pid is probed, since
    os.kill(pid, 0) ends a process on Windows, and before a runtime folder named by a uid Windows lacks."""
    if not (platform or sys.platform).startswith("linux"):
        raise RigError("the virtual rig runs on Linux only: it needs a JACK server and pseudo-terminals; measure "
                       "with a sound card (linpar measure --rig soundcard), or with the window's in-process "
                       "simulator")


def find_rig(name: str = DEFAULT_NAME, runtime_dir: Path | None = None) -> RigHandle | None:
    """The running rig of that name, or None (stale files of a dead one are removed)."""
    require_linux()
    paths = RigPaths.for_name(name, runtime_dir)
    pid = read_pid(paths)
    if not pid_alive(pid):
        _remove_stale(paths)
        return None
    state = read_state(paths)
    if state is None or state.pid != pid:
        return None    # starting, or stopping: not usable yet
    return RigHandle(name, paths, state, already_running=True)


@contextlib.contextmanager
def _one_at_a_time(paths: RigPaths, wait_s: float) -> Iterator[None]:
    """Hold the rig's lock while checking and starting (or stopping) it: two `linpar rig start` (or a
    `measure` starting its rig) at once would each see no rig and start one, the second then lost to `rig
    status` and `rig stop`. The other waits, then finds the rig the first started. The lock file sits beside
    the rig's folder (a rig name never starts with '.')."""
    paths.directory.parent.mkdir(parents=True, exist_ok=True)
    lock = take(paths.directory.parent / f".{paths.directory.name}.lock", wait_s)
    if lock is None:
        raise RigError(f"rig {paths.directory.name!r}: another process has been starting or stopping it for "
                       f"{wait_s:g} s; see 'linpar rig status', or try again")
    try:
        yield
    finally:
        lock.release()


def start_rig(name: str = DEFAULT_NAME, driver: str = "paper", effects: str | None = None,
              faults: Sequence[str] = (), noise: str | None = None, runtime_dir: Path | None = None,
              seed: int | None = None, timeout: float = START_TIMEOUT_S, extra_args: Sequence[str] = (),
              model: str = "linear") -> RigHandle:
    """The rig `name`, started in the background unless it runs; `model` is the server's --model."""
    require_linux()
    if model not in MODELS:
        raise RigError(f"unknown rig model {model!r} (expected {' or '.join(MODELS)})")
    paths = RigPaths.for_name(name, runtime_dir)
    with _one_at_a_time(paths, timeout + LOCK_MARGIN_S):
        return _start_unlocked(name, paths, driver, effects, faults, noise, runtime_dir, seed, timeout,
                               extra_args, model)


def _start_unlocked(name, paths, driver, effects, faults, noise, runtime_dir, seed, timeout, extra_args,
                    model) -> RigHandle:
    running = find_rig(name, runtime_dir)
    if running is not None:
        running_model = running.state.extra.get("model", "linear")
        if running_model != model:
            raise RigError(f"rig {name!r} already runs the {running_model} model; stop it first "
                           f"(linpar rig stop --name {name}) to start the {model} one")
        return running
    if pid_alive(read_pid(paths)):
        raise RigError(f"rig {name!r} is starting or stopping (pid {read_pid(paths)}); try again in a moment")
    paths.ensure()
    cmd = [sys.executable, "-m", "instruments.rig.server", "--name", name, "--driver", str(driver),
           "--model", model]
    if runtime_dir is not None:
        cmd += ["--runtime-dir", str(runtime_dir)]
    if effects:
        cmd += ["--effects", effects]
    if noise:
        cmd += ["--noise", noise]
    for fault in faults:
        cmd += ["--fault", fault]
    if seed is not None:
        cmd += ["--seed", str(seed)]
    cmd += list(extra_args)
    with open(paths.log_file, "ab") as log:
        process = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                                   start_new_session=True, cwd=Path(__file__).resolve().parents[2])
    deadline = time.monotonic() + timeout
    while True:
        state = read_state(paths)
        if state is not None and state.pid == process.pid:
            try:
                send_command(paths.control_socket, {"cmd": "ping"}, timeout=2.0)
                return RigHandle(name, paths, state)
            except ControlError:
                pass
        if process.poll() is not None:
            raise RigError(f"rig {name!r} exited with code {process.returncode} while starting: "
                           f"{_last_line(paths.log_file)} (log: {paths.log_file})")
        if time.monotonic() > deadline:
            _kill_group(process.pid)
            raise RigError(f"rig {name!r} was not ready within {timeout:g} s (log: {paths.log_file})")
        time.sleep(0.05)


def stop_rig(name: str = DEFAULT_NAME, runtime_dir: Path | None = None, timeout: float = 10.0) -> bool:
    """Stop the rig and its jackd; False if it was not running. RigError if it would not die."""
    require_linux()
    paths = RigPaths.for_name(name, runtime_dir)
    with _one_at_a_time(paths, timeout + LOCK_MARGIN_S + START_TIMEOUT_S):
        return _stop_unlocked(name, paths, timeout)


def _stop_unlocked(name: str, paths: RigPaths, timeout: float) -> bool:
    pid = read_pid(paths)
    if not pid_alive(pid):
        _remove_stale(paths)
        return False
    try:
        send_command(paths.control_socket, {"cmd": "stop"}, timeout=2.0)
    except ControlError:
        _signal(pid, signal.SIGTERM)
    if not _wait_gone(pid, timeout):
        _kill_group(pid)
        if not _wait_gone(pid, 3.0):
            raise RigError(f"rig {name!r} (pid {pid}) does not stop")
    _remove_stale(paths)
    return True


def rig_status(name: str = DEFAULT_NAME, runtime_dir: Path | None = None) -> dict | None:
    """The rig's own status report (state, connections, xruns, faults), or None if it is not running."""
    require_linux()
    handle = find_rig(name, runtime_dir)
    if handle is None:
        return None
    try:
        return handle.command("status")
    except ControlError as exc:
        return {"state": None, "error": str(exc), "pid": handle.pid}


def list_rigs(runtime_dir: Path | None = None) -> list[str]:
    require_linux()
    from instruments.rig.state import runtime_root
    root = Path(runtime_dir or runtime_root())
    if not root.is_dir():
        return []
    return sorted(p.name for p in root.iterdir() if p.is_dir() and find_rig(p.name, runtime_dir) is not None)


def _wait_gone(pid: int, timeout: float) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        _reap(pid)
        if not pid_alive(pid):
            return True
        time.sleep(0.05)
    return False


def _reap(pid: int) -> None:
    """Collect the exit status if the rig is our child (started by this process), so no zombie stays."""
    try:
        os.waitpid(pid, os.WNOHANG)
    except ChildProcessError:
        pass


def _signal(pid: int, sig: int) -> None:
    try:
        os.kill(pid, sig)
    except ProcessLookupError:
        pass


def _kill_group(pid: int) -> None:
    """SIGKILL the rig's process group (the rig is its leader; its jackd is in it)."""
    try:
        os.killpg(pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    _reap(pid)


def _remove_stale(paths: RigPaths) -> None:
    if not pid_alive(read_pid(paths)):
        for path in (paths.state_file, paths.pid_file, paths.control_socket):
            path.unlink(missing_ok=True)


def _last_line(path: Path) -> str:
    """The rig's reason for failing (its "rig failed:" line), else the log's last line."""
    try:
        lines = [line for line in path.read_text(errors="replace").splitlines() if line.strip()]
    except OSError:
        return "no log"
    failed = [line for line in lines if line.startswith("rig failed: ")]
    if failed:
        return failed[-1][len("rig failed: "):]
    return lines[-1] if lines else "no output"
