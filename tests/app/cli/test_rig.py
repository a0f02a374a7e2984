"""`linpar rig start --model`: the option, its way to the rig server's command line, and (with jackd) a running rig."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from app.cli import rig as cli_rig
from app.cli import build_parser, main
from tests.pace import paced

REPO = Path(__file__).resolve().parents[3]


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


class _FakeManager:
    """Stands for instruments.rig.manager: records start_rig's arguments, starts nothing."""

    class RigError(RuntimeError):
        pass

    def __init__(self):
        self.calls = []

    def start_rig(self, *args, **kwargs):
        self.calls.append((args, kwargs))
        state = type("State", (), {"to_json": lambda self: json.dumps({"extra": {"model": kwargs.get("model")}})})
        return type("Handle", (), {"state": state(), "already_running": False, "pid": 1})()


@pytest.fixture
def fake_manager(monkeypatch):
    fake = _FakeManager()
    monkeypatch.setattr(cli_rig, "_manager", lambda: fake)
    return fake


def test_start_offers_the_nonlinear_model_and_says_what_it_is(capsys):
    assert build_parser().parse_args(["rig", "start"]).model == "linear"
    assert build_parser().parse_args(["rig", "start", "--model", "nonlinear"]).model == "nonlinear"
    with pytest.raises(SystemExit):
        build_parser().parse_args(["rig", "start", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    assert "--model {linear,nonlinear}" in help_text and "Bl(x), Kms(x) and Le(x)" in help_text


def test_an_unknown_model_is_refused_in_one_line(capsys, fake_manager):
    code, _, err = run(capsys, "rig", "start", "--model", "cubic")
    assert code == 2 and err.count("\n") == 1 and "'cubic'" in err and "nonlinear" in err
    assert fake_manager.calls == []


@pytest.mark.parametrize("argv, model", [((), "linear"), (("--model", "nonlinear"), "nonlinear")])
def test_start_hands_the_model_to_the_manager(capsys, fake_manager, argv, model):
    code, out, err = run(capsys, "rig", "start", "--name", "x", *argv, "--json")
    assert code == 0, err
    (_args, kwargs), = fake_manager.calls
    assert kwargs["model"] == model


def test_effects_with_the_nonlinear_model_is_an_error_not_silently_ignored(capsys, fake_manager):
    code, _, err = run(capsys, "rig", "start", "--model", "nonlinear", "--effects", "lr2")
    assert code == 2 and err.count("\n") == 1 and "--effects" in err and "linear model only" in err
    assert fake_manager.calls == []


def test_a_running_rig_of_the_other_model_is_an_error_not_silently_reused(monkeypatch, tmp_path):
    from instruments.rig import manager
    state = type("State", (), {"extra": {"model": "linear"}})()
    running = type("Handle", (), {"state": state, "already_running": True})()
    monkeypatch.setattr(manager, "find_rig", lambda name, runtime_dir=None: running)
    with pytest.raises(manager.RigError, match="already runs the linear model; stop it first"):
        manager.start_rig("busy", runtime_dir=tmp_path, model="nonlinear")
    assert manager.start_rig("busy", runtime_dir=tmp_path, model="linear") is running


def test_the_cli_choices_are_the_servers():
    from instruments.rig import manager, server
    choices = next(a.choices for a in server.build_parser()._actions if a.dest == "model")
    assert tuple(choices) == manager.MODELS == cli_rig.RIG_MODELS


def test_the_manager_passes_the_model_on_the_servers_command_line(monkeypatch, tmp_path):
    from instruments.rig import manager, server
    commands = []

    class Exited:
        pid, returncode = 2 ** 22 + 1, 1

        def __init__(self, cmd, **kwargs):
            commands.append(cmd)

        def poll(self):
            return self.returncode
    monkeypatch.setattr(manager.subprocess, "Popen", Exited)

    with pytest.raises(manager.RigError, match="exited with code 1"):
        manager.start_rig("model-test", runtime_dir=tmp_path, model="nonlinear")
    cmd, = commands
    assert cmd[1:3] == ["-m", "instruments.rig.server"]
    assert server.build_parser().parse_args(cmd[3:]).model == "nonlinear"
    with pytest.raises(manager.RigError, match="unknown rig model 'cubic'"):
        manager.start_rig("model-test", runtime_dir=tmp_path, model="cubic")
    assert len(commands) == 1


@pytest.mark.rig
def test_a_nonlinear_rig_starts_and_says_so(virtual_rig, tmp_path):   # virtual_rig: the same skip when jackd is missing
    name = f"linpar-nl-{os.getpid()}"
    where = ["--name", name, "--runtime-dir", str(tmp_path)]

    def linpar(*args):
        return subprocess.run([sys.executable, "-m", "app.cli", "rig", *args, *where], cwd=REPO,
                              capture_output=True, text=True, timeout=paced(60))
    try:
        started = linpar("start", "--model", "nonlinear", "--json")
        assert started.returncode == 0, started.stderr
        assert json.loads(started.stdout)["extra"]["model"] == "nonlinear"
        status = linpar("status")
        assert status.returncode == 0 and "nonlinear model" in status.stdout
    finally:
        assert linpar("stop").returncode == 0


@pytest.mark.parametrize("spec, says", [("latency=abc", "expected a number"), ("latency=-0.001", "from 0 to 1"),
                                        ("latency=1.5", "from 0 to 1"), ("latency=0.008,jitter=-0.002", "from 0 to 1"),
                                        ("latency=0.008,jitter=inf", "finite")])
@pytest.mark.parametrize("action", ["start", "fault"])
def test_a_latency_fault_that_no_link_has_is_one_line_before_anything_starts(capsys, fake_manager, spec, says,
                                                                             action):
    argv = ("rig", "start", "--fault", spec) if action == "start" else ("rig", "fault", spec)
    code, out, err = run(capsys, *argv)
    assert code == 2 and err.count("\n") == 1 and says in err and out == ""
    assert fake_manager.calls == []


def test_a_latency_fault_with_jitter_is_handed_to_the_rig(capsys, fake_manager):
    code, _, err = run(capsys, "rig", "start", "--fault", "latency=0.008,jitter=0.002", "--json")
    assert code == 0, err
    (_args, kwargs), = fake_manager.calls
    from instruments.rig.engine import RigFaults
    faults = RigFaults.parse(_args[3] if len(_args) > 3 else kwargs.get("faults", ()))
    assert faults.laser_link == {"link_latency_s": 0.008, "link_jitter_s": 0.002}
    assert faults.describe() == ["latency=0.008", "jitter=0.002"]
