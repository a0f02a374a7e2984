"""One error model (analysis.errors): a user error is one line and exit 2, a bug exit 70 with a crash report.

The boundaries are app.cli.main and the GUI's job runner (app.jobs.book.failure_text): they catch
LinparError (and the environment's OSError / MemoryError), never a bare ValueError or KeyError, so a
bug cannot pass for bad input.
"""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

import app.cli.effects
from analysis.errors import LinparError, is_user_error, user_message
from app.cli import main

REPO = Path(__file__).resolve().parents[3]


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_a_bug_exits_70_with_one_line_and_a_crash_report(capsys, monkeypatch, tmp_path):
    monkeypatch.setenv("LINPAR_CACHE", str(tmp_path / "cache"))

    def broken(args):
        raise ValueError("a bug, not bad input")       # a bare ValueError is a bug, not the user's error
    monkeypatch.setattr(app.cli.effects, "run", broken)
    code, out, err = run(capsys, "effects", "--json")
    assert code == 70 and out == ""
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    match = re.fullmatch(r"linpar: internal error: ValueError: a bug, not bad input \(details in (.+)\)\n", err)
    assert match, err
    report = Path(match.group(1))
    assert report.parent == tmp_path / "cache"
    text = report.read_text(encoding="utf-8")
    assert "Traceback (most recent call last)" in text and "a bug, not bad input" in text
    assert "linpar effects --json" in text and "version:  linpar" in text


def test_two_crashes_in_one_second_keep_two_reports(capsys, monkeypatch, tmp_path):
    monkeypatch.setenv("LINPAR_CACHE", str(tmp_path))
    monkeypatch.setattr(app.cli.effects, "run", lambda args: 1 / 0)
    for _ in range(2):
        assert run(capsys, "effects")[0] == 70
    assert len(list(tmp_path.glob("crash-*.txt"))) == 2


def test_a_crash_report_that_cannot_be_written_still_gives_one_line(capsys, monkeypatch, tmp_path):
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("LINPAR_CACHE", str(blocker / "cache"))
    monkeypatch.setattr(app.cli.effects, "run", lambda args: 1 / 0)
    code, _, err = run(capsys, "effects")
    assert code == 70 and len(err.splitlines()) == 1 and "no crash report" in err


def test_the_cache_folder_follows_xdg(monkeypatch, tmp_path):
    from app.crash_report import cache_dir
    monkeypatch.delenv("LINPAR_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    if sys.platform.startswith("linux"):
        assert cache_dir() == tmp_path / "linpar"


def test_user_errors_are_linpar_errors_oserror_and_memory_only():
    assert is_user_error(LinparError("x")) and is_user_error(FileNotFoundError(2, "No such file", "a.wav"))
    assert is_user_error(MemoryError())
    for bug in (ValueError("x"), KeyError("x"), TypeError("x"), ZeroDivisionError(), OverflowError()):
        assert not is_user_error(bug)
    assert user_message(FileNotFoundError(2, "No such file or directory", "a.wav")) == \
        "a.wav: No such file or directory"
    assert user_message(LinparError("two\nlines")) == "two lines"


def every_error_class():
    """Every exception class defined in the three packages, by importing each module."""
    import importlib
    import inspect
    classes = {}
    for package in ("analysis", "instruments", "app"):
        for path in sorted((REPO / package).rglob("*.py")):
            module = ".".join(path.relative_to(REPO).with_suffix("").parts)
            if module.endswith("__init__"):
                module = module[: -len(".__init__")]
            if module in ("app.main", "instruments.rig.server") or module.endswith(".__main__"):
                continue        # Qt's start-up, a server script, `python -m`: no error classes, side effects on import
            try:
                mod = importlib.import_module(module)
            except ImportError:
                continue
            for name, obj in vars(mod).items():
                if inspect.isclass(obj) and issubclass(obj, Exception) and obj.__module__ == module:
                    classes[f"{module}.{name}"] = obj
    return classes


# Exceptions that are not errors for the user: cancellations and internal signals, caught where they arise;
# what a worker process raised, brought back to be reported as it would have been there: a bug.
NOT_USER_ERRORS = {"Cancelled", "_NotJson", "SchemaError", "SpecError", "analysis.worker_errors."}


def test_every_error_a_module_defines_derives_from_linpar_error():
    classes = every_error_class()
    assert "analysis.recording.sidecar.RecordingError" in classes
    stray = sorted(name for name, cls in classes.items()
                   if not issubclass(cls, LinparError) and not any(n in name for n in NOT_USER_ERRORS))
    assert stray == []


def test_no_boundary_catches_a_bare_value_or_key_error():
    """The grep of the issue: no `except (ValueError...` / `except KeyError` in app/."""
    found = subprocess.run(["grep", "-rn", r"except (ValueError\|except KeyError", "app/"], cwd=REPO,
                           capture_output=True, text=True).stdout
    assert found == ""


@pytest.mark.parametrize("argv, words", [
    (["export", "/nonexistent", "--csv", "x.csv", "--sd", "0.01"], "--sd and --model apply to recordings"),
    (["report", "/nonexistent"], "give --pdf FILE"),
    (["export", "/nonexistent"], "give at least one of"),
    (["analyze", "x", "--model", "lr2,nonsense"], "--model: unknown effect 'nonsense'"),
    (["diagnose", "x", "--from", "nonsense"], "--from: unknown effect"),
])
def test_what_used_to_be_a_bare_value_error_is_a_user_error(capsys, argv, words):
    code, _, err = run(capsys, *argv)
    assert code == 2 and words in err and len(err.splitlines()) == 1, err
