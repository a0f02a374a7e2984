"""Sound cards by specification: open_audio makes every back end, a new one is
a module with open_from_spec (or a registration), and an unknown one says
which exist. The protocol suite (test_audio_protocol.py) runs the simulated
and the rig's card through the same factory."""

import subprocess
import sys
from pathlib import Path

import pytest

from instruments.audio import AudioError, AudioInterface, AudioSpec, ChannelMap, audio_backends, factory, open_audio
from instruments.rig.engine import RIG_CALIBRATION, RIG_CHANNEL_MAP
from tests.pace import paced

ROOT = Path(__file__).resolve().parents[3]


def test_the_simulated_back_end_takes_the_spec_and_its_options():
    wiring = ChannelMap(output=0, voltage=0, current=1)
    audio = open_audio(AudioSpec("simulated", sample_rate=44100, channel_map=wiring,
                                 options={"realtime": False, "blocksize": 512}))
    assert isinstance(audio, AudioInterface)
    assert (audio.sample_rate, audio.channel_map, audio.blocksize, audio.realtime) == (44100, wiring, 512, False)
    assert audio.calibration == RIG_CALIBRATION                 # None: the simulated rig's own
    assert open_audio(AudioSpec("simulated", options={"realtime": False})).channel_map == RIG_CHANNEL_MAP


def test_a_sound_card_without_calibration_and_an_unknown_back_end_say_what_to_do():
    with pytest.raises(AudioError, match="no calibration given"):
        open_audio(AudioSpec("sounddevice"))
    with pytest.raises(AudioError, match="unknown audio back end 'asio4all'; known: .*rig.*simulated.*sounddevice"):
        open_audio(AudioSpec("asio4all"))


def test_a_registered_back_end_is_opened_by_name(monkeypatch):
    monkeypatch.setattr(factory, "_registered", {})
    made = []
    factory.register_audio_backend("toy", lambda spec: made.append(spec) or "a toy card")
    spec = AudioSpec("toy", sample_rate=96000)
    assert open_audio(spec) == "a toy card" and made == [spec]
    assert "toy" in audio_backends()


def test_every_listed_back_end_has_its_opener():
    for backend, module in factory.BACKENDS.items():
        code = f"import {module} as m, sys; sys.exit(0 if callable(getattr(m, 'open_from_spec', None)) else 1)"
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=paced(60), cwd=ROOT)
        assert done.returncode == 0, f"{backend}: {module} has no open_from_spec\n{done.stderr}"


def test_nothing_outside_the_back_ends_makes_a_card_by_class_name():
    backends = {"instruments/audio/simulated.py", "instruments/audio/sounddevice_audio.py"}
    callers = [path.relative_to(ROOT).as_posix() for folder in ("app", "instruments", "tools", "bench")
               for path in (ROOT / folder).rglob("*.py")
               if ("SimulatedAudio(" in path.read_text(encoding="utf-8")
                   or "SoundDeviceAudio(" in path.read_text(encoding="utf-8"))]
    assert sorted(set(callers) - backends) == []
