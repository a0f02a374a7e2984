"""The rig's command socket in a runtime directory deeper than a Unix socket's path can hold."""
from __future__ import annotations

import sys

import pytest

from instruments.rig.control import ControlServer, send_command

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the rig runs on Linux only")


def test_a_runtime_directory_too_deep_for_a_socket_path_still_answers(tmp_path):
    """A path over sun_path's 107 bytes (a test worker's temporary folder made the rig exit with 'AF_UNIX path
    too long'): bound and reached through the directory's descriptor."""
    deep = tmp_path / ("d" * 60) / ("e" * 60)
    deep.mkdir(parents=True)
    path = deep / "control.sock"
    assert len(str(path)) > 107
    server = ControlServer(path, lambda request: {"ok": True, "cmd": request["cmd"]})
    server.start()
    try:
        assert send_command(path, {"cmd": "ping"}) == {"ok": True, "cmd": "ping"}
        assert path.exists()            # the socket is the directory's own file, not a stand-in elsewhere
    finally:
        server.close()
