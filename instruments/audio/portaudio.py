"""PortAudio (through python-sounddevice): loading it, choosing its JACK server, leaving it safely.

Three facts about PortAudio 19.6's JACK host API shape this module (checked
on Debian's libportaudio2 19.6.0 with jackd2 1.9.21):

1. It connects to the JACK server named by $JACK_DEFAULT_SERVER when PortAudio
   is initialised, which python-sounddevice does on import. To use another
   server the environment must change and PortAudio be initialised again
   (``use_jack_server``), with no stream open.
2. When that server goes away (killed, or stopped by `linpar rig stop`),
   Pa_StopStream, Pa_AbortStream and Pa_CloseStream of a stream on it never
   return, and Pa_Terminate fails an assertion and aborts the process.
   python-sounddevice calls both from an atexit handler. So the handler is
   replaced (``_exit_handler`` below): PortAudio is terminated at exit only
   when its JACK server, if any, is still there, and never after a stream was
   abandoned (``mark_abandoned``).
3. The JACK host API opens its JACK client with JackNoStartServer, but libjack
   may still try to start a server when asked by name; JACK_NO_START_SERVER=1
   is set whenever this module picks a server, so a missing server is an
   error, never a jackd started behind the user's back.
"""
from __future__ import annotations

import atexit
import os
import socket
import sys
import threading
from pathlib import Path
from types import ModuleType

from instruments.audio.errors import AudioError, AudioUnavailable

_NO_PORTAUDIO = ("PortAudio is not available ({reason}): install the Debian package libportaudio2 "
                 "(tools/system-packages.sh does it); the simulated audio works without it")

_lock = threading.Lock()
# NB: module state shared by every thread that opens streams; guarded by _lock.
_state: dict[str, object] = {"handler_installed": False, "abandoned": None}


def sounddevice_module() -> ModuleType:
    """python-sounddevice, imported; AudioUnavailable when PortAudio cannot load."""
    if sys.platform == "win32":
        # python-sounddevice's Windows wheel loads its PortAudio with ASIO only when asked, before the import:
        # ASIO is what suits a measurement there (instruments.audio.host_apis).
        os.environ.setdefault("SD_ENABLE_ASIO", "1")
    try:
        import sounddevice
    except OSError as exc:
        raise AudioUnavailable(_NO_PORTAUDIO.format(reason=exc)) from None
    except ImportError as exc:
        raise AudioUnavailable(_NO_PORTAUDIO.format(reason=f"python-sounddevice: {exc}")) from None
    with _lock:
        if not _state["handler_installed"]:
            atexit.unregister(sounddevice._exit_handler)
            atexit.register(_exit_handler)
            _state["handler_installed"] = True
    return sounddevice


def jack_server_name() -> str:
    """The JACK server PortAudio uses (or would use): $JACK_DEFAULT_SERVER, else 'default'."""
    return os.environ.get("JACK_DEFAULT_SERVER") or "default"


def jack_server_alive(name: str | None = None) -> bool:
    """Whether a JACK2 server of that name answers on its socket (no libjack call, so no side effects).

    Linux only, where JACK2 keeps its sockets in /dev/shm; elsewhere True (no way to tell, and the virtual
    rig, whose server may vanish, runs on Linux alone).
    """
    if not sys.platform.startswith("linux"):
        return True
    name = name or jack_server_name()
    path = Path(os.environ.get("JACK_TMP_DIR", "/dev/shm")) / f"jack_{name}_{os.getuid()}_0"
    if not path.exists():
        return False
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as probe:
        probe.settimeout(0.5)
        try:
            probe.connect(str(path))
        except OSError:
            return False
    return True


def use_jack_server(name: str) -> None:
    """Point PortAudio's JACK host API at the server ``name`` (re-initialises PortAudio).

    No stream may be open. The previous server, if any, must still be running
    (see the module doc); AudioError if PortAudio can no longer be restarted
    in this process.
    """
    os.environ["JACK_DEFAULT_SERVER"] = name
    os.environ["JACK_NO_START_SERVER"] = "1"
    reinitialize()


def reinitialize() -> None:
    """Terminate and initialise PortAudio again: fresh device list, current environment."""
    sd = sounddevice_module()
    with _lock:
        _refuse_if_abandoned()
        while sd._initialized > 0:
            sd._terminate()
        sd._initialize()


def release() -> None:
    """Terminate PortAudio now, while its JACK server is still there (call before stopping the server)."""
    sd = sys.modules.get("sounddevice")
    if sd is None:
        return
    with _lock:
        if _state["abandoned"] is not None:
            return
        while sd._initialized > 0:
            sd._terminate()


def mark_abandoned(reason: str) -> None:
    """A stream was left open because closing it would hang: PortAudio must not be touched again."""
    with _lock:
        _state["abandoned"] = reason


def abandoned_reason() -> str | None:
    return _state["abandoned"]  # type: ignore[return-value]


def _refuse_if_abandoned() -> None:
    if _state["abandoned"] is not None:
        raise AudioError(f"PortAudio cannot be used again in this process: {_state['abandoned']}; "
                         f"restart the program")


def _uses_jack(sd: ModuleType) -> bool:
    try:
        return any(api["name"].startswith("JACK") for api in sd.query_hostapis())
    except Exception:   # PortAudio already gone: nothing to ask
        return False


def _exit_handler() -> None:
    """python-sounddevice's atexit clean-up, minus the calls that would hang or abort (module doc, 2)."""
    sd = sys.modules.get("sounddevice")
    if sd is None or _state["abandoned"] is not None or sd._initialized <= 0:
        return
    if _uses_jack(sd) and not jack_server_alive():
        return   # the process ends anyway; Pa_Terminate would fail an assertion and abort it
    sd._exit_handler()
