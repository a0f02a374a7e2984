"""The rig's command socket: one JSON object per line in, one per line out.

Requests: {"cmd": "ping"} | {"cmd": "status"} | {"cmd": "fault", "set": ["disconnect=current", ...]}
| {"cmd": "fault", "clear": true} | {"cmd": "xrun", "seconds": 0.1} | {"cmd": "kill-client"}
| {"cmd": "stop"} | {"cmd": "laser-pty", "path": "/dev/pts/N" | null}.
Replies: {"ok": true, ...} or {"ok": false, "error": "one line"}.

A Unix socket in the rig's private runtime directory: only the user reaches it.
"""
from __future__ import annotations

import contextlib
import json
import os
import socket
import threading
from pathlib import Path
from typing import Any, Callable

from analysis.errors import LinparError

Handler = Callable[[dict[str, Any]], dict[str, Any]]


class ControlError(LinparError, RuntimeError):
    pass


# A Unix socket's path holds at most 107 bytes (sun_path); a runtime directory deep in a temporary folder
# (a test worker's, a user's long home) passes that. Such a path is reached through the directory's open
# descriptor, /proc/self/fd/N/control.sock, which Linux resolves like the path itself (the rig is Linux only).
_SUN_PATH_MAX = 100


@contextlib.contextmanager
def _reachable(path: Path):
    """The path to bind or connect to: the path itself, or the same file through its directory's descriptor."""
    if len(os.fsencode(str(path))) <= _SUN_PATH_MAX:
        yield str(path)
        return
    directory = os.open(path.parent, os.O_RDONLY)
    try:
        yield f"/proc/self/fd/{directory}/{path.name}"
    finally:
        os.close(directory)


class ControlServer:
    def __init__(self, path: Path, handler: Handler):
        self.path = Path(path)
        self._handler = handler
        self.path.unlink(missing_ok=True)
        self._sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        with _reachable(self.path) as where:
            self._sock.bind(where)
        self._sock.listen(8)
        self._sock.settimeout(0.2)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, name="rig-control", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def _serve(self) -> None:
        while not self._stop.is_set():
            try:
                conn, _ = self._sock.accept()
            except (socket.timeout, OSError):
                continue
            with conn:
                conn.settimeout(5.0)
                try:
                    line = _read_line(conn)
                    try:
                        request = json.loads(line)
                        if not isinstance(request, dict):
                            raise ValueError("expected a JSON object")
                        reply = {"ok": True, **self._handler(request)}
                    except Exception as exc:   # every error goes back to the caller as one line
                        reply = {"ok": False, "error": " ".join(f"{exc}".splitlines()) or type(exc).__name__}
                    conn.sendall((json.dumps(reply) + "\n").encode())
                except OSError:
                    pass

    def close(self) -> None:
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(2.0)
        self._sock.close()
        self.path.unlink(missing_ok=True)


def send_command(path: Path, request: dict[str, Any], timeout: float = 5.0) -> dict[str, Any]:
    """Send one request to the rig; its reply, or ControlError (rig not running, error reply)."""
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as sock:
        sock.settimeout(timeout)
        try:
            with _reachable(Path(path)) as where:
                sock.connect(where)
            sock.sendall((json.dumps(request) + "\n").encode())
            reply = json.loads(_read_line(sock))
        except (OSError, ValueError) as exc:
            raise ControlError(f"the rig does not answer on {path} ({exc})") from None
    if not reply.get("ok"):
        raise ControlError(f"the rig refused {request.get('cmd')!r}: {reply.get('error')}")
    return reply


def _read_line(sock: socket.socket, limit: int = 1 << 20) -> str:
    data = b""
    while not data.endswith(b"\n"):
        chunk = sock.recv(65536)
        if not chunk:
            break
        data += chunk
        if len(data) > limit:
            raise ValueError("request too long")
    return data.decode("utf-8").strip()
