"""The parser is built for the command asked for (app/cli/boundary.py): its table of commands must be what the
command groups register, and a command line that names no command plainly still gets every command."""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

import pytest

from app.cli.boundary import COMMAND_GROUPS, COMMANDS, build_parser, command_group, command_named, main
from app.cli.options import Parser
from tests.pace import paced

REPO = Path(__file__).resolve().parents[3]


def registered_by(module: str) -> list[str]:
    sub = argparse.ArgumentParser().add_subparsers(dest="command", parser_class=Parser)
    command_group(module).register(sub)
    return list(sub.choices)


def test_the_table_names_every_command_each_group_registers_and_no_other():
    table = {module: [name for name, m in COMMANDS.items() if m == module] for module in COMMAND_GROUPS}
    assert {module: registered_by(module) for module in COMMAND_GROUPS} == table


def test_the_whole_parser_has_the_tables_commands_in_its_order():
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    assert list(sub.choices) == list(COMMANDS)


def test_help_lists_every_command(capsys):
    with pytest.raises(SystemExit) as shown:
        main(["--help"])
    assert shown.value.code == 0
    out = capsys.readouterr().out
    for name in COMMANDS:
        assert f"    {name} " in out or f"    {name}\n" in out


@pytest.mark.parametrize("argv, command", [
    (["analyze", "rec", "--json"], "analyze"),
    (["--size-limit", "wav=1G", "export", "x"], "export"),
    (["--size-limit=wav=1G", "large-signal"], "large-signal"),
    ([], None), (["--help"], None), (["-h", "analyze"], None), (["--version"], None), (["--size", "wav=1G", "qa"], None),
    (["--size-limit", "-h", "qa"], None), (["--size-limit"], None), (["analyse", "rec"], None), (["rec"], None),
])
def test_the_command_is_read_only_when_it_is_plain(argv, command):
    assert command_named(argv) == command


def test_an_unknown_command_is_refused_with_every_command_named(capsys):
    assert main(["analyse", "rec"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "invalid choice: 'analyse'" in err
    assert all(f"'{name}'" in err for name in COMMANDS)


def test_the_parser_of_one_command_parses_as_the_whole_one():
    argv = ["--size-limit", "wav=2G", "analyze", "rec", "--model", "lr2", "--json"]
    assert vars(build_parser("analyze").parse_args(argv)) == vars(build_parser().parse_args(argv))


def test_only_the_processs_own_command_line_freezes_its_objects_for_the_exit(monkeypatch, capsys):
    import gc
    frozen = []
    monkeypatch.setattr(gc, "freeze", lambda: frozen.append(True))
    assert main(["effects", "--json"]) == 0                 # called with arguments (tests, scripts): the process goes on
    assert frozen == []
    monkeypatch.setattr("sys.argv", ["linpar", "effects", "--json"])
    assert main() == 0
    assert frozen == [True]
    monkeypatch.setattr("sys.argv", ["linpar", "gui", "--no-such-option"])
    assert main() == 2                                      # the window's process: its Qt objects are collected
    assert frozen == [True]
    monkeypatch.setattr("app.cli.gui.run", lambda args: 0)
    for shape in (["--size-lim", "wav=1G", "gui"], ["--size-limit", "wav=1G", "--size-l", "wav=2G", "gui"]):
        monkeypatch.setattr("sys.argv", ["linpar", *shape])     # argparse's abbreviation: the window all the same
        assert main() == 0
        assert frozen == [True], shape


def test_a_reader_that_goes_away_ends_the_command_quietly():
    """`linpar archive list | head`: the pipe's reader leaves early. Not "linpar: error: Broken pipe", nor the
    interpreter's complaint at exit: the command ends as a shell reports SIGPIPE (141), stderr empty."""
    read_end, write_end = os.pipe()
    os.close(read_end)                        # gone before the command writes anything: every write fails
    try:
        done = subprocess.run([sys.executable, "-m", "app.cli", "effects"], stdout=write_end,
                              stderr=subprocess.PIPE, text=True, timeout=paced(60), cwd=REPO)
    finally:
        os.close(write_end)
    assert done.returncode == 141 and done.stderr == ""
