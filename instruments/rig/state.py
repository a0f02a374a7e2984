"""Where a running rig says what it is: a runtime directory per rig name.

    $XDG_RUNTIME_DIR/linpar-rig/<name>/    (or /tmp/linpar-rig-<uid>/<name>/)
        rig.pid       the rig process (leader of its own process group)
        state.json    written atomically once the rig is ready (RigState)
        control.sock  the rig's command socket (instruments.rig.control)
        rig.log       the rig's and jackd's output

The state file is what a workstation reads to use the rig: the JACK server
name (set JACK_DEFAULT_SERVER to it), the sample rate, the calibration to use,
the channel map that matches the rig's cables, the port names, and where the
serial laser emulator's pseudo-terminal will be (None until one is plugged in).
"""
from __future__ import annotations

import json
import os
import tempfile
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from analysis.errors import LinparError
from instruments.audio.config import Calibration, ChannelMap

STATE_FORMAT = "linpar-rig-state/1"
DEFAULT_NAME = "linpar"


class RigNameError(LinparError, ValueError):
    """A rig name that cannot name a folder (and a JACK server)."""


class RigStateError(LinparError, ValueError):
    """A rig's state file that cannot be read (another version's, or damaged)."""


def runtime_root() -> Path:
    """The folder that holds one sub-folder per rig name (private to the user)."""
    xdg = os.environ.get("XDG_RUNTIME_DIR")
    if xdg and Path(xdg).is_dir():
        return Path(xdg) / "linpar-rig"
    return Path(tempfile.gettempdir()) / f"linpar-rig-{os.getuid()}"


@dataclass(frozen=True)
class RigPaths:
    directory: Path

    @classmethod
    def for_name(cls, name: str, root: Path | None = None) -> RigPaths:
        if not name or "/" in name or name.startswith("."):
            raise RigNameError(f"rig name {name!r}: expected a plain name (letters, digits, '-', '_')")
        return cls(Path(root or runtime_root()) / name)

    @property
    def pid_file(self) -> Path:
        return self.directory / "rig.pid"

    @property
    def state_file(self) -> Path:
        return self.directory / "state.json"

    @property
    def control_socket(self) -> Path:
        return self.directory / "control.sock"

    @property
    def log_file(self) -> Path:
        return self.directory / "rig.log"

    def ensure(self) -> None:
        self.directory.mkdir(parents=True, exist_ok=True, mode=0o700)
        os.chmod(self.directory.parent, 0o700)


@dataclass(frozen=True)
class RigState:
    name: str                      # the rig's name = its JACK server's name
    jack_server: str
    pid: int                       # the rig process
    jackd_pid: int
    sample_rate: int
    period_frames: int
    driver: str
    effects: tuple[str, ...]
    fir_length: int
    faults: tuple[str, ...]
    noise: dict[str, float]
    calibration: dict[str, float]
    channel_map: dict[str, Any]
    ports: dict[str, str]          # rig port role -> full JACK port name
    client_pattern: str            # which JACK clients the rig wires to itself
    laser_pty: str | None = None   # the serial laser emulator's pty, once plugged in
    format: str = STATE_FORMAT
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def workstation_calibration(self) -> Calibration:
        return Calibration.from_dict(self.calibration)

    @property
    def workstation_channel_map(self) -> ChannelMap:
        return ChannelMap.from_dict(self.channel_map)

    def to_json(self) -> str:
        d = asdict(self)
        d["effects"], d["faults"] = list(self.effects), list(self.faults)
        return json.dumps(d, indent=1, sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> RigState:
        try:
            d = json.loads(text)
            if not isinstance(d, dict) or d.get("format") != STATE_FORMAT:
                found = d.get("format") if isinstance(d, dict) else type(d).__name__
                raise RigStateError(f"rig state: format {found!r}, expected {STATE_FORMAT!r}")
            d["effects"], d["faults"] = tuple(d["effects"]), tuple(d["faults"])
            return cls(**d)
        except (json.JSONDecodeError, KeyError, TypeError) as exc:
            raise RigStateError(f"rig state: not readable ({type(exc).__name__}: {exc}); stop the rig and start "
                                f"it again") from None


def read_state(paths: RigPaths) -> RigState | None:
    """The state of the rig, None when it has not written one (not started, not ready, or gone)."""
    try:
        return RigState.from_json(paths.state_file.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return None


def read_pid(paths: RigPaths) -> int | None:
    try:
        return int(paths.pid_file.read_text().strip())
    except (FileNotFoundError, ValueError):
        return None


def pid_alive(pid: int | None) -> bool:
    """Whether a process of that id exists and is not a zombie."""
    if not pid:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
        return stat.rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return True   # no /proc: trust kill(0)
